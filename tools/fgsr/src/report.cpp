// `fgsr report` (fgsr/cli/report.hpp): a PresentMon-style CSV to the dashboard's model, the
// self-contained dashboard page, summary.json, the printed table and the gnuplot plots.
#include <fgsr/cli/report.hpp>

#include <fgsr/cli/cli_util.hpp>

#include "plot_util.hpp"

#include <assets.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

namespace fgsr::cli {

namespace {

using telemetry::FrameRecord;
using telemetry::SessionInfo;
using telemetry::Summary;

uint32_t record_type(const std::string& frame_type) {
    if (frame_type == "Application") return FGSR_FRAME_NONE;
    if (frame_type == "fgsr-upscaled") return FGSR_FRAME_UPSCALED;
    if (frame_type == "fgsr-extrapolated") return FGSR_FRAME_EXTRAPOLATED;
    return FGSR_FRAME_INTERPOLATED; // fgsr-interpolated, PresentMon's Repeated, vendors' generated frames
}

bool status_ok(const std::string& s) {
    return s.empty() || s == "OK" || s == "ok" || s == "NA";
}

bool status_dropped(const std::string& s) {
    return s == "DROPPED" || s == "dropped";
}

std::string num(double v, int digits) {
    return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : std::string("NA");
}

// gnuplot reads "NaN" as an undefined value (the point is skipped).
std::string dat(double v) {
    return std::isfinite(v) ? fmt::format("{:.6g}", v) : std::string("NaN");
}

Result<std::string> read_file(const std::filesystem::path& p) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec))
        return make_error(Errc::io, "cannot read " + p.string() + ": no such file");
    std::ifstream f(p, std::ios::binary);
    if (!f) return make_error(Errc::io, "cannot read " + p.string());
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) return make_error(Errc::io, "cannot read " + p.string());
    return ss.str();
}

// <script>window.FGSR_DATA = ...;</script> with nothing in the JSON that ends or comments out the
// element ("</" as "<\/", "<!--" as "\u003c!--"; both only occur inside strings).
Result<std::string> data_script(const nlohmann::json& state) {
    std::string js;
    try {
        js = state.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    } catch (const std::exception& e) {
        return make_error(Errc::io, std::string("cannot write the dashboard's data: ") + e.what());
    }
    std::string safe;
    safe.reserve(js.size() + 64);
    for (size_t i = 0; i < js.size(); ++i) {
        if (js[i] == '<' && i + 1 < js.size() && js[i + 1] == '/') {
            safe += "<\\/";
            ++i;
        } else if (js.compare(i, 4, "<!--") == 0) {
            safe += "\\u003c";
        } else {
            safe += js[i];
        }
    }
    return "<script>window.FGSR_DATA = " + safe + ";</script>";
}

struct Series {
    std::string title, colour;
    int column = 0;    // frames.dat column of the y value
    int type = -1;     // only frames of this type (column 3), -1: all
    int point = 7;     // gnuplot point type (7 filled circle, 6 open circle, 5 filled square)
    double size = 0.8; // point size
};

// frames.dat: t_s ft_ms type lat_d lat_c disp session, one line per frame record.
std::string frames_dat(const ReportData& d) {
    std::string s = "# fgsr report: t_s ft_ms type(0 application, 1 upscaled, 2 interpolated, 3 "
                    "extrapolated) lat_daemon_ms lat_client_ms displayed_ms session\n";
    for (const FrameRecord& r : d.frames)
        s += fmt::format("{} {} {} {} {} {} {}\n", dat(r.t_s), dat(r.ft_ms), r.type, dat(r.lat_d_ms),
                         dat(r.lat_c_ms), dat(r.disp_ms), r.session);
    return s;
}

struct PassMean {
    std::string name;
    double mean_ms = 0;
    size_t frames = 0;
};

// Mean GPU ms of each pass over the frames that ran it (pass-id order).
std::vector<PassMean> pass_means(const ReportData& d) {
    const std::vector<std::string> names = telemetry::pass_names();
    std::vector<PassMean> m(names.size());
    for (size_t p = 0; p < names.size(); ++p) m[p].name = names[p];
    for (const FrameRecord& r : d.frames) {
        if (!r.has_passes) continue;
        for (size_t p = 0; p < m.size() && p < r.pass_ms.size(); ++p)
            if (r.pass_ms[p] > 0) {
                m[p].mean_ms += double(r.pass_ms[p]);
                ++m[p].frames;
            }
    }
    std::vector<PassMean> out;
    for (PassMean& p : m)
        if (p.frames > 0) {
            p.mean_ms /= double(p.frames);
            out.push_back(p);
        }
    return out;
}

