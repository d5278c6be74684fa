// Frame-rate and latency figures as the tools people tune frame generation with report them
// (CapFrameX, MangoHud, PresentMon's summaries): average FPS, 1 % and 0.1 % low FPS, latency
// percentiles. One implementation for fgsrd's dashboard and /metrics, `fgsr report` and the tests.
//
// Definitions (docs/TELEMETRY.md):
//   average FPS   frames / sum of their frame times (not the mean of per-frame FPS);
//   x % low FPS   1000 / mean of the slowest ceil(x % of n) frame times, in ms: the average frame
//                 rate of the worst x % of frames (higher is better); with fewer than 1/x frames
//                 it is the slowest frame alone;
//   percentile q  nearest rank: the smallest sample with at least q of the samples at or below it
//                 (p99 latency: 99 % of frames had at most this latency; lower is better).
// Empty input gives NaN everywhere (shown as "NA" / null by the writers).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace fgsr {

// Nearest-rank percentile of `samples` (q in [0, 1]); NaN when empty. NaN samples are ignored.
double percentile(std::span<const double> samples, double q);

struct Percentiles {
    double p50, p90, p99;
    size_t count; // samples that were not NaN
};
Percentiles percentiles(std::span<const double> samples);

struct FrameRate {
    double avg_fps, low1_fps, low01_fps;
    size_t frames; // frame times used (finite and positive)
};
// frame_times_ms: the intervals between consecutive displayed frames, in ms.
FrameRate frame_rate(std::span<const double> frame_times_ms);

} // namespace fgsr
