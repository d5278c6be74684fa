// fgsr's vendor-bulk probe protocol: encoding commands and decoding (copy, then validate) replies.
#include <fgsr/probe/vendor_protocol.hpp>

#include <array>
#include <cstdio>
#include <cstring>

namespace fgsr::probe {

namespace {

void put16(std::vector<uint8_t>& b, uint16_t v) {
    b.push_back(uint8_t(v));
    b.push_back(uint8_t(v >> 8));
}
void put32(std::vector<uint8_t>& b, uint32_t v) {
    put16(b, uint16_t(v));
    put16(b, uint16_t(v >> 16));
}

uint16_t get16(const uint8_t* p) {
    return uint16_t(p[0] | p[1] << 8);
}
uint32_t get32(const uint8_t* p) {
    return uint32_t(get16(p)) | uint32_t(get16(p + 2)) << 16;
}
uint64_t get64(const uint8_t* p) {
    return uint64_t(get32(p)) | uint64_t(get32(p + 4)) << 32;
}

std::vector<uint8_t> header(VendorType type, uint16_t tag, uint16_t length) {
    std::vector<uint8_t> b;
    b.reserve(kVendorHeaderBytes + length);
    put16(b, kVendorMagic);
    b.push_back(kVendorVersion);
    b.push_back(uint8_t(type));
    put16(b, length);
    put16(b, tag);
    return b;
}

size_t payload_bytes(VendorType t) {
    switch (t) {
    case VendorType::ack:
        return 4;
    case VendorType::info:
        return 28;
    case VendorType::sync_reply:
        return 8;
    case VendorType::sample:
        return 28;
    case VendorType::done:
        return 4;
    case VendorType::error:
        return 4;
    default:
        return SIZE_MAX;
    }
}

std::string hex(unsigned v, int digits) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%0*x", digits, v);
    return b;
}

} // namespace

std::string vendor_error_text(uint16_t code, uint16_t detail) {
    const std::string d = " (detail " + std::to_string(detail) + ")";
    switch (VendorErrorCode(code)) {
    case VendorErrorCode::bad_header:
        return "the probe did not understand a header (magic or version)" + d;
    case VendorErrorCode::bad_command:
        return "the probe does not know the command" + d;
    case VendorErrorCode::bad_length:
        return "the probe rejected a command's length" + d;
    case VendorErrorCode::bad_argument: {
        static constexpr const char* kArgs[] = {"count", "interval_ms", "threshold"};
        return std::string("the probe rejected START's ") + (detail < 3 ? kArgs[detail] : "argument") + d;
    }
    case VendorErrorCode::busy:
        return "the probe is busy with another run" + d;
    case VendorErrorCode::sensor:
        return "the probe's light sensor reads nothing usable (dark, saturated or disconnected)" + d;
    case VendorErrorCode::input:
        return "the probe cannot inject the click (its HID interface is not in use by the host)" + d;
    }
    return "the probe reported error " + std::to_string(code) + d;
}

std::string vendor_firmware_text(uint32_t f) {
    return std::to_string(f >> 16) + "." + std::to_string((f >> 8) & 0xff) + "." + std::to_string(f & 0xff);
}

std::vector<uint8_t> encode_command(VendorType type, uint16_t tag) {
    return header(type, tag, 0);
}

std::vector<uint8_t> encode_start(uint16_t tag, uint32_t count, uint32_t interval_ms, uint16_t threshold) {
    std::vector<uint8_t> b = header(VendorType::start, tag, 12);
    put32(b, count);
    put32(b, interval_ms);
    put16(b, threshold);
    put16(b, 0);
    return b;
}

