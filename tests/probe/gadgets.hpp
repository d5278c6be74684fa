// The device side of the probes fgsr_probe drives, written for the tests from the protocol
// descriptions (docs/PROBE.md), independently of the host code: an OSLTT (CDC-ACM serial with its
// text protocol, its cdc_acm driver bound until detached) and a probe of fgsr's vendor-bulk
// protocol (with a clock of its own, drift and offset included). Each has scenario knobs for the
// fault cases: never answer, stop answering, stall, unplug, garbage, protocol violations.
//
// Times are the host's CLOCK_MONOTONIC as the emulator passes it (now_ns): a result becomes
// available when its photon time has passed, so runs take real (short) time.
#pragma once

#include "usb_emulation.hpp"

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::probe::test {

// Descriptors of the emulated devices.
UsbIdentity osltt_identity(uint16_t vid = 0x2886, uint16_t pid = 0x802f);
UsbIdentity fgsr_identity(uint16_t vid = 0x1209, uint16_t pid = 0x0001);
UsbIdentity mouse_identity();  // 046d:c077, a HID mouse: not a probe
DriverBinding osltt_drivers(); // cdc_acm on interfaces 0 and 1 (one group), usbhid on 2

// Builds a RES: line as OSLTT's firmware prints it, with the change at the sample that gives
// latency_us exactly: window_us = 5 * n, so sample i is at click_delay_us + 5 i us. latency_us must
// be click_delay_us + 5 i with 101 <= i < n. change = false: no sample crosses the threshold.
std::string osltt_res_line(uint32_t click_delay_us, uint32_t n, uint32_t latency_us, bool change = true);

struct OslttScenario {
    std::vector<uint32_t> latencies_us;            // one RES: line per value
    uint32_t click_delay_us = 120, samples = 9000; // the firmware's: changes up to 45 ms are seen
    std::vector<size_t> misses;                    // result indexes printed without a change
    uint32_t interval_ms = 5;                      // between results
    uint32_t series = 0;                           // results per button press (0: all in one series)
    uint32_t press_after_ms = 20;                  // the emulated button press, after "T"
    bool never_answer = false;                     // prints nothing at all
    bool chatter = true;                           // greeting numbers, "RESULT:", other firmware lines
    std::optional<size_t> silent_after;            // stops after this many results (a timeout)
    std::optional<size_t> garbage_after;           // binary bytes instead of the next result
    std::optional<size_t> malformed_after;         // a RES: line with a bad field instead
    std::optional<size_t> stall_after;             // the IN endpoint stalls
    std::optional<size_t> unplug_after;            // the device vanishes
    std::string firmware = "0.10";
};

class OslttGadget final : public Gadget {
  public:
    explicit OslttGadget(OslttScenario s) : s_(std::move(s)) {}
    bool control(const Setup& setup, std::span<const uint8_t> data, uint64_t now_ns) override;
    bool bulk_out(uint8_t endpoint, std::span<const uint8_t> data, uint64_t now_ns) override;
    InResult bulk_in(uint8_t endpoint, size_t max_bytes, uint64_t now_ns) override;

    bool dtr = false;
    uint32_t baud = 0;
    std::string received; // every byte the host sent
    size_t results_sent = 0;

  private:
    void emit(std::string text, uint64_t at_ns);
    void handle_token(char c, uint64_t now_ns);
    OslttScenario s_;
    struct Chunk {
        uint64_t at_ns;
        std::string bytes;
        bool is_result;
    };
    std::deque<Chunk> out_;
    std::string input_;
    bool test_mode_ = false, greeted_ = false, silent_ = false;
    uint64_t next_greeting_ns_ = 0;
    size_t scheduled_ = 0;
};

struct VendorScenario {
    std::vector<uint32_t> latencies_ticks; // per sample, in device ticks (used cyclically)
    uint32_t clock_hz = 1000000;
    double drift_ppm = 0;                   // the device clock's true rate is clock_hz * (1 + drift)
    uint64_t boot_offset_ticks = 123456789; // device ticks at host time 0 of the emulation
    uint32_t max_count = 1000;
    std::vector<size_t> misses; // sample indexes flagged NO_CHANGE
    bool never_answer = false;
    std::optional<size_t> silent_after;
    std::optional<size_t> garbage_after; // a message with a wrong magic instead of that sample
    std::optional<size_t> stall_after;
    std::optional<size_t> unplug_after;
    std::optional<size_t> bad_photon_after; // photon_ts before click_ts
    std::optional<size_t> skip_index_after; // index jumps by one
    std::optional<uint16_t> start_error;    // ERROR(code) instead of START's ACK
    bool garbage_info = false;              // GET_INFO answered with garbage
    // Latencies change with each START (run k uses latencies_ticks scaled by run_scale[k]).
    std::vector<double> run_scale;
};

class VendorGadget final : public Gadget {
  public:
    explicit VendorGadget(VendorScenario s);
    bool control(const Setup& setup, std::span<const uint8_t> data, uint64_t now_ns) override;
    bool bulk_out(uint8_t endpoint, std::span<const uint8_t> data, uint64_t now_ns) override;
    InResult bulk_in(uint8_t endpoint, size_t max_bytes, uint64_t now_ns) override;

    uint64_t device_ticks(uint64_t host_ns) const;
    // The host time of each sample's click (the truth the clock mapping should recover), per START.
    std::vector<std::vector<uint64_t>> click_host_ns;
    std::vector<std::vector<uint32_t>> latencies_sent; // ticks, per START
    size_t starts = 0, syncs = 0, aborts = 0;

  private:
    void reply(std::vector<uint8_t> message, uint64_t at_ns, bool is_sample = false);
    VendorScenario s_;
    uint64_t epoch_ns_;
    struct Message {
        uint64_t at_ns;
        std::vector<uint8_t> bytes;
        bool is_sample;
    };
    std::deque<Message> out_;
    size_t samples_sent_ = 0;
};

} // namespace fgsr::probe::test
