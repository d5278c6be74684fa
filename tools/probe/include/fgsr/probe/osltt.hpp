// OSLTT's text protocol (the Open Source Latency Testing Tool's firmware on a CDC-ACM serial link,
// 115200 8N1, DTR on; docs/PROBE.md "OSLTT" says what is taken from the firmware and what is
// assumed): the pure part, without USB, so that it is tested on its own.
//
// The host sends single letters: "I" (identify: the firmware answers "FW:<version>"), "X" (leave the
// current mode), "T" (test mode: each press of the probe's button runs its auto-click series, one
// "RES:" line per click, then "AUTO FINISHED" or "SINGLE FIRE"). A result line:
//
//   RES:<click_delay_us>,<window_us>,<n>,<adc_0>,...,<adc_{n-1}>,
//
// click_delay_us: from the injected click to the first ADC sample; window_us: the time the n ADC
// samples took; adc_i: the photodiode's readings (14-bit). The change is the first sample i > 100
// above twice the mean of samples 0..99 (the firmware's own rule); the latency is
// click_delay_us + i * window_us / n. Lines the firmware prints otherwise ("RESULT:", its greeting,
// "Settings Synced", ...) are not errors: the reader skips what it does not know, but it refuses
// binary data and lines past kMaxLineBytes.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace fgsr::probe {

// A RES: line of 9000 samples is about 50 kB; anything past 1 MiB is not OSLTT.
inline constexpr size_t kMaxLineBytes = 1 << 20;
// The firmware samples 9000 times; fewer than the 101 the rule needs, or absurdly many, is garbage.
inline constexpr uint32_t kMinResSamples = 101, kMaxResSamples = 200000;

// Splits the serial byte stream into lines (LF, an optional CR before it dropped).
class LineReader {
  public:
    // Fails on a byte that is not text (below 0x20 except tab, CR, LF; or 0x7f and above), naming
    // it and its offset in the stream, and on a line longer than kMaxLineBytes.
    Result<void> feed(std::span<const uint8_t> bytes);
    std::optional<std::string> next_line();
    size_t pending_bytes() const { return partial_.size(); }

  private:
    std::string partial_;
    std::deque<std::string> lines_;
    uint64_t offset_ = 0;
};

struct OslttResult {
    uint32_t click_delay_us = 0, window_us = 0, sample_count = 0;
    uint32_t baseline = 0;      // mean of samples 0..99
    uint32_t trigger_index = 0; // the first sample above 2 x baseline (0: none: the change was not seen)
    uint32_t level_after = 0;   // that sample's reading
    double latency_ms = 0;      // NaN when trigger_index is 0
};

// Parses a "RES:" line (strict: every field a decimal number in range, n values and then only the
// trailing comma). Errors name the field.
Result<OslttResult> parse_osltt_result(std::string_view line);

// "FW:0.10" -> "0.10"; nullopt for any other line.
std::optional<std::string> parse_osltt_firmware(std::string_view line);

} // namespace fgsr::probe
