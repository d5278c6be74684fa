// fgsr_probe against emulated probes (umockdev, usbdevfs level): enumeration and --list, claiming
// with cdc_acm detached and reattached, OSLTT's handshake and a measurement run, the vendor
// protocol's run with its clock mapping, waiting for a probe through hot-plug, the measurement
// mode over a command, and `fgsr probe`'s whole run (report text and CSV).
#include "probe_fixture.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/core/presentmon.hpp>
#include <fgsr/probe/modes.hpp>
#include <fgsr/probe/report.hpp>
#include <fgsr/probe/session.hpp>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace fgsr::probe::test {
namespace {

std::vector<uint32_t> osltt_latencies_us() {
    // click delay 120 us + 5 us per ADC sample: 5.12 .. 43.62 ms
    return {12120, 15620, 9870,  22120, 16370, 14120, 30120, 11370, 13620, 18870,
            16120, 12870, 25370, 14620, 13120, 43620, 17620, 15120, 19370, 5120};
}

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / (name + "." + std::to_string(getpid()))).string();
}

TEST_F(EmulatedBus, ListsTheProbesOnTheBusAndOnlyThose) {
    add_osltt({});
    add_vendor({{1000}});
    add_vendor({{1000}}, 1, 11, fgsr_identity(0x1209, 0xbeef)); // another PID, fgsr's interface class
    testbed_->add_plain(2, 3, mouse_identity());
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto list = list_probes(*usb, DeviceSelector{});
    ASSERT_TRUE(list.ok()) << list.error().message;
    ASSERT_EQ(list->size(), 3u);
    const ProbeDevice& o = (*list)[0];
    EXPECT_EQ(o.vid, 0x2886);
    EXPECT_EQ(o.address, 7);
    EXPECT_EQ(o.protocol, Protocol::osltt);
    EXPECT_EQ(o.comm_interface, 0);
    EXPECT_EQ(o.data_interface, 1);
    EXPECT_EQ(o.ep_out, 0x02);
    EXPECT_EQ(o.ep_in, 0x83);
    EXPECT_EQ(o.in_packet_size, 64);
    EXPECT_TRUE(o.problem.empty()) << o.problem;
    const ProbeDevice& v = (*list)[1];
    EXPECT_EQ(v.protocol, Protocol::fgsr);
    EXPECT_EQ(v.data_interface, 0);
    EXPECT_EQ(v.ep_out, 0x01);
    EXPECT_EQ(v.ep_in, 0x81);
    EXPECT_EQ((*list)[2].pid, 0xbeef);
    EXPECT_EQ((*list)[2].name, "fgsr-class device");

    // Named explicitly, the mouse is listed with the reason it cannot be used.
    auto mouse = list_probes(*usb, *parse_device_selector("2/3"));
    ASSERT_TRUE(mouse.ok());
    ASSERT_EQ(mouse->size(), 1u);
    EXPECT_NE((*mouse)[0].problem.find("no CDC data interface"), std::string::npos) << (*mouse)[0].problem;

    // Three usable probes: find_probe wants a choice.
    auto pick = find_probe(*usb, DeviceSelector{}, 0);
    ASSERT_FALSE(pick.ok());
    EXPECT_NE(pick.error().message.find("3 probes found"), std::string::npos) << pick.error().message;
    auto by_id = find_probe(*usb, *parse_device_selector("2886:802f"), 0);
    ASSERT_TRUE(by_id.ok()) << by_id.error().message;
    EXPECT_EQ(by_id->address, 7);

    // `fgsr probe --list`
    ProbeCommand c;
    c.list = true;
    c.progress = false;
    std::string report;
    ASSERT_TRUE(run_probe_command(c, {}, report).ok());
    EXPECT_NE(
        report.find("bus 1 address 7 (2886:802f)  OSLTT (Seeed XIAO SAMD21)  protocol osltt  interface 1, "
                    "endpoints out 0x02 in 0x83"),
        std::string::npos)
        << report;
    EXPECT_NE(report.find("bus 1 address 9 (1209:0001)"), std::string::npos) << report;
    EXPECT_EQ(report.find("046d:c077"), std::string::npos) << report;
    std::printf("--- fgsr probe --list ---\n%s", report.c_str());
}

