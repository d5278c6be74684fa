// The fault cases of both protocols against emulated probes: unplug mid-run, a stalled endpoint, a
// probe that stops answering (timeout), garbage, a probe that never answers, and protocol
// violations. Each must end in an error value whose message says what happened, within a bounded
// time (asserted), and leave nothing hanging. The messages are printed for the record.
#include "probe_fixture.hpp"

#include <fgsr/probe/vendor_protocol.hpp>

#include <linux/capability.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdio>

namespace fgsr::probe::test {
namespace {

struct Outcome {
    Error error{Errc::io, ""};
    double seconds = 0;
    bool failed = false;
    bool opened = false;
};

class Faults : public EmulatedBus {
  protected:
    // Opens the one probe and runs `count` measurements; the first failure is the outcome.
    Outcome attempt(uint32_t count, int timeout_ms = 300) {
        Outcome out;
        auto usb = UsbContext::create();
        EXPECT_TRUE(usb.ok());
        const auto t0 = std::chrono::steady_clock::now();
        auto d = find_probe(*usb, DeviceSelector{}, 0);
        EXPECT_TRUE(d.ok());
        if (!d) return out;
        OpenOptions oo;
        oo.timeout_ms = timeout_ms;
        oo.progress = false;
        auto p = open_probe(*usb, *d, oo);
        if (!p) {
            out.failed = true;
            out.error = p.error();
        } else {
            out.opened = true;
            auto r = (*p)->run(quiet_run(count, timeout_ms));
            if (!r) {
                out.failed = true;
                out.error = r.error();
            }
        }
        out.seconds = seconds_since(t0);
        std::printf("[%s] %.2f s: %s: %s\n", ::testing::UnitTest::GetInstance()->current_test_info()->name(),
                    out.seconds, errc_name(out.error.code), out.error.message.c_str());
        return out;
    }
};

bool has(const Outcome& o, const std::string& text) {
    return o.error.message.find(text) != std::string::npos;
}

OslttScenario osltt_run(size_t results = 10) {
    OslttScenario s;
    for (size_t k = 0; k < results; ++k) s.latencies_us.push_back(uint32_t(10120 + 500 * k));
    return s;
}

VendorScenario vendor_run() {
    VendorScenario s;
    s.latencies_ticks = {10000, 12000, 14000};
    return s;
}

// Root ignores file modes: drops the capabilities that let it (from the effective set only, so
// that they can be taken back) while alive.
class WithoutDacOverride {
  public:
    WithoutDacOverride() {
        if (geteuid() != 0) return;
        if (syscall(SYS_capget, &header_, saved_) != 0) return;
        __user_cap_data_struct reduced[2] = {saved_[0], saved_[1]};
        reduced[0].effective &= ~((1u << CAP_DAC_OVERRIDE) | (1u << CAP_DAC_READ_SEARCH));
        dropped_ = syscall(SYS_capset, &header_, reduced) == 0;
    }
    ~WithoutDacOverride() {
        if (dropped_) syscall(SYS_capset, &header_, saved_);
    }
    bool effective() const { return geteuid() != 0 || dropped_; }

  private:
    __user_cap_header_struct header_{_LINUX_CAPABILITY_VERSION_3, 0};
    __user_cap_data_struct saved_[2]{};
    bool dropped_ = false;
};

TEST_F(Faults, PermissionDeniedNamesTheUdevRule) {
    add_vendor(vendor_run());
    const std::string node = testbed_->root_dir() + "/dev/bus/usb/001/009";
    ASSERT_EQ(chmod(node.c_str(), 0), 0) << node;
    auto usb = UsbContext::create();
    ASSERT_TRUE(usb.ok());
    auto d = find_probe(*usb, DeviceSelector{}, 0);
    ASSERT_TRUE(d.ok()) << d.error().message;
    Result<std::unique_ptr<Probe>> p = make_error(Errc::io, "not tried");
    {
        WithoutDacOverride guard;
        if (!guard.effective()) GTEST_SKIP() << "cannot drop CAP_DAC_OVERRIDE here";
        p = open_probe(*usb, *d, OpenOptions{300, false});
    }
    ASSERT_FALSE(p.ok());
    std::printf("[PermissionDenied] %s\n", p.error().message.c_str());
    EXPECT_EQ(
        p.error().message.rfind("cannot open the probe at bus 1 address 9 (1209:0001): permission denied", 0),
        0u)
        << p.error().message;
    EXPECT_NE(p.error().message.find("70-fgsr-probe.rules /etc/udev/rules.d/"), std::string::npos);
}

// --- OSLTT ---

TEST_F(Faults, OslttUnpluggedMidRun) {
    OslttScenario s = osltt_run();
    s.unplug_after = 4;
    EmulatedDevice& dev = add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.code, Errc::no_device);
    EXPECT_EQ(o.error.message,
              "OSLTT measurement, waiting for result 5 of 10: the probe was unplugged (or reset)");
    EXPECT_LT(o.seconds, 5.0);
    EXPECT_TRUE(dev.unplugged());
    testbed_->remove(sysfs_[0]);
    auto usb = UsbContext::create();
    auto gone = find_probe(*usb, DeviceSelector{}, 0);
    EXPECT_FALSE(gone.ok());
}

TEST_F(Faults, OslttStall) {
    OslttScenario s = osltt_run();
    s.stall_after = 2;
    EmulatedDevice& dev = add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message,
              "OSLTT measurement, waiting for result 3 of 10: the endpoint stalled (the probe refused the "
              "transfer)");
    EXPECT_LT(o.seconds, 5.0);
    // The stall was cleared, and the probe told to leave test mode.
    const auto log = dev.log();
    EXPECT_NE(std::find(log.begin(), log.end(), "CLEAR_HALT 0x83"), log.end());
    const std::string sent = dev.gadget<OslttGadget>().received;
    EXPECT_EQ(sent.substr(sent.size() - 4), "T X ");
}

