// Small helpers shared by the fgsr subcommands.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace fgsr::cli {

// "a,b,,c" -> {"a", "b", "c"}
inline std::vector<std::string> split_list(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) out.push_back(item);
    return out;
}

// The command line as reports record it: "fgsr" then argv[1..], space-separated.
inline std::string command_line_of(int argc, char** argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(i ? argv[i] : "fgsr");
    return s;
}

// Prints "fgsr: <code>: <message>" on stderr; returns the exit status of a failed subcommand (1).
inline int report_error(const Error& e) {
    std::fprintf(stderr, "fgsr: %s: %s\n", errc_name(e.code), e.message.c_str());
    return 1;
}

} // namespace fgsr::cli
