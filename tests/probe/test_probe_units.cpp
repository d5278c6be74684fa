// fgsr_probe's pure parts, without USB: OSLTT's line reader and parsers, the vendor protocol's
// encoding and validation, the clock mapping on synthetic exchanges, summaries, modes, selectors,
// the messages for permission and transfer failures, and the CSV read back as PresentMon's columns.
#include "gadgets.hpp"

#include <fgsr/core/presentmon.hpp>
#include <fgsr/probe/clock_map.hpp>
#include <fgsr/probe/device.hpp>
#include <fgsr/probe/modes.hpp>
#include <fgsr/probe/osltt.hpp>
#include <fgsr/probe/report.hpp>
#include <fgsr/probe/usb.hpp>
#include <fgsr/probe/vendor_protocol.hpp>

#include <libusb-1.0/libusb.h>

#include <gtest/gtest.h>

#include <cmath>

namespace fgsr::probe {
namespace {

std::span<const uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const uint8_t*>(s.data()), s.size()};
}

TEST(ProbeOsltt, LineReaderSplitsLinesAndRefusesBinary) {
    LineReader r;
    ASSERT_TRUE(r.feed(as_bytes("FW:0.1")).ok());
    EXPECT_FALSE(r.next_line());
    ASSERT_TRUE(r.feed(as_bytes("0\r\nhello\n\r\n")).ok());
    EXPECT_EQ(*r.next_line(), "FW:0.10");
    EXPECT_EQ(*r.next_line(), "hello");
    EXPECT_EQ(*r.next_line(), "");
    EXPECT_FALSE(r.next_line());
    auto bad = r.feed(as_bytes(std::string("ok\x1b", 3)));
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().message,
              "binary data from the probe (byte 0x1b at offset 19 of its output): not OSLTT's "
              "text protocol");
    LineReader big;
    const std::string chunk(1 << 16, '7');
    Result<void> last;
    for (int i = 0; i < 17 && last.ok(); ++i) last = big.feed(as_bytes(chunk));
    ASSERT_FALSE(last.ok());
    EXPECT_NE(last.error().message.find("longer than 1048576 bytes"), std::string::npos);
}

TEST(ProbeOsltt, ResultLineGivesTheLatencyOfTheFirmwaresRule) {
    // Emulator's line: click delay 120 us, 2000 samples in 10000 us, change at sample 400.
    auto r = parse_osltt_result(test::osltt_res_line(120, 2000, 2120));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->trigger_index, 400u);
    EXPECT_EQ(r->baseline, 1000u);
    EXPECT_EQ(r->level_after, 3000u);
    EXPECT_DOUBLE_EQ(r->latency_ms, 2.12);
    // A hand-written one: 101 samples at 10 us each, baseline 100, sample 101 is not above 200...
    std::string line = "RES:50,1010,102,";
    for (int i = 0; i < 100; ++i) line += "100,";
    line += "150,200,";
    auto none = parse_osltt_result(line);
    ASSERT_TRUE(none.ok()) << none.error().message;
    EXPECT_EQ(none->trigger_index, 0u);
    EXPECT_TRUE(std::isnan(none->latency_ms));
    // ... and 201 is: 50 us + 101 * 1010 / 102 us.
    line.replace(line.size() - 4, 3, "201");
    auto hit = parse_osltt_result(line);
    ASSERT_TRUE(hit.ok());
    EXPECT_EQ(hit->trigger_index, 101u);
    EXPECT_DOUBLE_EQ(hit->latency_ms, (50 + 101 * 1010.0 / 102) / 1000);
}

