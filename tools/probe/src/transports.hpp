// Inside fgsr_probe: the constructors of the two transports that open_probe() (device.cpp) picks
// between, and small helpers they share (progress lines, deadlines).
#pragma once

#include <fgsr/probe/device.hpp>
#include <fgsr/probe/usb.hpp>

#include <chrono>
#include <memory>

namespace fgsr::probe::detail {

// dev: the opened device, nothing claimed yet.
Result<std::unique_ptr<Probe>> open_osltt(UsbDevice dev, const ProbeDevice& device,
                                          const OpenOptions& options);
Result<std::unique_ptr<Probe>> open_vendor(UsbDevice dev, const ProbeDevice& device,
                                           const OpenOptions& options);

using Clock = std::chrono::steady_clock;

// Milliseconds left until deadline (at least 1 while it has not passed, 0 after).
inline int ms_left(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return Clock::now() < deadline ? 1 : 0;
    return left > 1000000 ? 1000000 : int(left);
}

inline bool cancelled(const RunOptions& o) {
    return o.cancel && o.cancel->load(std::memory_order_relaxed);
}

// "sample 3/20: 12.345 ms" on stderr when o.progress.
void print_progress(const RunOptions& o, const Sample& s);

} // namespace fgsr::probe::detail
