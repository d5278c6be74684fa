// The emulated probes' device side: OSLTT (CDC-ACM, text protocol) and fgsr's vendor-bulk probe.
#include "gadgets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace fgsr::probe::test {

namespace {

void le16(std::vector<uint8_t>& b, uint16_t v) {
    b.push_back(uint8_t(v));
    b.push_back(uint8_t(v >> 8));
}
void le32(std::vector<uint8_t>& b, uint32_t v) {
    le16(b, uint16_t(v));
    le16(b, uint16_t(v >> 16));
}
void le64(std::vector<uint8_t>& b, uint64_t v) {
    le32(b, uint32_t(v));
    le32(b, uint32_t(v >> 32));
}

std::vector<uint8_t> bytes(std::initializer_list<int> v) {
    std::vector<uint8_t> b;
    for (int x : v) b.push_back(uint8_t(x));
    return b;
}

bool contains(const std::vector<size_t>& v, size_t x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}

// The emulated vendor device's message: magic "FP", version 1, type, length, tag, payload.
std::vector<uint8_t> message(uint8_t type, uint16_t tag, const std::vector<uint8_t>& payload) {
    std::vector<uint8_t> m = bytes({'F', 'P', 1, type});
    le16(m, uint16_t(payload.size()));
    le16(m, tag);
    m.insert(m.end(), payload.begin(), payload.end());
    return m;
}

} // namespace

UsbIdentity osltt_identity(uint16_t vid, uint16_t pid) {
    UsbIdentity id{vid, pid, {}, "Seeeduino XIAO"};
    id.descriptors = bytes({0x12, 0x01, 0x00, 0x02, 0xef, 0x02, 0x01, 0x40, vid & 0xff, vid >> 8, pid & 0xff,
                            pid >> 8, 0x00, 0x01, 0x01, 0x02, 0x03, 0x01});
    const auto cfg = bytes({
        0x09, 0x02, 0x64, 0x00, 0x03, 0x01, 0x00, 0xa0, 0xfa, // configuration: 3 interfaces, 100 bytes
        0x08, 0x0b, 0x00, 0x02, 0x02, 0x02, 0x00, 0x00,       // IAD: interfaces 0-1, CDC
        0x09, 0x04, 0x00, 0x00, 0x01, 0x02, 0x02, 0x00, 0x00, // interface 0: CDC communication, ACM
        0x05, 0x24, 0x00, 0x10, 0x01,                         // CDC header
        0x05, 0x24, 0x01, 0x01, 0x01,                         // call management
        0x04, 0x24, 0x02, 0x06,                               // ACM
        0x05, 0x24, 0x06, 0x00, 0x01,                         // union: 0 controls 1
        0x07, 0x05, 0x81, 0x03, 0x10, 0x00, 0x10,             // interrupt IN 0x81
        0x09, 0x04, 0x01, 0x00, 0x02, 0x0a, 0x00, 0x00, 0x00, // interface 1: CDC data
        0x07, 0x05, 0x02, 0x02, 0x40, 0x00, 0x00,             // bulk OUT 0x02
        0x07, 0x05, 0x83, 0x02, 0x40, 0x00, 0x00,             // bulk IN 0x83
        0x09, 0x04, 0x02, 0x00, 0x01, 0x03, 0x00, 0x00, 0x00, // interface 2: HID (the click)
        0x09, 0x21, 0x11, 0x01, 0x00, 0x01, 0x22, 0x65, 0x00, // HID descriptor
        0x07, 0x05, 0x84, 0x03, 0x40, 0x00, 0x01,             // interrupt IN 0x84
    });
    id.descriptors.insert(id.descriptors.end(), cfg.begin(), cfg.end());
    return id;
}

UsbIdentity fgsr_identity(uint16_t vid, uint16_t pid) {
    UsbIdentity id{vid, pid, {}, "fgsr-probe"};
    id.descriptors = bytes({0x12, 0x01, 0x00, 0x02, 0x00, 0x00, 0x00, 0x40, vid & 0xff, vid >> 8, pid & 0xff,
                            pid >> 8, 0x00, 0x01, 0x01, 0x02, 0x03, 0x01});
    const auto cfg = bytes({
        0x09, 0x02, 0x20, 0x00, 0x01, 0x01, 0x00, 0x80, 0x32, // configuration: 1 interface, 32 bytes
        0x09, 0x04, 0x00, 0x00, 0x02, 0xff, 0x46, 0x01, 0x00, // interface 0: ff/46/01
        0x07, 0x05, 0x01, 0x02, 0x40, 0x00, 0x00,             // bulk OUT 0x01
        0x07, 0x05, 0x81, 0x02, 0x40, 0x00, 0x00,             // bulk IN 0x81
    });
    id.descriptors.insert(id.descriptors.end(), cfg.begin(), cfg.end());
    return id;
}