TEST(ProbeOsltt, ResultLineIsParsedStrictly) {
    const std::string good = test::osltt_res_line(120, 200, 1020);
    EXPECT_TRUE(parse_osltt_result(good).ok());
    const auto msg = [](const std::string& l) {
        auto r = parse_osltt_result(l);
        return r.ok() ? std::string("ok") : r.error().message;
    };
    EXPECT_NE(msg(good.substr(0, good.size() - 1)).find("sample 199 of 200"),
              std::string::npos); // no final comma
    EXPECT_NE(msg(good + "5,").find("more than 200 readings"), std::string::npos);
    EXPECT_NE(msg("RES:120,1000,100,").find("sample count: 101 to 200000"), std::string::npos);
    EXPECT_NE(msg("RES:-5,1000,200,").find("click delay"), std::string::npos);
    EXPECT_NE(msg("RES:5,0,200,").find("window"), std::string::npos);
    EXPECT_NE(msg("RES:5,1000,200,70000,").find("sample 0 of 200: a reading 0-65535"), std::string::npos);
    EXPECT_NE(msg("RESULT:12.3").find("not a RES: line"), std::string::npos);
    EXPECT_EQ(*parse_osltt_firmware("FW:0.10"), "0.10");
    EXPECT_EQ(*parse_osltt_firmware("FW: 1.5 "), "1.5");
    EXPECT_FALSE(parse_osltt_firmware("FW:"));
    EXPECT_FALSE(parse_osltt_firmware("FW:abc"));
    EXPECT_FALSE(parse_osltt_firmware("Settings Synced"));
}

std::vector<uint8_t> reply(uint8_t type, uint16_t tag, std::vector<uint8_t> payload) {
    std::vector<uint8_t> m(8 + payload.size());
    const uint8_t header[8] = {
        0x46, 0x50, 1, type, uint8_t(payload.size()), 0, uint8_t(tag), uint8_t(tag >> 8)};
    std::copy(header, header + 8, m.begin());
    std::copy(payload.begin(), payload.end(), m.begin() + 8);
    return m;
}

TEST(ProbeVendor, CommandsAreLittleEndianWithTheHeader) {
    EXPECT_EQ(encode_command(VendorType::sync, 0x1234),
              (std::vector<uint8_t>{0x46, 0x50, 1, 0x02, 0, 0, 0x34, 0x12}));
    EXPECT_EQ(
        encode_start(7, 100, 250, 0x0203),
        (std::vector<uint8_t>{0x46, 0x50, 1, 0x03, 12, 0, 7, 0, 100, 0, 0, 0, 250, 0, 0, 0, 3, 2, 0, 0}));
}

TEST(ProbeVendor, RepliesAreValidated) {
    std::vector<uint8_t> info = {0x02, 0x01, 0x00, 0x00, 0x40, 0x42, 0x0f, 0x00, 0xe8, 0x03, 0x00, 0x00};
    const char name[16] = "rp2040-probe";
    for (char c : name) info.push_back(uint8_t(c));
    auto r = decode_reply(reply(0x81, 3, info));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->tag, 3);
    EXPECT_EQ(r->info.clock_hz, 1000000u);
    EXPECT_EQ(r->info.max_count, 1000u);
    EXPECT_EQ(r->info.name, "rp2040-probe");
    EXPECT_EQ(vendor_firmware_text(r->info.firmware), "0.1.2");

    const auto msg = [](const std::vector<uint8_t>& m) {
        auto x = decode_reply(m);
        return x.ok() ? std::string("ok") : x.error().message;
    };
    auto bad_name = info;
    bad_name[12 + 3] = 0x07;
    EXPECT_EQ(msg(reply(0x81, 3, bad_name)), "INFO name: byte 3 is 0x07 (printable ASCII, then NUL padding)");
    auto slow = info;
    slow[4] = 10, slow[5] = 0, slow[6] = 0, slow[7] = 0;
    EXPECT_EQ(msg(reply(0x81, 3, slow)), "INFO with clock_hz 10 (1 kHz to 1 GHz)");
    EXPECT_EQ(msg(reply(0x82, 1, {1, 2, 3})),
              "reply of type 0x82 with length 3 in 11 bytes (its payload is 8 bytes)");
    EXPECT_EQ(msg(reply(0x99, 1, {})), "reply of unknown type 0x99");
    EXPECT_EQ(msg({0x46, 0x50}), "reply of 2 bytes: shorter than the 8-byte header");
    EXPECT_EQ(msg(std::vector<uint8_t>(64, 0x46)), "reply of 64 bytes: messages are at most 63");
    auto v2 = reply(0x84, 1, {1, 0, 0, 0});
    v2[2] = 2;
    EXPECT_EQ(msg(v2), "reply of protocol version 2 (this fgsr speaks 1)");
    std::vector<uint8_t> sample(28, 0);
    sample[4] = 0x10; // undefined flag
    EXPECT_EQ(msg(reply(0x83, 1, sample)), "SAMPLE 0 with undefined flag bits 0x00000010");
    EXPECT_EQ(msg(reply(0x80, 1, {0x02, 0, 0, 0})), "ACK of command 0x02 (only START and ABORT are acked)");
    EXPECT_EQ(msg(reply(0x80, 1, {0x03, 0, 1, 0})), "ACK with non-zero padding");
    auto e = decode_reply(reply(0xee, 9, {4, 0, 1, 0}));
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(vendor_error_text(e->error_code, e->error_detail),
              "the probe rejected START's interval_ms (detail 1)");
}