std::string plot_line(const std::vector<Series>& series) {
    std::string s = "plot ";
    for (size_t i = 0; i < series.size(); ++i) {
        const Series& se = series[i];
        const std::string y =
            se.type < 0 ? fmt::format("{}", se.column) : fmt::format("($3=={}?${}:NaN)", se.type, se.column);
        s += fmt::format("{}'frames.dat' using 1:{} with points pt {} ps {} lc rgb '{}' title {}",
                         i ? ", " : "", y, se.point, se.size, se.colour, plot::gnuplot_quote(se.title));
    }
    return s + "\n";
}

struct Plots {
    std::string script;
    std::vector<std::string> pngs;
};

// The script for the plots that have data (frametime, latency, passes).
Plots plot_script(const ReportData& d, const std::string& file_name, bool with_passes) {
    Plots p;
    std::vector<Series> ft, lat;
    const char* type_colour[] = {"#0077bb", "#009988", "#ee7733", "#cc3311"};
    for (uint32_t type = 0; type < 4; ++type) {
        const bool any = std::any_of(d.frames.begin(), d.frames.end(), [&](const FrameRecord& r) {
            return r.type == type && std::isfinite(r.ft_ms);
        });
        if (any) ft.push_back({telemetry::frame_type_label(type), type_colour[type], 2, int(type), 7, 0.8});
    }
    auto any_finite = [&](double FrameRecord::*field) {
        return std::any_of(d.frames.begin(), d.frames.end(),
                           [&](const FrameRecord& r) { return std::isfinite(r.*field); });
    };
    // Open circles for the client's figure: it often coincides with the displayed one.
    if (any_finite(&FrameRecord::lat_d_ms))
        lat.push_back({"daemon (submit to output written)", "#0077bb", 4, -1, 7, 0.8});
    if (any_finite(&FrameRecord::lat_c_ms))
        lat.push_back({"client (submit to output held)", "#ee7733", 5, -1, 6, 1.6});
    if (any_finite(&FrameRecord::disp_ms))
        lat.push_back({"displayed (submit to present)", "#009988", 6, -1, 7, 0.6});

    std::string& s = p.script;
    s += "# Generated by `fgsr report`: gnuplot report.gp (in this directory) redraws the plots.\n";
    s += "set encoding utf8\nset grid lc rgb '#dddddd'\nset key below horizontal font ',9'\n";
    s += "set terminal pngcairo noenhanced size 1100,520 font 'sans,10'\n";
    s += "set xlabel 'time (s)'\nset yrange [0:*]\n";
    if (!ft.empty()) {
        s += "set output 'frametime.png'\n";
        s += "set title " +
             plot::gnuplot_quote("fgsr report: " + file_name + ": frame time (present to present)") + "\n";
        s += "set ylabel 'frame time (ms)'\n" + plot_line(ft);
        p.pngs.push_back("frametime.png");
    }
    if (!lat.empty()) {
        s += "set output 'latency.png'\n";
        s += "set title " + plot::gnuplot_quote("fgsr report: " + file_name + ": latency") + "\n";
        s += "set ylabel 'latency (ms)'\n" + plot_line(lat);
        p.pngs.push_back("latency.png");
    }
    if (with_passes) {
        s += "set output 'passes.png'\n";
        s += "set title " + plot::gnuplot_quote("fgsr report: " + file_name + ": GPU time per pass") + "\n";
        s += "set xlabel ''\nset ylabel 'GPU ms (mean over the frames that ran the pass)'\n";
        s += "set style fill solid 0.85 border -1\nset boxwidth 0.7\nset xtics rotate by -30\nset offsets "
             "0.5, 0.5, graph 0.1, 0\n";
        s += "plot 'passes.dat' using 0:2:xtic(1) with boxes lc rgb '#0077bb' notitle, "
             "'' using 0:2:(sprintf('%.3f', $2)) with labels offset 0,0.8 font ',8' notitle\n";
        p.pngs.push_back("passes.png");
    }
    return p;
}

nlohmann::json summary_file(const ReportResult& r, const std::string& title) {
    nlohmann::json sessions = nlohmann::json::array();
    for (size_t i = 0; i < r.data.sessions.size(); ++i) {
        nlohmann::json s = telemetry::session_json(r.data.sessions[i]);
        s["summary"] = telemetry::summary_json(r.data.session_summaries[i]);
        sessions.push_back(std::move(s));
    }
    return {{"source", r.source},
            {"title", title},
            {"rows", r.data.rows},
            {"duration_s",
             std::isfinite(r.data.duration_s) ? nlohmann::json(r.data.duration_s) : nlohmann::json()},
            {"summary", telemetry::summary_json(r.data.summary)},
            {"sessions", std::move(sessions)}};
}

} // namespace

