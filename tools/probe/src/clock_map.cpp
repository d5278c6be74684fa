// Device clock to CLOCK_MONOTONIC: round-trip midpoints, best half kept, least-squares fit.
#include <fgsr/probe/clock_map.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace fgsr::probe {

Result<ClockMap> ClockMap::fit(std::span<const SyncPoint> points, double nominal_hz, double min_span_s) {
    if (!(nominal_hz >= 1000 && nominal_hz <= 1e9))
        return make_error(Errc::invalid_argument, "clock mapping: nominal rate " +
                                                      std::to_string(nominal_hz) + " Hz (1 kHz to 1 GHz)");
    std::vector<SyncPoint> kept;
    for (const SyncPoint& p : points)
        if (p.host_after_ns >= p.host_before_ns) kept.push_back(p);
    if (kept.empty()) return make_error(Errc::empty_input, "clock mapping: no synchronisation exchange");
    std::sort(kept.begin(), kept.end(), [](const SyncPoint& a, const SyncPoint& b) {
        return a.host_after_ns - a.host_before_ns < b.host_after_ns - b.host_before_ns;
    });
    kept.resize(std::max<size_t>(1, (kept.size() + 1) / 2));

    ClockMap m;
    m.nominal_hz_ = nominal_hz;
    // Work relative to the first kept point: ticks and ns differences fit easily in long double.
    const uint64_t t0 = kept.front().device_ticks;
    const long double h0 = (long double)(kept.front().host_before_ns) +
                           (long double)(kept.front().host_after_ns - kept.front().host_before_ns) / 2;
    std::vector<long double> x, y;
    long double max_half_rtt = 0;
    for (const SyncPoint& p : kept) {
        x.push_back((long double)(int64_t(p.device_ticks - t0)));
        const long double mid =
            (long double)(p.host_before_ns) + (long double)(p.host_after_ns - p.host_before_ns) / 2;
        y.push_back(mid - h0);
        max_half_rtt = std::max(max_half_rtt, (long double)(p.host_after_ns - p.host_before_ns) / 2);
    }
    const auto [xmin, xmax] = std::minmax_element(x.begin(), x.end());
    const long double span_s = (*xmax - *xmin) / nominal_hz;
    const size_t n = x.size();
    long double mx = 0, my = 0;
    for (size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
    mx /= n;
    my /= n;
    long double slope = 1e9L / nominal_hz;
    if (n >= 2 && span_s >= min_span_s) {
        long double sxy = 0, sxx = 0;
        for (size_t i = 0; i < n; ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
        if (sxx > 0) {
            slope = sxy / sxx;
            m.rate_fitted_ = true;
        }
    }
    m.ns_per_tick_ = slope;
    const double drift = m.drift_ppm();
    if (!std::isfinite(drift) || std::fabs(drift) > kMaxDriftPpm) {
        char b[200];
        std::snprintf(
            b, sizeof b,
            "clock mapping: the probe's clock runs %+.0f ppm off its stated %.0f Hz (more than %.0f ppm: "
            "a wrong clock_hz, or timestamps that do not count steadily)",
            drift, nominal_hz, kMaxDriftPpm);
        return make_error(Errc::io, b);
    }
    // The line through the centroid.
    m.ref_ticks_ = t0 + uint64_t(int64_t(std::llroundl(mx)));
    m.ref_ns_ = h0 + my + slope * ((long double)(int64_t(m.ref_ticks_ - t0)) - mx);
    long double worst = 0;
    for (size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(y[i] - (my + slope * (x[i] - mx))));
    m.error_ns_ = double(max_half_rtt + worst);
    return m;
}

uint64_t ClockMap::to_monotonic_ns(uint64_t device_ticks) const {
    const long double d = (long double)(int64_t(device_ticks - ref_ticks_));
    const long double ns = ref_ns_ + d * ns_per_tick_;
    return ns <= 0 ? 0 : uint64_t(std::llroundl(ns));
}

} // namespace fgsr::probe