TEST(ProbeClock, FitRecoversOffsetAndDriftFromMidpoints) {
    // Device: 1 MHz nominal, 200 ppm fast, 5e9 ticks at host 1000 s. Round trips of 100-300 us,
    // the device reading its clock anywhere inside; the round trips of 5 ms are left out.
    const double hz = 1e6, rate = hz * (1 + 200e-6);
    const auto ticks_at = [&](double host_ns) { return uint64_t(5e9 + (host_ns - 1e12) * rate / 1e9); };
    std::vector<SyncPoint> pts;
    for (int i = 0; i < 16; ++i) {
        const double t = 1e12 + (i < 8 ? i * 1e6 : 4e9 + i * 1e6); // before and after a 4 s run
        const double rtt = (i % 3 == 0 ? 5e6 : 100e3 + 20e3 * (i % 4));
        const double read_at = t + rtt * (i % 2 ? 0.3 : 0.7);
        pts.push_back(SyncPoint{ticks_at(read_at), uint64_t(t), uint64_t(t + rtt)});
    }
    auto m = ClockMap::fit(pts, hz);
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_TRUE(m->rate_fitted());
    EXPECT_NEAR(m->drift_ppm(), 200, 20);
    const double probe_host = 1e12 + 2.5e9;
    EXPECT_NEAR(double(m->to_monotonic_ns(ticks_at(probe_host))), probe_host, m->error_ns());
    EXPECT_LT(m->error_ns(), 300e3);
    EXPECT_DOUBLE_EQ(m->ticks_to_ns(12500), 12.5e6);
    // Short span: the rate stays nominal.
    auto short_map = ClockMap::fit(std::span(pts).first(8), hz);
    ASSERT_TRUE(short_map.ok());
    EXPECT_FALSE(short_map->rate_fitted());
    EXPECT_DOUBLE_EQ(short_map->drift_ppm(), 0);
    // A clock that is not what it claims.
    for (auto& p : pts) p.device_ticks = p.device_ticks * 2;
    auto wrong = ClockMap::fit(pts, hz);
    ASSERT_FALSE(wrong.ok());
    EXPECT_NE(wrong.error().message.find("ppm off its stated 1000000 Hz (more than 1000 ppm"),
              std::string::npos)
        << wrong.error().message;
    EXPECT_FALSE(ClockMap::fit({}, hz).ok());
}