ReportData report_data(std::span<const PresentRow> rows) {
    ReportData d;
    d.rows = rows.size();
    double t0 = std::numeric_limits<double>::quiet_NaN(), t_last = t0;
    for (const PresentRow& r : rows)
        if (std::isfinite(r.time_s)) {
            if (!std::isfinite(t0)) t0 = r.time_s;
            t_last = r.time_s;
        }
    d.duration_s = std::isfinite(t0) ? t_last - t0 : 0.0;
    std::map<std::pair<uint32_t, uint64_t>, size_t> index; // (pid, swapchain) -> session
    std::vector<uint32_t> modes;
    std::vector<std::vector<FrameRecord>> per_session;
    for (const PresentRow& row : rows) {
        auto [it, fresh] = index.try_emplace({row.process_id, row.swapchain}, d.sessions.size());
        const size_t si = it->second;
        if (fresh) {
            SessionInfo s;
            s.id = uint32_t(si + 1);
            s.application = row.application;
            s.client = row.runtime;
            s.pid = row.process_id;
            s.active = false;
            d.sessions.push_back(s);
            modes.push_back(0);
            per_session.emplace_back();
        }
        SessionInfo& s = d.sessions[si];
        s.tiles_total += row.tiles_total;
        s.tiles_skipped += row.tiles_skipped;
        if (!status_ok(row.status)) {
            ++(status_dropped(row.status) ? s.dropped : s.rejected);
            continue;
        }
        FrameRecord f;
        f.session = s.id;
        f.kind = telemetry::Kind::present;
        f.type = record_type(row.frame_type);
        f.t_s = std::isfinite(row.time_s) ? row.time_s - t0 : row.time_s;
        f.ft_ms =
            per_session[si].empty() ? std::numeric_limits<double>::quiet_NaN() : row.ms_between_presents;
        f.lat_d_ms = row.daemon_latency_ms;
        f.lat_c_ms = row.client_latency_ms;
        f.disp_ms = row.ms_until_displayed;
        f.gpu_ms = row.ms_gpu_time;
        f.c2p_ms = row.ms_click_to_photon;
        for (size_t p = 0; p < row.pass_ms.size() && p < f.pass_ms.size(); ++p)
            if (std::isfinite(row.pass_ms[p])) {
                f.has_passes = true;
                f.pass_ms[p] = float(row.pass_ms[p]);
            }
        f.tiles_total = row.tiles_total;
        f.tiles_skipped = row.tiles_skipped;
        f.sequence = row.sequence;
        f.output_index = row.output_index;
        ++s.frames;
        if (f.type != FGSR_FRAME_NONE) ++s.generated;
        modes[si] |= f.type == FGSR_FRAME_UPSCALED       ? FGSR_MODE_SR
                     : f.type == FGSR_FRAME_EXTRAPOLATED ? FGSR_MODE_EXTRAPOLATE
                     : f.type == FGSR_FRAME_INTERPOLATED ? FGSR_MODE_INTERPOLATE
                                                         : 0u;
        d.frames.push_back(f);
        per_session[si].push_back(f);
    }
    for (size_t i = 0; i < d.sessions.size(); ++i) {
        d.sessions[i].mode = telemetry::mode_label(modes[i]);
        d.session_summaries.push_back(telemetry::summarize(per_session[i], std::span(&d.sessions[i], 1)));
    }
    d.summary = telemetry::summarize(d.frames, d.sessions);
    return d;
}

Result<ReportResult> run_report(const ReportOptions& o) {
    auto text = read_file(o.csv);
    if (!text) return text.error();
    auto rows = parse_presentmon_csv(*text);
    if (!rows) return make_error(rows.error().code, o.csv.string() + ": " + rows.error().message);
    ReportResult r;
    r.source = o.csv.string();
    r.data = report_data(*rows);
    const std::string file_name = o.csv.filename().string();
    const std::string title = "fgsr report: " + file_name;

    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) return make_error(Errc::io, "cannot create " + o.out.string() + ": " + ec.message());

    telemetry::StateHeader h;
    h.source = "recorded";
    h.title = title;
    h.now_s = r.data.duration_s;
    h.window_s = r.data.duration_s;
    auto script =
        data_script(telemetry::state_json(h, r.data.sessions, r.data.summary, std::span(r.data.frames)));
    if (!script) return script.error();
    FGSR_TRY(plot::write_text(o.out / "index.html", dashboard::standalone_page(*script)));
    r.written.push_back("index.html");
    std::string summary;
    try {
        summary = summary_file(r, title).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    } catch (const std::exception& e) {
        return make_error(Errc::io, std::string("cannot write summary.json: ") + e.what());
    }
    FGSR_TRY(plot::write_text(o.out / "summary.json", summary));
    r.written.push_back("summary.json");

    if (!o.plots) return r;
    const std::vector<PassMean> passes = pass_means(r.data);
    std::string pd = "# fgsr report: pass mean_gpu_ms frames\n";
    for (const PassMean& p : passes) pd += fmt::format("\"{}\" {} {}\n", p.name, dat(p.mean_ms), p.frames);
    const Plots plots = plot_script(r.data, file_name, !passes.empty());
    if (plots.pngs.empty()) {
        r.note = "no plots: the file has no frame times, latencies or pass times";
        return r;
    }
    FGSR_TRY(plot::write_text(o.out / "frames.dat", frames_dat(r.data)));
    FGSR_TRY(plot::write_text(o.out / "passes.dat", pd));
    FGSR_TRY(plot::write_text(o.out / "report.gp", plots.script));
    if (!plot::gnuplot_available()) {
        r.note = "gnuplot not found (Debian: gnuplot-nox): report.gp written, plots not drawn";
        std::fprintf(stderr, "fgsr report: %s\n", r.note.c_str());
        return r;
    }
    if (o.progress) std::fprintf(stderr, "[report] drawing %zu plots (gnuplot)\n", plots.pngs.size());
    FGSR_TRY(plot::run_gnuplot(o.out, "report.gp"));
    r.written.insert(r.written.end(), plots.pngs.begin(), plots.pngs.end());
    if (passes.empty()) r.note = "no passes.png: the file has no per-pass GPU times";
    return r;
}