TEST_F(Faults, OslttStopsAnsweringMidRun) {
    OslttScenario s = osltt_run();
    s.silent_after = 3;
    add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message, "OSLTT measurement: no result within 300 ms after 3 of 10");
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, OslttGarbage) {
    OslttScenario s = osltt_run();
    s.garbage_after = 2;
    add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    // Result 2 or 3: the garbage may arrive in the transfer that completes the line of result 2.
    EXPECT_TRUE(has(o, "OSLTT measurement, waiting for result ")) << o.error.message;
    EXPECT_TRUE(has(o, " of 10: binary data from the probe (byte 0x01 at offset")) << o.error.message;
    EXPECT_TRUE(has(o, "not OSLTT's text protocol")) << o.error.message;
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, OslttMalformedResult) {
    OslttScenario s = osltt_run();
    s.malformed_after = 1;
    add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_TRUE(has(o, "malformed RES: line from the probe (window: a number of us, 1 us to 10 s): "
                       "'RES:120,abc,2000,1,2,3,'"))
        << o.error.message;
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, OslttNeverAnswers) {
    OslttScenario s = osltt_run();
    s.never_answer = true;
    EmulatedDevice& dev = add_osltt(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_FALSE(o.opened);
    EXPECT_EQ(o.error.message,
              "OSLTT handshake: no 'FW:' reply to 'I' within 300 ms (the probe sent nothing: is "
              "it an OSLTT, and is its firmware running?)");
    EXPECT_LT(o.seconds, 3.0);
    // Even after a failed handshake, cdc_acm is given its interfaces back.
    EXPECT_EQ(dev.driver(0), "cdc_acm");
    EXPECT_EQ(dev.driver(1), "cdc_acm");
}

// --- fgsr vendor protocol ---

TEST_F(Faults, VendorUnpluggedMidRun) {
    VendorScenario s = vendor_run();
    s.unplug_after = 5;
    EmulatedDevice& dev = add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.code, Errc::no_device);
    EXPECT_EQ(o.error.message,
              "fgsr probe run: waiting for sample 6 of 10: the probe was unplugged (or reset)");
    EXPECT_LT(o.seconds, 5.0);
    EXPECT_TRUE(dev.unplugged());
}

TEST_F(Faults, VendorStall) {
    VendorScenario s = vendor_run();
    s.stall_after = 3;
    EmulatedDevice& dev = add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message,
              "fgsr probe run: waiting for sample 4 of 10: the endpoint stalled (the probe refused "
              "the transfer)");
    EXPECT_LT(o.seconds, 5.0);
    // The stall was cleared and the run aborted.
    const auto log = dev.log();
    EXPECT_NE(std::find(log.begin(), log.end(), "CLEAR_HALT 0x81"), log.end());
    EXPECT_GE(dev.gadget<VendorGadget>().aborts, 2u); // at open, and after the failure
}

TEST_F(Faults, VendorStopsAnsweringMidRun) {
    VendorScenario s = vendor_run();
    s.silent_after = 4;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message, "fgsr probe run: waiting for sample 5 of 10: no reply within 305 ms");
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, VendorGarbageSample) {
    VendorScenario s = vendor_run();
    s.garbage_after = 2;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message,
              "fgsr probe run: waiting for sample 3 of 10: reply with magic 0x4247 (expected "
              "0x5046): not fgsr's probe protocol");
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, VendorGarbageHandshake) {
    VendorScenario s = vendor_run();
    s.garbage_info = true;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_FALSE(o.opened);
    EXPECT_EQ(o.error.message,
              "fgsr probe handshake: GET_INFO: reply with magic 0x6548 (expected 0x5046): not "
              "fgsr's probe protocol");
    EXPECT_LT(o.seconds, 3.0);
}

TEST_F(Faults, VendorNeverAnswers) {
    VendorScenario s = vendor_run();
    s.never_answer = true;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_FALSE(o.opened);
    EXPECT_EQ(o.error.message,
              "fgsr probe handshake: GET_INFO: no reply within 300 ms (the probe sent nothing: is "
              "its firmware running?)");
    EXPECT_LT(o.seconds, 3.0);
}

TEST_F(Faults, VendorPhotonBeforeClick) {
    VendorScenario s = vendor_run();
    s.bad_photon_after = 1;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_TRUE(has(o, "waiting for sample 2 of 10: SAMPLE 1: photon_ts 0 before click_ts "))
        << o.error.message;
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, VendorLostSample) {
    VendorScenario s = vendor_run();
    s.skip_index_after = 6;
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_EQ(o.error.message, "fgsr probe run: SAMPLE index 7, expected 6 (samples lost or repeated)");
    EXPECT_LT(o.seconds, 5.0);
}

TEST_F(Faults, VendorRefusesToStart) {
    VendorScenario s = vendor_run();
    s.start_error = uint16_t(VendorErrorCode::sensor);
    add_vendor(s);
    const Outcome o = attempt(10);
    ASSERT_TRUE(o.failed);
    EXPECT_TRUE(o.opened);
    EXPECT_EQ(o.error.message, "fgsr probe run: START: the probe's light sensor reads nothing usable (dark, "
                               "saturated or disconnected) (detail 0)");
    EXPECT_LT(o.seconds, 5.0);
}

} // namespace
} // namespace fgsr::probe::test