TEST(ProbeReport, SummaryModesAndCsv) {
    std::vector<Sample> s;
    for (double ms : {9.0, 3.0, 7.0, 1.0, 5.0})
        s.push_back(Sample{uint32_t(s.size()), ms, 1000000000, 1000000000});
    const LatencySummary sum = summarize(s);
    EXPECT_EQ(sum.count, 5u);
    EXPECT_EQ(sum.p50, 5.0);
    EXPECT_EQ(sum.p90, 9.0);
    EXPECT_EQ(sum.min, 1.0);
    EXPECT_EQ(sum.max, 9.0);
    EXPECT_EQ(sum.mean, 5.0);
    EXPECT_TRUE(std::isnan(summarize({}).p50));
    EXPECT_EQ(summary_line(sum),
              "click-to-photon latency over 5 samples: p50 5.000 ms, p90 9.000 ms, p99 9.000 ms, "
              "min 1.000 ms, max 9.000 ms, mean 5.000 ms");

    auto modes = parse_modes("off,extrapolate");
    ASSERT_TRUE(modes.ok());
    EXPECT_EQ(*modes, (std::vector<Mode>{Mode::off, Mode::extrapolate}));
    EXPECT_EQ(parse_modes("off,off").error().message, "--modes: 'off' given twice");
    EXPECT_EQ(parse_modes("fast").error().message,
              "--modes: 'fast' (expected off, interpolate, extrapolate)");
    EXPECT_FALSE(parse_modes(",").ok());
    EXPECT_EQ(mode_environment(Mode::interpolate), (std::vector<std::pair<std::string, std::string>>{
                                                       {"FGSR_ENABLE", "1"}, {"FGSR_MODE", "interpolate"}}));
    EXPECT_EQ(mode_environment(Mode::off),
              (std::vector<std::pair<std::string, std::string>>{{"FGSR_DISABLE", "1"}}));

    CsvRun run;
    run.mode = Mode::interpolate;
    run.pid = 4242;
    run.application = "fgsr_layer_app";
    s[2].photon_ns = 2500000000;
    s[2].brightness_before = 12;
    s[2].brightness_after = 3456;
    run.samples = s;
    const std::string text = csv_text(std::span(&run, 1));
    auto rows = parse_presentmon_csv(text);
    ASSERT_TRUE(rows.ok()) << rows.error().message;
    ASSERT_EQ(rows->size(), 5u);
    EXPECT_EQ((*rows)[2].application, "fgsr_layer_app");
    EXPECT_EQ((*rows)[2].process_id, 4242u);
    EXPECT_EQ((*rows)[2].swapchain, 2u);
    EXPECT_DOUBLE_EQ((*rows)[2].ms_click_to_photon, 7.0);
    EXPECT_DOUBLE_EQ((*rows)[2].time_s, 2.5);
    EXPECT_TRUE(std::isnan((*rows)[2].ms_between_presents));
    EXPECT_NE(text.find(",interpolate,2,1000000000,2500000000,12,3456,0\n"), std::string::npos) << text;
}

TEST(ProbeDevice, SelectorsAndProtocols) {
    auto a = parse_device_selector("1209:0001");
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(*a->vid, 0x1209);
    EXPECT_EQ(*a->pid, 0x0001);
    auto b = parse_device_selector("001/012");
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(*b->bus, 1);
    EXPECT_EQ(*b->address, 12);
    EXPECT_FALSE(parse_device_selector("").value().names_device());
    EXPECT_EQ(parse_device_selector("12345:1").error().message,
              "--device '12345:1': VID:PID wants two hex numbers up to ffff");
    EXPECT_FALSE(parse_device_selector("1/0").ok());
    EXPECT_FALSE(parse_device_selector("1/300").ok());
    EXPECT_FALSE(parse_device_selector("mouse").ok());
    EXPECT_EQ(*parse_protocol("osltt").value(), Protocol::osltt);
    EXPECT_FALSE(parse_protocol("auto").value().has_value());
    EXPECT_FALSE(parse_protocol("serial").ok());
    // The udev rule covers every supported id.
    for (const KnownProbe& k : known_probes()) EXPECT_TRUE(k.vid && k.pid && k.name);
}

TEST(ProbeUsb, FailureMessagesSayWhatHappened) {
    const std::string p = permission_message("bus 1 address 5 (1209:0001)");
    EXPECT_NE(p.find("cannot open the probe at bus 1 address 5 (1209:0001): permission denied"),
              std::string::npos);
    EXPECT_NE(p.find("tools/probe/70-fgsr-probe.rules /etc/udev/rules.d/"), std::string::npos) << p;
    EXPECT_NE(p.find("lib/udev/rules.d/70-fgsr-probe.rules"), std::string::npos) << p;
    EXPECT_NE(p.find("udevadm control --reload"), std::string::npos) << p;
    EXPECT_EQ(usb_failure(LIBUSB_ERROR_ACCESS), UsbFailure::access);
    EXPECT_EQ(usb_io_error(UsbIo{LIBUSB_ERROR_TIMEOUT, 0}, "GET_INFO", 250).message,
              "GET_INFO: no reply within 250 ms");
    EXPECT_EQ(usb_io_error(UsbIo{LIBUSB_ERROR_NO_DEVICE, 0}, "x", 1).code, Errc::no_device);
    EXPECT_EQ(usb_io_error(UsbIo{LIBUSB_ERROR_PIPE, 0}, "x", 1).message,
              "x: the endpoint stalled (the probe refused the transfer)");
    EXPECT_EQ(usb_io_error(UsbIo{LIBUSB_ERROR_OVERFLOW, 0}, "x", 1).message,
              "x: LIBUSB_ERROR_OVERFLOW (Overflow)");
}

} // namespace
} // namespace fgsr::probe
