// Latency summaries, the side-by-side table of the modes, and the per-sample CSV.
#include <fgsr/probe/report.hpp>

#include <fgsr/core/frame_stats.hpp>
#include <fgsr/core/presentmon.hpp>
#include <fgsr/protocol.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

namespace fgsr::probe {

static_assert(uint32_t(Mode::unknown) == FGSR_PROBE_MODE_UNKNOWN &&
                  uint32_t(Mode::off) == FGSR_PROBE_MODE_OFF &&
                  uint32_t(Mode::interpolate) == FGSR_PROBE_MODE_INTERPOLATE &&
                  uint32_t(Mode::extrapolate) == FGSR_PROBE_MODE_EXTRAPOLATE,
              "Mode mirrors FGSR_PROBE_MODE_*");

namespace {

std::string ms(double v) {
    if (!std::isfinite(v)) return "NA";
    char b[32];
    std::snprintf(b, sizeof b, "%.3f", v);
    return b;
}

} // namespace

const char* mode_name(Mode m) {
    switch (m) {
    case Mode::off:
        return "off";
    case Mode::interpolate:
        return "interpolate";
    case Mode::extrapolate:
        return "extrapolate";
    case Mode::unknown:
        break;
    }
    return "unknown";
}

Result<std::vector<Mode>> parse_modes(std::string_view text) {
    std::vector<Mode> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t comma = std::min(text.find(',', pos), text.size());
        const std::string_view item = text.substr(pos, comma - pos);
        pos = comma + 1;
        if (item.empty()) continue;
        Mode m;
        if (item == "off")
            m = Mode::off;
        else if (item == "interpolate")
            m = Mode::interpolate;
        else if (item == "extrapolate")
            m = Mode::extrapolate;
        else
            return make_error(Errc::invalid_argument, "--modes: '" + std::string(item) +
                                                          "' (expected off, interpolate, extrapolate)");
        if (std::find(out.begin(), out.end(), m) != out.end())
            return make_error(Errc::invalid_argument, "--modes: '" + std::string(item) + "' given twice");
        out.push_back(m);
    }
    if (out.empty())
        return make_error(Errc::invalid_argument, "--modes: no mode (off, interpolate, extrapolate)");
    return out;
}

LatencySummary summarize(std::span<const Sample> samples) {
    LatencySummary s;
    std::vector<double> v;
    v.reserve(samples.size());
    for (const Sample& x : samples) v.push_back(x.latency_ms);
    const Percentiles p = percentiles(v);
    s.count = p.count;
    s.p50 = p.p50;
    s.p90 = p.p90;
    s.p99 = p.p99;
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    s.min = s.max = s.mean = kNaN;
    double sum = 0;
    size_t n = 0;
    for (double x : v) {
        if (!std::isfinite(x)) continue;
        s.min = n ? std::min(s.min, x) : x;
        s.max = n ? std::max(s.max, x) : x;
        sum += x;
        ++n;
    }
    if (n) s.mean = sum / double(n);
    return s;
}

std::string summary_line(const LatencySummary& s) {
    return "click-to-photon latency over " + std::to_string(s.count) + " samples: p50 " + ms(s.p50) +
           " ms, p90 " + ms(s.p90) + " ms, p99 " + ms(s.p99) + " ms, min " + ms(s.min) + " ms, max " +
           ms(s.max) + " ms, mean " + ms(s.mean) + " ms";
}

std::string modes_table(std::span<const ModeColumn> columns) {
    std::string out;
    char b[64];
    const auto row = [&](const char* label, auto value) {
        std::snprintf(b, sizeof b, "%-16s", label);
        out += b;
        for (const ModeColumn& c : columns) {
            std::snprintf(b, sizeof b, " %13s", value(c).c_str());
            out += b;
        }
        out += '\n';
    };
    out += "click-to-photon latency (ms)\n";
    row("mode", [](const ModeColumn& c) { return std::string(mode_name(c.mode)); });
    row("samples", [](const ModeColumn& c) { return std::to_string(c.summary.count); });
    row("missed", [](const ModeColumn& c) { return std::to_string(c.missed); });
    row("p50", [](const ModeColumn& c) { return ms(c.summary.p50); });
    row("p90", [](const ModeColumn& c) { return ms(c.summary.p90); });
    row("p99", [](const ModeColumn& c) { return ms(c.summary.p99); });
    row("min", [](const ModeColumn& c) { return ms(c.summary.min); });
    row("max", [](const ModeColumn& c) { return ms(c.summary.max); });
    row("mean", [](const ModeColumn& c) { return ms(c.summary.mean); });
    return out;
}

std::string csv_text(std::span<const CsvRun> runs) {
    std::string out = presentmon_header() +
                      ",probe_mode,probe_index,probe_click_ns,probe_photon_ns,probe_brightness_before,"
                      "probe_brightness_after,probe_flags\n";
    for (const CsvRun& run : runs) {
        for (const Sample& s : run.samples) {
            PresentRow r;
            r.application = run.application;
            r.process_id = run.pid;
            r.swapchain = uint32_t(run.mode);
            r.frame_type = "Application";
            r.time_s = double(s.photon_ns) / 1e9;
            r.ms_click_to_photon = s.latency_ms;
            r.sequence = s.index;
            char extra[192];
            std::snprintf(extra, sizeof extra, ",%s,%u,%" PRIu64 ",%" PRIu64 ",%u,%u,%u\n",
                          mode_name(run.mode), s.index, s.click_ns, s.photon_ns, s.brightness_before,
                          s.brightness_after, s.flags);
            out += presentmon_row(r);
            out += extra;
        }
    }
    return out;
}

Result<void> write_csv(const std::filesystem::path& path, std::span<const CsvRun> runs) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    if (!f) return make_error(Errc::io, path.string() + ": cannot create");
    const std::string text = csv_text(runs);
    f.write(text.data(), std::streamsize(text.size()));
    f.close();
    if (!f) return make_error(Errc::io, path.string() + ": write failed");
    return {};
}

} // namespace fgsr::probe