std::string report_text(const ReportResult& r) {
    const ReportData& d = r.data;
    const Summary& s = d.summary;
    std::string t = fmt::format("fgsr report of {}: {} rows, {} session{}, {} displayed frames in {} s\n",
                                r.source, d.rows, d.sessions.size(), d.sessions.size() == 1 ? "" : "s",
                                d.frames.size(), num(d.duration_s, 2));
    for (const SessionInfo& si : d.sessions)
        t += fmt::format("  session {}: {} (pid {}, {}), {}: {} frames, {} generated\n", si.id,
                         si.application.empty() ? "?" : si.application, si.pid, si.client, si.mode, si.frames,
                         si.generated);
    t += fmt::format("  {:<22}{:>10}{:>10}{:>10}\n", "frame rate (FPS)", "avg", "1 % low", "0.1 % low");
    t += fmt::format("  {:<22}{:>10}{:>10}{:>10}\n", "", num(s.avg_fps, 1), num(s.low1_fps, 1),
                     num(s.low01_fps, 1));
    t += fmt::format("  {:<22}{:>10}{:>10}{:>10}{:>8}\n", "latency (ms)", "p50", "p90", "p99", "frames");
    auto lat = [&](const char* name, const telemetry::LatencyFigures& l) {
        t += fmt::format("  {:<22}{:>10}{:>10}{:>10}{:>8}\n", name, num(l.p50, 2), num(l.p90, 2),
                         num(l.p99, 2), l.count);
    };
    lat("daemon", s.daemon);
    lat("client", s.client);
    lat("displayed", s.displayed);
    if (s.click_to_photon.count) lat("click to photon", s.click_to_photon);
    t += fmt::format("  dropped {}, rejected {}, tiles skipped {} of {}", s.dropped, s.rejected,
                     s.tiles_skipped, s.tiles_total);
    if (s.tiles_total)
        t += fmt::format(" ({:.1f} %)", 100.0 * double(s.tiles_skipped) / double(s.tiles_total));
    t += "\n";
    std::string files;
    for (const std::string& f : r.written) files += (files.empty() ? "" : ", ") + f;
    t += "  wrote " + files + "\n";
    if (!r.note.empty()) t += "  " + r.note + "\n";
    return t;
}

CLI::App* add_report_command(CLI::App& app, ReportCli& c) {
    auto* cmd = app.add_subcommand(
        "report",
        "Dashboard of a recorded run: HTML page, summary.json and plots from a PresentMon-style CSV "
        "(fgsr replay --telemetry, the layer's FGSR_LAYER_PRESENTS, PresentMon)");
    cmd->add_option("csv", c.csv, "The CSV file")->required();
    cmd->add_option("--out", c.out, "Output directory (index.html, summary.json, PNG plots)")->required();
    cmd->add_flag("--no-plots", c.no_plots, "Do not write or draw the gnuplot plots");
    cmd->add_flag("--quiet", c.quiet, "No status lines on stderr");
    return cmd;
}

int report_main(ReportCli& c) {
    ReportOptions& o = c.options;
    o.csv = c.csv;
    o.out = c.out;
    o.plots = !c.no_plots;
    o.progress = !c.quiet;
    auto r = run_report(o);
    if (!r) return report_error(r.error());
    std::fputs(report_text(*r).c_str(), stdout);
    return 0;
}

} // namespace fgsr::cli