TEST_F(EmulatedBus, NoProbeIsAClearErrorAtOnce) {
    testbed_->add_plain(2, 3, mouse_identity());
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    const auto t0 = std::chrono::steady_clock::now();
    auto d = find_probe(*usb, DeviceSelector{}, 0);
    ASSERT_FALSE(d.ok());
    EXPECT_EQ(d.error().code, Errc::no_device);
    EXPECT_NE(d.error().message.find("no supported probe found"), std::string::npos) << d.error().message;
    EXPECT_NE(d.error().message.find("--wait"), std::string::npos) << d.error().message;
    EXPECT_LT(seconds_since(t0), 1.0);
}

TEST_F(EmulatedBus, WaitsForAProbeToBePluggedIn) {
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    VendorScenario s{{1000}};
    auto dev = std::make_unique<EmulatedDevice>(std::make_unique<VendorGadget>(s), DriverBinding{});
    std::thread plug([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(400));
        testbed_->add(1, 12, fgsr_identity(), *dev);
    });
    const auto t0 = std::chrono::steady_clock::now();
    bool told = false;
    auto d = find_probe(*usb, DeviceSelector{}, 5000, [&] { told = true; });
    const double waited = seconds_since(t0);
    plug.join();
    ASSERT_TRUE(d.ok()) << d.error().message;
    EXPECT_TRUE(told);
    EXPECT_EQ(d->address, 12);
    EXPECT_GE(waited, 0.35);
    EXPECT_LT(waited, 3.0);
    devices_.push_back(std::move(dev));
}

TEST_F(EmulatedBus, OslttDetachesCdcAcmWhileRunningAndReattachesIt) {
    OslttScenario s;
    s.latencies_us = {12120, 15620, 9870};
    EmulatedDevice& dev = add_osltt(s);
    EXPECT_EQ(dev.driver(0), "cdc_acm");
    EXPECT_EQ(dev.driver(1), "cdc_acm");
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    {
        auto probe = open(*usb);
        ASSERT_TRUE(probe);
        EXPECT_EQ(probe->info().detached_interfaces, std::vector<uint8_t>{0});
        EXPECT_EQ(dev.driver(0), "");
        EXPECT_EQ(dev.driver(1), ""); // cdc_acm lets go of its data interface with the other
        EXPECT_EQ(dev.driver(2), "usbhid");
        auto r = probe->run(quiet_run(3));
        ASSERT_TRUE(r.ok()) << r.error().message;
        EXPECT_EQ(r->samples.size(), 3u);
    }
    EXPECT_EQ(dev.driver(0), "cdc_acm");
    EXPECT_EQ(dev.driver(1), "cdc_acm");
    EXPECT_EQ(dev.driver(2), "usbhid");
    const std::vector<std::string> log = dev.log();
    const auto at = [&](const std::string& e) {
        return size_t(std::find(log.begin(), log.end(), e) - log.begin());
    };
    ASSERT_LT(at("DISCONNECT 0"), log.size());
    EXPECT_LT(at("GETDRIVER 0 cdc_acm"), at("DISCONNECT 0"));
    EXPECT_LT(at("DISCONNECT 0"), at("CLAIM 0"));
    EXPECT_LT(at("CLAIM 0"), at("CLAIM 1"));
    EXPECT_LT(at("RELEASE 1"), at("CONNECT 0"));
    EXPECT_LT(at("CONNECT 0"), log.size());
    EXPECT_EQ(at("CLAIM 2"), log.size()); // the HID interface is left alone
    // Line coding and DTR went to the communication interface.
    auto& g = dev.gadget<OslttGadget>();
    EXPECT_EQ(g.baud, 115200u);
    EXPECT_TRUE(g.dtr);
    EXPECT_EQ(g.received.substr(0, 6), "X I X ");
}

TEST_F(EmulatedBus, VendorProbeWithoutKernelDriverIsClaimedWithoutDetach) {
    EmulatedDevice& dev = add_vendor({{1000}});
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto probe = open(*usb);
    ASSERT_TRUE(probe);
    EXPECT_TRUE(probe->info().detached_interfaces.empty());
    const auto log = dev.log();
    EXPECT_NE(std::find(log.begin(), log.end(), "GETDRIVER 0 -"), log.end());
    EXPECT_EQ(std::find(log.begin(), log.end(), "DISCONNECT 0"), log.end());
    EXPECT_NE(std::find(log.begin(), log.end(), "CLAIM 0"), log.end());
}