UsbIdentity mouse_identity() {
    UsbIdentity id{0x046d, 0xc077, {}, "USB Optical Mouse"};
    id.descriptors = bytes({0x12, 0x01, 0x00, 0x02, 0x00, 0x00, 0x00, 0x08, 0x6d, 0x04, 0x77, 0xc0, 0x00,
                            0x01, 0x01, 0x02, 0x00, 0x01, 0x09, 0x02, 0x22, 0x00, 0x01, 0x01, 0x00, 0xa0,
                            0x32, 0x09, 0x04, 0x00, 0x00, 0x01, 0x03, 0x01, 0x02, 0x00, 0x09, 0x21, 0x11,
                            0x01, 0x00, 0x01, 0x22, 0x34, 0x00, 0x07, 0x05, 0x81, 0x03, 0x04, 0x00, 0x0a});
    return id;
}

DriverBinding osltt_drivers() {
    DriverBinding b;
    b.drivers = {{0, "cdc_acm"}, {1, "cdc_acm"}, {2, "usbhid"}};
    b.groups = {{0, 1}};
    return b;
}

std::string osltt_res_line(uint32_t click_delay_us, uint32_t n, uint32_t latency_us, bool change) {
    const uint32_t trigger = (latency_us - click_delay_us) / 5;
    std::string s =
        "RES:" + std::to_string(click_delay_us) + "," + std::to_string(5 * n) + "," + std::to_string(n) + ",";
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t v = i < 100 ? (i % 2 ? 1010 : 990) : 1500;
        if (change && i >= trigger) v = 3000;
        s += std::to_string(v) + ",";
    }
    return s;
}

// --- OSLTT ---

void OslttGadget::emit(std::string text, uint64_t at_ns) {
    out_.push_back(Chunk{at_ns, std::move(text), false});
}

bool OslttGadget::control(const Setup& setup, std::span<const uint8_t> data, uint64_t now_ns) {
    if (setup.request_type != 0x21) return false;
    if (setup.request == 0x20 && data.size() == 7) {
        baud = uint32_t(data[0] | data[1] << 8 | data[2] << 16 | uint32_t(data[3]) << 24);
        return true;
    }
    if (setup.request == 0x22) {
        const bool was = dtr;
        dtr = setup.value & 1;
        if (dtr && !was) next_greeting_ns_ = now_ns;
        return true;
    }
    return false;
}

bool OslttGadget::bulk_out(uint8_t, std::span<const uint8_t> data, uint64_t now_ns) {
    received.append(reinterpret_cast<const char*>(data.data()), data.size());
    input_.append(reinterpret_cast<const char*>(data.data()), data.size());
    greeted_ = true; // any input ends the greeting
    // The firmware reads two bytes at a time and looks at the first.
    while (input_.size() >= 2) {
        handle_token(input_[0], now_ns);
        input_.erase(0, 2);
    }
    return true;
}

void OslttGadget::handle_token(char c, uint64_t now) {
    if (s_.never_answer) return;
    if (c == 'I') {
        if (s_.chatter) emit("Clicks\r\n", now); // chatter from another firmware version first
        emit("FW:" + s_.firmware + "\r\n", now);
    } else if (c == 'T' && !test_mode_) {
        test_mode_ = true;
        const uint64_t ms = 1000000;
        uint64_t t = now + s_.press_after_ms * ms;
        const size_t n = s_.latencies_us.size();
        for (size_t k = 0; k < n; ++k) {
            t += s_.interval_ms * ms;
            const bool miss = contains(s_.misses, k);
            out_.push_back(Chunk{
                t, osltt_res_line(s_.click_delay_us, s_.samples, s_.latencies_us[k], !miss) + "\r\n", true});
            if (s_.chatter) emit("RESULT:" + std::to_string(s_.latencies_us[k] / 1000) + ".00\r\n", t);
            const bool series_end = s_.series && (k + 1) % s_.series == 0 && k + 1 < n;
            if (series_end) {
                emit("AUTO FINISHED\r\n", t);
                t += s_.press_after_ms * ms; // the button, pressed again
            }
        }
        emit("AUTO FINISHED\r\n", t);
        scheduled_ = n;
    } else if (c == 'X') {
        if (test_mode_) {
            // The series stops between shots.
            out_.erase(
                std::remove_if(out_.begin(), out_.end(), [&](const Chunk& ch) { return ch.at_ns > now; }),
                out_.end());
        }
        test_mode_ = false;
    }
}

