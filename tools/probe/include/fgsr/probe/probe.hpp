// A click-to-photon probe as `fgsr probe` uses it, whatever its protocol: what it is (ProbeInfo),
// one measurement (Sample), and a run of N measurements (Probe::run). The transports are
// osltt_probe.cpp (the OSLTT text protocol over CDC-ACM) and vendor_probe.cpp (fgsr's vendor-bulk
// protocol); open_probe() in device.hpp picks one.
//
// Times: click_ns and photon_ns are CLOCK_MONOTONIC nanoseconds (fgsr/core/clock.hpp), the probe's
// clock mapped onto it (vendor protocol: ClockMap; OSLTT, which has no device timestamps: the
// host's arrival time of the result less the probe's reported durations, docs/PROBE.md).
// latency_ms comes from the probe's own clock alone (photon minus click, in the probe's ticks at
// its nominal rate), so it does not inherit the mapping's error.
#pragma once

#include <fgsr/core/result.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fgsr::probe {

enum class Protocol {
    osltt, // OSLTT's text protocol over a CDC-ACM data interface's bulk endpoints
    fgsr,  // fgsr's vendor-bulk protocol (docs/PROBE.md)
};
const char* protocol_name(Protocol p); // "osltt", "fgsr"

// Sample::flags
inline constexpr uint32_t kSampleSaturated = 0x1; // the sensor saturated (vendor flag)

struct Sample {
    uint32_t index = 0;                                   // 0-based, in the order the probe measured
    double latency_ms = 0;                                // photon minus click, > 0
    uint64_t click_ns = 0;                                // CLOCK_MONOTONIC
    uint64_t photon_ns = 0;                               // CLOCK_MONOTONIC, >= click_ns
    uint32_t brightness_before = 0, brightness_after = 0; // sensor units (OSLTT: ADC counts)
    uint32_t flags = 0;                                   // kSample*
};

struct ProbeInfo {
    std::string name; // "OSLTT", or the vendor probe's name string
    Protocol protocol = Protocol::fgsr;
    std::string firmware;                     // as the probe reports it
    double clock_hz = 0;                      // the probe's timestamp clock (0: none, OSLTT)
    std::string usb;                          // "bus 1 address 5 (1209:0001)"
    std::vector<uint8_t> detached_interfaces; // whose kernel driver was detached to claim them
};

struct RunOptions {
    uint32_t count = 20;          // measurements, 1 .. 10000
    uint32_t interval_ms = 300;   // between clicks (vendor protocol; OSLTT: the probe's setting)
    uint32_t threshold = 0;       // brightness change that counts as the photon (0: the probe's default)
    int timeout_ms = 2000;        // longest wait for any reply or the next sample beyond its interval
    int start_timeout_ms = 60000; // OSLTT: longest wait for the first result (a person presses its button)
    bool progress = true;         // a line per sample on stderr
    std::string progress_prefix;  // before each progress line ("interpolate: ")
    std::function<void(const Sample&)> on_sample; // each sample as it arrives
    const std::atomic<bool>* cancel = nullptr;    // set: stop at the next reply (an error "interrupted")
};

struct RunResult {
    std::vector<Sample> samples;
    uint32_t missed = 0;            // clicks whose change the probe did not see (not in samples)
    std::vector<std::string> notes; // unknown lines ignored and the like, for the report
    double clock_error_ms = 0;      // bound of the clock mapping's error (vendor), 0 when unknown
};

class Probe {
  public:
    virtual ~Probe() = default;
    virtual const ProbeInfo& info() const = 0;
    // Runs options.count measurements. Fails (with a message naming the step) on a timeout, a
    // stall, an unplug, garbage or a protocol violation; never waits longer than the timeouts.
    virtual Result<RunResult> run(const RunOptions& options) = 0;
};

} // namespace fgsr::probe
