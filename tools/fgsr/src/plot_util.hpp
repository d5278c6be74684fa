// Private to the fgsr subcommands that draw gnuplot plots (`fgsr report`, `fgsr bench`): text
// files, quoting, and running a script with
// gnuplot in the directory that holds it and its data files, so that `gnuplot SCRIPT` redraws the
// plots by hand.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fgsr::cli::plot {

inline Result<void> write_text(const std::filesystem::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary);
    if (!f) return make_error(Errc::io, "cannot write " + p.string());
    f << text;
    if (!f) return make_error(Errc::io, "cannot write " + p.string());
    return {};
}

// s as one word of a POSIX shell command line.
inline std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// s as a gnuplot single-quoted string ('' stands for a quote).
inline std::string gnuplot_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
    return q + "'";
}

// Whether a gnuplot executable is on PATH (Debian: gnuplot-nox).
inline bool gnuplot_available() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

// Runs `gnuplot script` in dir, its output in dir/script.log (removed when gnuplot succeeds).
inline Result<void> run_gnuplot(const std::filesystem::path& dir, const std::string& script) {
    const std::string log = script + ".log";
    const std::string cmd = "cd " + shell_quote(dir.string()) + " && gnuplot " + shell_quote(script) + " >" +
                            shell_quote(log) + " 2>&1";
    if (std::system(cmd.c_str()) != 0)
        return make_error(Errc::io, "gnuplot failed on " + (dir / script).string() + " (see " +
                                        (dir / log).string() + ")");
    std::error_code ec;
    std::filesystem::remove(dir / log, ec);
    return {};
}

} // namespace fgsr::cli::plot
