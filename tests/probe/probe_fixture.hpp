// The fixture of fgsr_probe_tests: a umockdev testbed of its own per test (and the check that the
// emulation is in effect: a test fails, not skips, when the process runs without umockdev's
// preload library), helpers that put emulated probes on the bus, and small expectations computed
// independently of fgsr_probe (nearest-rank percentiles by integer rank).
#pragma once

#include "gadgets.hpp"
#include "usb_emulation.hpp"

#include <fgsr/probe/device.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <vector>

namespace fgsr::probe::test {

class EmulatedBus : public ::testing::Test {
  protected:
    void SetUp() override {
        testbed_ = std::make_unique<Testbed>();
        ASSERT_TRUE(Testbed::in_mock_environment())
            << "the umockdev emulation is not in effect: run the tests under umockdev-wrapper "
               "(LD_PRELOAD=libumockdev-preload.so.0), as ctest does";
        ASSERT_NE(std::getenv("UMOCKDEV_DIR"), nullptr);
    }
    void TearDown() override {
        devices_.clear();
        testbed_.reset();
    }

    EmulatedDevice& add_osltt(OslttScenario s, uint8_t bus = 1, uint8_t address = 7) {
        devices_.push_back(
            std::make_unique<EmulatedDevice>(std::make_unique<OslttGadget>(std::move(s)), osltt_drivers()));
        sysfs_.push_back(testbed_->add(bus, address, osltt_identity(), *devices_.back()));
        return *devices_.back();
    }
    EmulatedDevice& add_vendor(VendorScenario s, uint8_t bus = 1, uint8_t address = 9,
                               UsbIdentity identity = fgsr_identity()) {
        devices_.push_back(
            std::make_unique<EmulatedDevice>(std::make_unique<VendorGadget>(std::move(s)), DriverBinding{}));
        sysfs_.push_back(testbed_->add(bus, address, identity, *devices_.back()));
        return *devices_.back();
    }

    // The one probe on the bus, opened.
    std::unique_ptr<Probe> open(UsbContext& usb, int timeout_ms = 1000) {
        auto d = find_probe(usb, DeviceSelector{}, 0);
        EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
        if (!d) return nullptr;
        OpenOptions o;
        o.timeout_ms = timeout_ms;
        o.progress = false;
        auto p = open_probe(usb, *d, o);
        EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message);
        return p ? std::move(*p) : nullptr;
    }

    std::unique_ptr<Testbed> testbed_;
    std::vector<std::unique_ptr<EmulatedDevice>> devices_;
    std::vector<std::string> sysfs_;
};

// Nearest rank: the sample at rank ceil(pct/100 * n) of the sorted values.
inline double nearest_rank(std::vector<double> v, unsigned pct) {
    std::sort(v.begin(), v.end());
    const size_t rank = std::max<size_t>(1, (size_t(pct) * v.size() + 99) / 100);
    return v[rank - 1];
}

inline RunOptions quiet_run(uint32_t count, int timeout_ms = 1000) {
    RunOptions o;
    o.count = count;
    o.interval_ms = 5;
    o.timeout_ms = timeout_ms;
    o.start_timeout_ms = 2000;
    o.progress = false;
    return o;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace fgsr::probe::test