Result<VendorReply> decode_reply(std::span<const uint8_t> bytes) {
    // Copy first: nothing below reads the caller's buffer again.
    std::array<uint8_t, kVendorMaxMessage> m{};
    if (bytes.size() < kVendorHeaderBytes)
        return make_error(Errc::io, "reply of " + std::to_string(bytes.size()) + " bytes: shorter than the " +
                                        std::to_string(kVendorHeaderBytes) + "-byte header");
    if (bytes.size() > m.size())
        return make_error(Errc::io, "reply of " + std::to_string(bytes.size()) +
                                        " bytes: messages are at most " + std::to_string(m.size()));
    std::memcpy(m.data(), bytes.data(), bytes.size());
    const size_t size = bytes.size();

    const uint16_t magic = get16(&m[0]);
    if (magic != kVendorMagic)
        return make_error(Errc::io, "reply with magic " + hex(magic, 4) + " (expected " +
                                        hex(kVendorMagic, 4) + "): not fgsr's probe protocol");
    if (m[2] != kVendorVersion)
        return make_error(Errc::io, "reply of protocol version " + std::to_string(m[2]) +
                                        " (this fgsr speaks " + std::to_string(kVendorVersion) + ")");
    VendorReply r;
    r.type = VendorType(m[3]);
    const size_t want = payload_bytes(r.type);
    if (want == SIZE_MAX) return make_error(Errc::io, "reply of unknown type " + hex(m[3], 2));
    const uint16_t length = get16(&m[4]);
    r.tag = get16(&m[6]);
    if (length != want || size != kVendorHeaderBytes + want)
        return make_error(Errc::io, "reply of type " + hex(m[3], 2) + " with length " +
                                        std::to_string(length) + " in " + std::to_string(size) +
                                        " bytes (its payload is " + std::to_string(want) + " bytes)");
    const uint8_t* p = &m[kVendorHeaderBytes];
    switch (r.type) {
    case VendorType::ack:
        r.acked = p[0];
        if (p[1] || p[2] || p[3]) return make_error(Errc::io, "ACK with non-zero padding");
        if (r.acked != uint8_t(VendorType::start) && r.acked != uint8_t(VendorType::abort))
            return make_error(Errc::io,
                              "ACK of command " + hex(r.acked, 2) + " (only START and ABORT are acked)");
        break;
    case VendorType::info: {
        r.info.firmware = get32(p);
        r.info.clock_hz = get32(p + 4);
        r.info.max_count = get32(p + 8);
        if (r.info.clock_hz < 1000 || r.info.clock_hz > 1000000000)
            return make_error(Errc::io,
                              "INFO with clock_hz " + std::to_string(r.info.clock_hz) + " (1 kHz to 1 GHz)");
        if (r.info.max_count == 0)
            return make_error(Errc::io, "INFO with max_count 0 (the probe could measure nothing)");
        const char* name = reinterpret_cast<const char*>(p + 12);
        const size_t n = strnlen(name, 16);
        for (size_t i = 0; i < 16; ++i) {
            const uint8_t c = p[12 + i];
            if (i < n ? (c < 0x20 || c >= 0x7f) : c != 0)
                return make_error(Errc::io, "INFO name: byte " + std::to_string(i) + " is " + hex(c, 2) +
                                                " (printable ASCII, then NUL padding)");
        }
        r.info.name.assign(name, n);
        break;
    }
    case VendorType::sync_reply:
        r.device_ts = get64(p);
        break;
    case VendorType::sample:
        r.sample.index = get32(p);
        r.sample.flags = get32(p + 4);
        r.sample.click_ts = get64(p + 8);
        r.sample.photon_ts = get64(p + 16);
        r.sample.before = get16(p + 24);
        r.sample.after = get16(p + 26);
        if (r.sample.flags & ~kVendorFlagsDefined)
            return make_error(Errc::io, "SAMPLE " + std::to_string(r.sample.index) +
                                            " with undefined flag bits " +
                                            hex(r.sample.flags & ~kVendorFlagsDefined, 8));
        if (r.sample.photon_ts < r.sample.click_ts)
            return make_error(Errc::io, "SAMPLE " + std::to_string(r.sample.index) + ": photon_ts " +
                                            std::to_string(r.sample.photon_ts) + " before click_ts " +
                                            std::to_string(r.sample.click_ts));
        break;
    case VendorType::done:
        r.done_count = get32(p);
        break;
    case VendorType::error:
        r.error_code = get16(p);
        r.error_detail = get16(p + 2);
        break;
    default:
        break;
    }
    return r;
}

} // namespace fgsr::probe