TEST_F(EmulatedBus, OslttHandshakeAndRunGiveTheExactDistribution) {
    OslttScenario s;
    s.latencies_us = osltt_latencies_us();
    ASSERT_EQ(s.samples, 9000u); // the firmware's count: 50 kB lines, many transfers each
    s.misses = {4};              // the fifth click shows no change: missed, not a sample
    s.series = 8;                // the button is pressed three times
    EmulatedDevice& dev = add_osltt(s);
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto probe = open(*usb);
    ASSERT_TRUE(probe);
    EXPECT_EQ(probe->info().firmware, "0.10");
    EXPECT_EQ(probe->info().protocol, Protocol::osltt);
    std::vector<Sample> live;
    RunOptions o = quiet_run(19);
    o.on_sample = [&](const Sample& x) { live.push_back(x); };
    const uint64_t before = fgsr::monotonic_ns();
    auto r = probe->run(o);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->samples.size(), 19u);
    EXPECT_EQ(r->missed, 1u);
    EXPECT_EQ(live.size(), 19u);
    std::vector<double> expect;
    for (size_t k = 0; k < s.latencies_us.size(); ++k)
        if (k != 4) expect.push_back(s.latencies_us[k] / 1000.0);
    for (size_t k = 0; k < 19; ++k) {
        EXPECT_DOUBLE_EQ(r->samples[k].latency_ms, expect[k]) << k;
        EXPECT_EQ(r->samples[k].index, k);
        EXPECT_EQ(r->samples[k].brightness_before, 1000u);
        EXPECT_EQ(r->samples[k].brightness_after, 3000u);
        EXPECT_GE(r->samples[k].click_ns, before - 100000000); // within the run (less the window)
        EXPECT_EQ(r->samples[k].photon_ns - r->samples[k].click_ns, uint64_t(std::llround(expect[k] * 1e6)));
    }
    const LatencySummary sum = summarize(r->samples);
    EXPECT_EQ(sum.count, 19u);
    EXPECT_DOUBLE_EQ(sum.p50, nearest_rank(expect, 50));
    EXPECT_DOUBLE_EQ(sum.p90, nearest_rank(expect, 90));
    EXPECT_DOUBLE_EQ(sum.p99, nearest_rank(expect, 99));
    EXPECT_DOUBLE_EQ(sum.min, 5.12);
    EXPECT_DOUBLE_EQ(sum.max, 43.62);
    EXPECT_DOUBLE_EQ(sum.p50, 15.12);
    // The probe was driven through the emulated device, and left out of test mode.
    EXPECT_GT(dev.ioctl_count(), 50u);
    const std::string sent = dev.gadget<OslttGadget>().received;
    EXPECT_EQ(sent.substr(sent.size() - 4), "T X ");
}

