// The vendor probe's clock mapped onto CLOCK_MONOTONIC. Each SYNC exchange gives a point: the
// device's timestamp (ticks) and the host's times just before sending SYNC and just after the
// reply arrived; the device read its clock somewhere in between, best estimated by the midpoint,
// with an error of at most half the round trip.
//
// fit(): keeps the exchanges with the shortest round trips (the better half, at least one), then
//   - offset: least squares of host midpoint against device ticks with the rate fixed, or
//   - rate and offset by least squares when the kept points span at least min_span_s of device
//     time (syncs before and after a run of a few seconds), which follows the probe's crystal
//     drift (shorter spans leave the rate nominal: a 0.2 ms midpoint error over 2 s is 100 ppm);
// a fitted rate more than kMaxDriftPpm off the nominal one is an error (a wrong clock_hz or a
// broken timestamp counter). error_ns(): half the longest kept round trip plus the largest fit
// residual: a bound on how far a mapped time can be from the truth.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <span>

namespace fgsr::probe {

struct SyncPoint {
    uint64_t device_ticks = 0;
    uint64_t host_before_ns = 0, host_after_ns = 0; // CLOCK_MONOTONIC around the exchange
};

inline constexpr double kMaxDriftPpm = 1000;

class ClockMap {
  public:
    static Result<ClockMap> fit(std::span<const SyncPoint> points, double nominal_hz,
                                double min_span_s = 2.0);

    uint64_t to_monotonic_ns(uint64_t device_ticks) const;
    // Nanoseconds of a tick difference at the nominal rate (latencies use this: exact to the
    // crystal's tolerance and independent of the fit).
    double ticks_to_ns(uint64_t ticks) const { return double(ticks) * 1e9 / nominal_hz_; }
    // How fast the probe's clock runs against its nominal rate (> 0: fast), as fitted.
    double drift_ppm() const { return (1e9 / (double(ns_per_tick_) * nominal_hz_) - 1) * 1e6; }
    double error_ns() const { return error_ns_; }
    bool rate_fitted() const { return rate_fitted_; }

  private:
    double nominal_hz_ = 1;
    long double ns_per_tick_ = 1;
    uint64_t ref_ticks_ = 0; // device ticks of the reference point
    long double ref_ns_ = 0; // its host time (fitted)
    double error_ns_ = 0;
    bool rate_fitted_ = false;
};

} // namespace fgsr::probe
