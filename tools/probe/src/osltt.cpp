// OSLTT's text protocol without USB: the line reader and the parsers of "RES:" and "FW:" lines.
#include <fgsr/probe/osltt.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace fgsr::probe {

namespace {

bool is_text(uint8_t c) {
    return c == '\t' || c == '\r' || c == '\n' || (c >= 0x20 && c < 0x7f);
}

std::string shown(std::string_view s) {
    constexpr size_t kShow = 60;
    return s.size() <= kShow ? std::string(s) : std::string(s.substr(0, kShow)) + "...";
}

// The next comma-terminated decimal field of s from pos; advances pos past the comma.
bool next_field(std::string_view s, size_t& pos, uint64_t limit, uint64_t& out) {
    const size_t comma = s.find(',', pos);
    if (comma == std::string_view::npos || comma == pos) return false;
    const char* b = s.data() + pos;
    const char* e = s.data() + comma;
    auto [p, ec] = std::from_chars(b, e, out);
    if (ec != std::errc() || p != e || out > limit) return false;
    pos = comma + 1;
    return true;
}

} // namespace

Result<void> LineReader::feed(std::span<const uint8_t> bytes) {
    for (size_t i = 0; i < bytes.size(); ++i) {
        const uint8_t c = bytes[i];
        if (!is_text(c)) {
            char b[160];
            std::snprintf(
                b, sizeof b,
                "binary data from the probe (byte 0x%02x at offset %llu of its output): not OSLTT's "
                "text protocol",
                unsigned(c), static_cast<unsigned long long>(offset_ + i));
            return make_error(Errc::io, b);
        }
        if (c == '\n') {
            if (!partial_.empty() && partial_.back() == '\r') partial_.pop_back();
            lines_.push_back(std::move(partial_));
            partial_.clear();
        } else {
            if (partial_.size() >= kMaxLineBytes)
                return make_error(Errc::io, "a line from the probe is longer than " +
                                                std::to_string(kMaxLineBytes) +
                                                " bytes: not OSLTT's text protocol");
            partial_ += char(c);
        }
    }
    offset_ += bytes.size();
    return {};
}

std::optional<std::string> LineReader::next_line() {
    if (lines_.empty()) return std::nullopt;
    std::string l = std::move(lines_.front());
    lines_.pop_front();
    return l;
}

Result<OslttResult> parse_osltt_result(std::string_view line) {
    const std::string_view prefix = "RES:";
    if (line.substr(0, prefix.size()) != prefix)
        return make_error(Errc::io, "not a RES: line: '" + shown(line) + "'");
    const auto bad = [&](const std::string& what) {
        return make_error(Errc::io,
                          "malformed RES: line from the probe (" + what + "): '" + shown(line) + "'");
    };
    size_t pos = prefix.size();
    uint64_t delay = 0, window = 0, n = 0;
    if (!next_field(line, pos, 10000000, delay)) return bad("click delay: a number of us up to 10 s");
    if (!next_field(line, pos, 10000000, window) || window == 0)
        return bad("window: a number of us, 1 us to 10 s");
    if (!next_field(line, pos, kMaxResSamples, n) || n < kMinResSamples)
        return bad("sample count: " + std::to_string(kMinResSamples) + " to " +
                   std::to_string(kMaxResSamples));
    OslttResult r;
    r.click_delay_us = uint32_t(delay);
    r.window_us = uint32_t(window);
    r.sample_count = uint32_t(n);
    uint64_t sum = 0;
    for (uint32_t i = 0; i < r.sample_count; ++i) {
        uint64_t v = 0;
        if (!next_field(line, pos, 0xffff, v))
            return bad("sample " + std::to_string(i) + " of " + std::to_string(r.sample_count) +
                       ": a reading 0-65535 followed by a comma");
        if (i < 100) {
            sum += v;
            if (i == 99) r.baseline = uint32_t(sum / 100);
        } else if (i > 100 && r.trigger_index == 0 && v > 2ull * r.baseline) {
            r.trigger_index = i;
            r.level_after = uint32_t(v);
        }
    }
    if (pos != line.size()) return bad("more than " + std::to_string(r.sample_count) + " readings");
    r.latency_ms = r.trigger_index == 0
                       ? std::numeric_limits<double>::quiet_NaN()
                       : (double(r.click_delay_us) +
                          double(r.trigger_index) * double(r.window_us) / double(r.sample_count)) /
                             1000.0;
    return r;
}

std::optional<std::string> parse_osltt_firmware(std::string_view line) {
    if (line.substr(0, 3) != "FW:") return std::nullopt;
    std::string_view v = line.substr(3);
    while (!v.empty() && v.front() == ' ') v.remove_prefix(1);
    while (!v.empty() && v.back() == ' ') v.remove_suffix(1);
    if (v.empty() || v.size() > 32) return std::nullopt;
    for (char c : v)
        if (!((c >= '0' && c <= '9') || c == '.')) return std::nullopt;
    return std::string(v);
}

} // namespace fgsr::probe
