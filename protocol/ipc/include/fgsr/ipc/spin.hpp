// Bounded busy-waiting, for both ends of the wire: libfgsr_client spins briefly for a completion
// before it sleeps on the complete eventfd (fgsr_wait), fgsrd's I/O thread and lanes spin briefly
// for their next event before they sleep (docs/SERVICE.md, "Spinning"). A spin saves the wake-up of
// a sleeping thread (tens to hundreds of microseconds on a shared VM) when the event comes soon; it
// costs the CPU time it spins when it does not.
//
// Contract: spin_until never runs longer than its budget (plus one call of `ready` and one
// sched_yield); a budget of 0 calls `ready` once. It never blocks and never throws unless `ready`
// does. Thread-safe (no state).
#pragma once

#include <cstdint>
#include <ctime>
#include <sched.h>

namespace fgsr::ipc {

// A hint to the CPU that this thread is spinning (x86 PAUSE, AArch64 YIELD; nothing elsewhere).
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield" ::: "memory");
#endif
}

inline uint64_t spin_clock_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

// Calls ready() until it returns true or budget_ns (CLOCK_MONOTONIC) has passed; returns its last
// value. Between calls: a few pause instructions, and every kYieldEvery calls a sched_yield(), so
// that on a machine with fewer cores than runnable threads the thread being waited for gets the
// core (on an idle core sched_yield returns at once).
template <class F> bool spin_until(F&& ready, uint64_t budget_ns) {
    constexpr unsigned kPauses = 16, kYieldEvery = 8;
    if (ready()) return true;
    if (budget_ns == 0) return false;
    const uint64_t end = spin_clock_ns() + budget_ns;
    for (unsigned round = 1;; ++round) {
        for (unsigned i = 0; i < kPauses; ++i) cpu_relax();
        if (round % kYieldEvery == 0) sched_yield();
        if (ready()) return true;
        if (spin_clock_ns() >= end) return false;
    }
}

} // namespace fgsr::ipc