InResult OslttGadget::bulk_in(uint8_t, size_t max_bytes, uint64_t now) {
    InResult r;
    if (s_.never_answer || silent_) return r;
    if (dtr && !greeted_ && s_.chatter && now >= next_greeting_ns_) {
        emit("1397511252\r\n", now); // the firmware's greeting: Serial.println('OSLTT')
        next_greeting_ns_ = now + 250000000;
    }
    std::string data;
    while (!out_.empty() && out_.front().at_ns <= now && data.size() < max_bytes) {
        Chunk& ch = out_.front();
        if (ch.is_result) {
            const size_t k = results_sent;
            const auto at = [&](const std::optional<size_t>& o) { return o && *o == k; };
            if (at(s_.silent_after)) {
                silent_ = true;
                break;
            }
            if (at(s_.stall_after)) {
                if (!data.empty()) break;
                r.kind = InResult::stall;
                return r;
            }
            if (at(s_.unplug_after)) {
                if (!data.empty()) break;
                r.kind = InResult::unplug;
                return r;
            }
            if (at(s_.garbage_after)) ch.bytes = std::string("\x01\xfe\xff\x80garbage\x00\r\n", 14);
            if (at(s_.malformed_after)) ch.bytes = "RES:120,abc,2000,1,2,3,\r\n";
        }
        const size_t take = std::min(ch.bytes.size(), max_bytes - data.size());
        data += ch.bytes.substr(0, take);
        if (take == ch.bytes.size()) {
            if (ch.is_result) ++results_sent;
            out_.pop_front();
        } else {
            ch.bytes.erase(0, take);
            if (ch.is_result) ++results_sent;
            ch.is_result = false; // its fault checks are done; the rest is plain bytes
        }
    }
    if (data.empty()) return r;
    r.kind = InResult::data;
    r.bytes.assign(data.begin(), data.end());
    return r;
}

// --- fgsr vendor protocol ---

VendorGadget::VendorGadget(VendorScenario s) : s_(std::move(s)), epoch_ns_(0) {}

uint64_t VendorGadget::device_ticks(uint64_t host_ns) const {
    const long double rate = (long double)s_.clock_hz * (1.0L + (long double)s_.drift_ppm * 1e-6L);
    return s_.boot_offset_ticks + uint64_t(std::llroundl((long double)(host_ns - epoch_ns_) * rate / 1e9L));
}

void VendorGadget::reply(std::vector<uint8_t> m, uint64_t at_ns, bool is_sample) {
    out_.push_back(Message{at_ns, std::move(m), is_sample});
}

bool VendorGadget::control(const Setup&, std::span<const uint8_t>, uint64_t) {
    return false; // the vendor probe has no control requests
}

