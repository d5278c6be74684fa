#include <fgsr/core/frame_stats.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace fgsr {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<double> finite(std::span<const double> v) {
    std::vector<double> out;
    out.reserve(v.size());
    for (double x : v)
        if (std::isfinite(x)) out.push_back(x);
    return out;
}

// Nearest rank on sorted, non-empty samples.
double ranked(const std::vector<double>& sorted, double q) {
    const double n = double(sorted.size());
    const size_t rank = size_t(std::max(1.0, std::ceil(std::clamp(q, 0.0, 1.0) * n)));
    return sorted[std::min(sorted.size(), rank) - 1];
}

// 1000 / mean of the slowest ceil(share * n) frame times (sorted descending).
double low_fps(const std::vector<double>& descending, double share) {
    const size_t k = std::max<size_t>(1, size_t(std::ceil(share * double(descending.size()))));
    double sum = 0;
    for (size_t i = 0; i < k; ++i) sum += descending[i];
    return 1000.0 * double(k) / sum;
}

} // namespace

double percentile(std::span<const double> samples, double q) {
    std::vector<double> v = finite(samples);
    if (v.empty()) return kNaN;
    std::sort(v.begin(), v.end());
    return ranked(v, q);
}

Percentiles percentiles(std::span<const double> samples) {
    std::vector<double> v = finite(samples);
    if (v.empty()) return {kNaN, kNaN, kNaN, 0};
    std::sort(v.begin(), v.end());
    return {ranked(v, 0.50), ranked(v, 0.90), ranked(v, 0.99), v.size()};
}

FrameRate frame_rate(std::span<const double> frame_times_ms) {
    std::vector<double> v;
    v.reserve(frame_times_ms.size());
    for (double x : frame_times_ms)
        if (std::isfinite(x) && x > 0) v.push_back(x);
    if (v.empty()) return {kNaN, kNaN, kNaN, 0};
    double sum = 0;
    for (double x : v) sum += x;
    std::sort(v.begin(), v.end(), std::greater<>());
    return {1000.0 * double(v.size()) / sum, low_fps(v, 0.01), low_fps(v, 0.001), v.size()};
}

} // namespace fgsr
