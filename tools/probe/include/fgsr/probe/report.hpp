// What `fgsr probe` prints and writes: the latency summary of a run (nearest-rank percentiles of
// fgsr/core/frame_stats.hpp, min, max, mean), the side-by-side table of the measurement mode, and
// the per-sample CSV.
//
// The CSV is PresentMon's columns (fgsr/core/presentmon.hpp), one row per sample: Application the
// measured program (or "fgsr-probe"), ProcessID its pid (0 unknown), SwapChainAddress the mode
// number (FGSR_PROBE_MODE_*, so that `fgsr report` shows each mode as a session of its own),
// FrameType "Application", TimeInSeconds the photon time (CLOCK_MONOTONIC s),
// MsClickToPhotonLatency the latency, every other column NA; then the probe's own columns, which
// PresentMon readers ignore: probe_mode (off, interpolate, extrapolate, unknown), probe_index,
// probe_click_ns, probe_photon_ns, probe_brightness_before, probe_brightness_after, probe_flags.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/probe/probe.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace fgsr::probe {

// = FGSR_PROBE_MODE_* of fgsr/protocol.h (checked there by a static_assert in report.cpp).
enum class Mode : uint32_t { unknown = 0, off = 1, interpolate = 2, extrapolate = 3 };
const char* mode_name(Mode m); // "unknown", "off", "interpolate", "extrapolate"
// "off,interpolate,extrapolate" -> modes (each at most once; at least one).
Result<std::vector<Mode>> parse_modes(std::string_view text);

struct LatencySummary {
    size_t count = 0;
    double p50 = 0, p90 = 0, p99 = 0, min = 0, max = 0, mean = 0; // ms; NaN when count is 0
};
LatencySummary summarize(std::span<const Sample> samples);

// "click-to-photon latency over 20 samples: p50 12.345 ms, p90 ..., p99 ..., min ..., max ..."
std::string summary_line(const LatencySummary& s);

// One column per mode: samples, missed, p50, p90, p99, min, max, mean.
struct ModeColumn {
    Mode mode;
    LatencySummary summary;
    uint32_t missed = 0;
};
std::string modes_table(std::span<const ModeColumn> columns);

struct CsvRun {
    Mode mode = Mode::unknown;
    uint32_t pid = 0;
    std::string application = "fgsr-probe";
    std::span<const Sample> samples;
};
std::string csv_text(std::span<const CsvRun> runs); // header and rows, newline-terminated
Result<void> write_csv(const std::filesystem::path& path, std::span<const CsvRun> runs);

} // namespace fgsr::probe