bool VendorGadget::bulk_out(uint8_t, std::span<const uint8_t> d, uint64_t now) {
    if (s_.never_answer) return true;
    if (d.size() < 8 || d[0] != 'F' || d[1] != 'P' || d[2] != 1) {
        std::vector<uint8_t> p;
        le16(p, 1);
        le16(p, 0);
        reply(message(0xee, 0, p), now);
        return true;
    }
    const uint8_t type = d[3];
    const uint16_t length = uint16_t(d[4] | d[5] << 8), tag = uint16_t(d[6] | d[7] << 8);
    const auto ack = [&](uint8_t command) { reply(message(0x80, tag, bytes({command, 0, 0, 0})), now); };
    if (d.size() != 8u + length) {
        std::vector<uint8_t> p;
        le16(p, 3);
        le16(p, 0);
        reply(message(0xee, tag, p), now);
        return true;
    }
    switch (type) {
    case 0x01: { // GET_INFO
        if (s_.garbage_info) {
            const char junk[] = "Hello from a different gadget!!";
            reply(std::vector<uint8_t>(junk, junk + sizeof junk - 1), now);
            break;
        }
        std::vector<uint8_t> p;
        le32(p, 0x000102);
        le32(p, s_.clock_hz);
        le32(p, s_.max_count);
        char name[16] = "fgsr-emulated";
        p.insert(p.end(), name, name + 16);
        reply(message(0x81, tag, p), now);
        break;
    }
    case 0x02: { // SYNC
        ++syncs;
        std::vector<uint8_t> p;
        le64(p, device_ticks(now));
        reply(message(0x82, tag, p), now);
        break;
    }
    case 0x03: { // START
        ++starts;
        const uint32_t count = uint32_t(d[8] | d[9] << 8 | d[10] << 16 | uint32_t(d[11]) << 24);
        const uint32_t interval = uint32_t(d[12] | d[13] << 8 | d[14] << 16 | uint32_t(d[15]) << 24);
        if (s_.start_error) {
            std::vector<uint8_t> p;
            le16(p, *s_.start_error);
            le16(p, 0);
            reply(message(0xee, tag, p), now);
            break;
        }
        ack(0x03);
        const double scale = starts <= s_.run_scale.size() ? s_.run_scale[starts - 1] : 1.0;
        const long double rate = (long double)s_.clock_hz * (1.0L + (long double)s_.drift_ppm * 1e-6L);
        click_host_ns.emplace_back();
        latencies_sent.emplace_back();
        uint64_t last = now;
        for (uint32_t k = 0; k < count; ++k) {
            const uint64_t click_host = now + uint64_t(k + 1) * interval * 1000000ull;
            const uint64_t click = device_ticks(click_host);
            const uint32_t lat =
                uint32_t(std::lround(s_.latencies_ticks[k % s_.latencies_ticks.size()] * scale));
            const uint64_t photon_host = click_host + uint64_t(std::llroundl((long double)lat * 1e9L / rate));
            const bool miss = contains(s_.misses, k);
            std::vector<uint8_t> p;
            le32(p, k);
            le32(p, miss ? 1u : 0u);
            le64(p, click);
            le64(p, miss ? click + s_.clock_hz / 10 : click + lat);
            le16(p, 200);
            le16(p, miss ? 210 : 3900);
            reply(message(0x83, tag, p), photon_host, true);
            if (!miss) {
                click_host_ns.back().push_back(click_host);
                latencies_sent.back().push_back(lat);
            }
            last = photon_host;
        }
        std::vector<uint8_t> p;
        le32(p, count);
        reply(message(0x84, tag, p), last);
        break;
    }
    case 0x04: // ABORT
        ++aborts;
        out_.clear();
        ack(0x04);
        break;
    default: {
        std::vector<uint8_t> p;
        le16(p, 2);
        le16(p, type);
        reply(message(0xee, tag, p), now);
    }
    }
    return true;
}

InResult VendorGadget::bulk_in(uint8_t, size_t max_bytes, uint64_t now) {
    InResult r;
    if (out_.empty() || out_.front().at_ns > now) return r;
    Message m = out_.front();
    if (m.is_sample) {
        const size_t k = samples_sent_;
        const auto at = [&](const std::optional<size_t>& o) { return o && *o == k; };
        if (at(s_.silent_after)) return r;
        if (at(s_.stall_after)) {
            r.kind = InResult::stall;
            return r;
        }
        if (at(s_.unplug_after)) {
            r.kind = InResult::unplug;
            return r;
        }
        if (at(s_.garbage_after)) m.bytes[0] = 0x47, m.bytes[1] = 0x42;   // "GB": not the magic
        if (at(s_.bad_photon_after)) std::memset(&m.bytes[8 + 16], 0, 8); // photon_ts 0 < click_ts
        if (at(s_.skip_index_after)) m.bytes[8] = uint8_t(m.bytes[8] + 1);
        ++samples_sent_;
    }
    out_.pop_front();
    r.kind = InResult::data;
    r.bytes.assign(m.bytes.begin(), m.bytes.begin() + std::min(m.bytes.size(), max_bytes));
    return r;
}

} // namespace fgsr::probe::test
