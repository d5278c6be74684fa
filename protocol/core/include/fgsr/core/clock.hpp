// CLOCK_MONOTONIC in nanoseconds: the one clock of every timestamp fgsr exchanges (submit, dequeue,
// completion and calibrated GPU times; protocol.h) and of every deadline it keeps.
#pragma once

#include <cstdint>
#include <ctime>

namespace fgsr {

inline uint64_t monotonic_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

} // namespace fgsr