TEST_F(EmulatedBus, VendorRunMapsTheDeviceClockOntoMonotonic) {
    VendorScenario s;
    s.clock_hz = 1000000;
    s.drift_ppm = 150; // the probe's crystal runs fast
    s.latencies_ticks = {8000, 12500, 9750, 31000, 15250, 11000, 10000, 22500, 13750, 9000, 18000};
    s.misses = {7};
    EmulatedDevice& dev = add_vendor(s);
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto probe = open(*usb);
    ASSERT_TRUE(probe);
    EXPECT_EQ(probe->info().name, "fgsr-emulated");
    EXPECT_EQ(probe->info().firmware, "0.1.2");
    EXPECT_EQ(probe->info().clock_hz, 1e6);
    RunOptions o = quiet_run(37);
    o.interval_ms = 8;
    auto r = probe->run(o);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->samples.size(), 36u);
    EXPECT_EQ(r->missed, 1u);
    auto& g = dev.gadget<VendorGadget>();
    ASSERT_EQ(g.click_host_ns.size(), 1u);
    ASSERT_EQ(g.click_host_ns[0].size(), 36u);
    // Latencies from the probe's ticks at its nominal rate: exact.
    std::vector<double> expect;
    for (size_t k = 0; k < 36; ++k) expect.push_back(g.latencies_sent[0][k] / 1000.0);
    for (size_t k = 0; k < 36; ++k) EXPECT_DOUBLE_EQ(r->samples[k].latency_ms, expect[k]) << k;
    const LatencySummary sum = summarize(r->samples);
    EXPECT_DOUBLE_EQ(sum.p50, nearest_rank(expect, 50));
    EXPECT_DOUBLE_EQ(sum.p90, nearest_rank(expect, 90));
    EXPECT_DOUBLE_EQ(sum.p99, nearest_rank(expect, 99));
    EXPECT_DOUBLE_EQ(sum.min, 8.0);
    EXPECT_DOUBLE_EQ(sum.max, 31.0);
    // Click times: the device's ticks mapped back onto the host clock that made them, within the
    // mapping's own error bound (half a round trip plus the fit's residual), which must be small.
    EXPECT_GT(r->clock_error_ms, 0.0);
    EXPECT_LT(r->clock_error_ms, 10.0);
    const double bound_ns = r->clock_error_ms * 1e6 + 300e3; // + 150 ppm over the run's 0.3 s
    for (size_t k = 0; k < 36; ++k) {
        const double err = double(int64_t(r->samples[k].click_ns - g.click_host_ns[0][k]));
        EXPECT_LE(std::fabs(err), bound_ns) << "sample " << k << " mapped " << err / 1e6 << " ms off";
    }
    EXPECT_GE(g.syncs, 24u); // at open, before and after the run
}

TEST_F(EmulatedBus, MeasurementModeRunsTheCommandPerModeWithTheLayersEnvironment) {
    VendorScenario s;
    s.latencies_ticks = {10000, 12000, 14000, 16000, 18000};
    s.run_scale = {1.0, 2.0, 0.5}; // off, interpolate, extrapolate measure differently
    add_vendor(s);
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto probe = open(*usb);
    ASSERT_TRUE(probe);
    const std::string env_file = temp_path("fgsr_probe_modes_env");
    std::filesystem::remove(env_file);
    setenv("FGSR_MODE", "stale", 1); // must not leak into the off run
    MeasureOptions m;
    m.command = "echo \"enable=$FGSR_ENABLE mode=$FGSR_MODE disable=$FGSR_DISABLE\" >> " + env_file +
                "; exec sleep 30";
    m.modes = {Mode::off, Mode::interpolate, Mode::extrapolate};
    m.warmup_s = 0.2;
    m.run = quiet_run(5);
    std::vector<std::pair<Mode, uint32_t>> seen;
    m.on_sample = [&](Mode mode, const Sample&, uint32_t pid) { seen.emplace_back(mode, pid); };
    const auto t0 = std::chrono::steady_clock::now();
    auto runs = run_modes(*probe, m);
    unsetenv("FGSR_MODE");
    ASSERT_TRUE(runs.ok()) << runs.error().message;
    EXPECT_LT(seconds_since(t0), 10.0); // each `sleep 30` was stopped, not waited for
    ASSERT_EQ(runs->size(), 3u);
    const double p50[3] = {14.0, 28.0, 7.0};
    for (size_t i = 0; i < 3; ++i) {
        const ModeRun& run = (*runs)[i];
        EXPECT_EQ(run.mode, m.modes[i]);
        EXPECT_EQ(run.summary.count, 5u);
        EXPECT_DOUBLE_EQ(run.summary.p50, p50[i]) << mode_name(run.mode);
        EXPECT_NE(run.pid, 0u);
        errno = 0;
        EXPECT_EQ(kill(pid_t(run.pid), 0), -1) << "pid " << run.pid << " still runs";
        EXPECT_EQ(errno, ESRCH);
    }
    ASSERT_EQ(seen.size(), 15u);
    EXPECT_EQ(seen[0].first, Mode::off);
    EXPECT_EQ(seen[14].first, Mode::extrapolate);
    EXPECT_EQ(seen[14].second, (*runs)[2].pid);
    std::ifstream f(env_file);
    std::stringstream text;
    text << f.rdbuf();
    EXPECT_EQ(text.str(), "enable= mode= disable=1\n"
                          "enable=1 mode=interpolate disable=\n"
                          "enable=1 mode=extrapolate disable=\n");
    std::filesystem::remove(env_file);

    std::vector<ModeColumn> cols;
    for (const ModeRun& run : *runs) cols.push_back({run.mode, run.summary, 0});
    const std::string table = modes_table(cols);
    std::istringstream lines(table);
    std::string line, p50_line, mode_line;
    while (std::getline(lines, line)) {
        if (line.rfind("p50 ", 0) == 0) p50_line = line;
        if (line.rfind("mode ", 0) == 0) mode_line = line;
    }
    std::istringstream p50_words(p50_line), mode_words(mode_line);
    std::string w[4];
    p50_words >> w[0] >> w[1] >> w[2] >> w[3];
    EXPECT_EQ(w[1] + " " + w[2] + " " + w[3], "14.000 28.000 7.000") << table;
    mode_words >> w[0] >> w[1] >> w[2] >> w[3];
    EXPECT_EQ(w[1] + " " + w[2] + " " + w[3], "off interpolate extrapolate") << table;
    std::printf("%s", table.c_str());
}

