// fgsr's vendor-bulk probe protocol (docs/PROBE.md is the specification; this is its host-side
// encoding and decoding, without USB). One message per bulk transfer, each under 64 bytes (a short
// packet ends it), little-endian, an 8-byte header then the payload:
//
//   header   u16 magic 0x5046 ("FP"), u8 version 1, u8 type, u16 length (payload bytes), u16 tag
//   host -> probe                                     probe -> host
//   0x01 GET_INFO  -                                  0x81 INFO   u32 firmware (major<<16|minor<<8|patch),
//                                                                 u32 clock_hz, u32 max_count, char name[16]
//   0x02 SYNC      -                                  0x82 SYNC   u64 device_ts (ticks when handled)
//   0x03 START     u32 count, u32 interval_ms,        0x80 ACK    u8 command, u8[3] zero
//                  u16 threshold, u16 zero            0x83 SAMPLE u32 index, u32 flags, u64 click_ts,
//   0x04 ABORT     -                                              u64 photon_ts, u16 before, u16 after
//                                                     0x84 DONE   u32 samples sent
//                                                     0xee ERROR  u16 code, u16 detail
//
// A reply carries the tag of the command it answers (SAMPLE and DONE: START's). decode_reply()
// copies the bytes it is given and checks everything: magic, version, a known reply type, the
// exact payload length of that type, zero padding, ranges (clock_hz 1 kHz .. 1 GHz, photon_ts >=
// click_ts, flags within the defined bits, name printable ASCII).
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fgsr::probe {

inline constexpr uint16_t kVendorMagic = 0x5046;
inline constexpr uint8_t kVendorVersion = 1;
inline constexpr size_t kVendorHeaderBytes = 8;
inline constexpr size_t kVendorMaxMessage = 63; // one short packet at full speed
inline constexpr uint16_t kFgsrProbeVid = 0x1209, kFgsrProbePid = 0x0001;
inline constexpr uint32_t kVendorMaxCount = 10000;

enum class VendorType : uint8_t {
    get_info = 0x01,
    sync = 0x02,
    start = 0x03,
    abort = 0x04,
    ack = 0x80,
    info = 0x81,
    sync_reply = 0x82,
    sample = 0x83,
    done = 0x84,
    error = 0xee,
};

// SAMPLE flags
inline constexpr uint32_t kVendorFlagNoChange = 0x1;  // no change within the probe's window: a miss
inline constexpr uint32_t kVendorFlagSaturated = 0x2; // the sensor saturated during the measurement
inline constexpr uint32_t kVendorFlagsDefined = 0x3;

// ERROR codes
enum class VendorErrorCode : uint16_t {
    bad_header = 1,   // magic or version
    bad_command = 2,  // unknown type
    bad_length = 3,   // payload length wrong for the type
    bad_argument = 4, // detail: the argument's index (START: 0 count, 1 interval, 2 threshold)
    busy = 5,         // START while running
    sensor = 6,       // the light sensor reads nothing usable (dark, saturated, unplugged)
    input = 7,        // the click could not be injected (HID not enumerated by the host)
};
std::string vendor_error_text(uint16_t code, uint16_t detail);

struct VendorInfo {
    uint32_t firmware = 0, clock_hz = 0, max_count = 0;
    std::string name;
};
struct VendorSample {
    uint32_t index = 0, flags = 0;
    uint64_t click_ts = 0, photon_ts = 0;
    uint16_t before = 0, after = 0;
};

struct VendorReply {
    VendorType type = VendorType::ack;
    uint16_t tag = 0;
    uint8_t acked = 0;                         // ack
    VendorInfo info;                           // info
    uint64_t device_ts = 0;                    // sync_reply
    VendorSample sample;                       // sample
    uint32_t done_count = 0;                   // done
    uint16_t error_code = 0, error_detail = 0; // error
};

std::vector<uint8_t> encode_command(VendorType type, uint16_t tag);
std::vector<uint8_t> encode_start(uint16_t tag, uint32_t count, uint32_t interval_ms, uint16_t threshold);
Result<VendorReply> decode_reply(std::span<const uint8_t> bytes);

// "1.2.3"
std::string vendor_firmware_text(uint32_t firmware);

} // namespace fgsr::probe