TEST_F(EmulatedBus, MeasurementModeFailsWhenTheCommandExits) {
    add_vendor({{1000}});
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto probe = open(*usb);
    ASSERT_TRUE(probe);
    MeasureOptions m;
    m.command = "exit 3";
    m.modes = {Mode::off};
    m.warmup_s = 0.5;
    m.run = quiet_run(3);
    auto runs = run_modes(*probe, m);
    ASSERT_FALSE(runs.ok());
    EXPECT_EQ(runs.error().message, "off: the command exited with status 3 during the warm-up");
}

TEST_F(EmulatedBus, FgsrProbeCommandReportsAndWritesTheCsv) {
    VendorScenario s;
    s.latencies_ticks = {11000, 9000, 15000, 13000, 12000, 10000, 14000, 16000, 8000, 17000};
    add_vendor(s);
    const std::string csv = temp_path("fgsr_probe.csv");
    ProbeCommand c;
    c.count = 20;
    c.interval_ms = 5;
    c.timeout_ms = 1000;
    c.csv = csv;
    c.progress = false;
    std::vector<Sample> sent;
    std::string report;
    auto r = run_probe_command(
        c,
        [&](Mode m, const Sample& x, uint32_t) {
            EXPECT_EQ(m, Mode::unknown);
            sent.push_back(x);
        },
        report);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(sent.size(), 20u);
    std::printf("--- fgsr probe --count 20 --interval 5 --csv %s ---\n%s", csv.c_str(), report.c_str());
    EXPECT_NE(
        report.find("probe: fgsr-emulated (fgsr protocol), firmware 0.1.2, at bus 1 address 9 (1209:0001), "
                    "clock 1000000 Hz"),
        std::string::npos);
    EXPECT_NE(
        report.find("click-to-photon latency over 20 samples: p50 12.000 ms, p90 16.000 ms, p99 17.000 ms, "
                    "min 8.000 ms, max 17.000 ms, mean 12.500 ms"),
        std::string::npos)
        << report;
    // The CSV reads back as PresentMon's columns, MsClickToPhotonLatency per sample.
    std::ifstream f(csv);
    std::stringstream text;
    text << f.rdbuf();
    auto rows = fgsr::parse_presentmon_csv(text.str());
    ASSERT_TRUE(rows.ok()) << rows.error().message;
    ASSERT_EQ(rows->size(), 20u);
    for (size_t k = 0; k < 20; ++k) {
        EXPECT_DOUBLE_EQ((*rows)[k].ms_click_to_photon, s.latencies_ticks[k % 10] / 1000.0) << k;
        EXPECT_EQ((*rows)[k].frame_type, "Application");
        EXPECT_NEAR((*rows)[k].time_s, double(sent[k].photon_ns) / 1e9, 0.01);
    }
    EXPECT_NE(text.str().find(",probe_mode,probe_index,probe_click_ns,"), std::string::npos);
    std::filesystem::remove(csv);
}

} // namespace
} // namespace fgsr::probe::test
