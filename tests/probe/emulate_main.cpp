// fgsr_probe_emulator: runs a command with emulated probes on the USB bus, so that the real `fgsr
// probe` (or anything using libusb) can be tried without hardware:
//
//   umockdev-wrapper fgsr_probe_emulator [--gadget fgsr|osltt|both] [--fault none|unplug|stall|
//       timeout|garbage|silent-handshake] [--count N] -- COMMAND [ARGS...]
//
// It must itself run under umockdev-wrapper; it creates the testbed (UMOCKDEV_DIR), puts the
// probes on it (fgsr's vendor probe at bus 1 address 9, OSLTT at bus 1 address 7; latencies from
// 8 to 17 ms, 1 MHz probe clock with 120 ppm drift; the vendor probe's second and third runs, as
// in the measurement mode's interpolate and extrapolate, scaled by 1.45 and 0.95), starts COMMAND with its
// environment (so the preload library and UMOCKDEV_DIR reach it) and answers the probes' ioctls on its own
// thread until COMMAND exits. Exits with COMMAND's status (2: usage, 3: the emulation is not in effect).
#include "gadgets.hpp"
#include "usb_emulation.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace fgsr::probe::test;

namespace {

int usage() {
    std::fprintf(stderr,
                 "usage: umockdev-wrapper fgsr_probe_emulator [--gadget fgsr|osltt|both] [--fault "
                 "none|unplug|stall|timeout|garbage|silent-handshake] [--count N] -- COMMAND [ARGS...]\n");
    return 2;
}

} // namespace

// --fault NAME on either emulated probe (their scenarios name the faults alike).
template <class Scenario> void apply_fault(Scenario& s, const std::string& fault) {
    s.never_answer = fault == "silent-handshake";
    if (fault == "unplug") s.unplug_after = 5;
    if (fault == "stall") s.stall_after = 5;
    if (fault == "timeout") s.silent_after = 5;
    if (fault == "garbage") s.garbage_after = 5;
}

int main(int argc, char** argv) {
    std::string gadget = "fgsr", fault = "none";
    size_t count = 200;
    int i = 1;
    for (; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--") {
            ++i;
            break;
        }
        if (i + 1 >= argc) return usage();
        if (a == "--gadget")
            gadget = argv[++i];
        else if (a == "--fault")
            fault = argv[++i];
        else if (a == "--count")
            count = std::strtoul(argv[++i], nullptr, 10);
        else
            return usage();
    }
    if (i >= argc || (gadget != "fgsr" && gadget != "osltt" && gadget != "both")) return usage();

    Testbed testbed;
    if (!Testbed::in_mock_environment()) {
        std::fprintf(stderr, "fgsr_probe_emulator: the umockdev emulation is not in effect: run it under "
                             "umockdev-wrapper\n");
        return 3;
    }
    const std::vector<uint32_t> ms = {11, 9, 15, 13, 12, 10, 14, 16, 8, 17};
    std::vector<std::unique_ptr<EmulatedDevice>> devices;
    if (gadget == "fgsr" || gadget == "both") {
        VendorScenario s;
        for (uint32_t m : ms) s.latencies_ticks.push_back(m * 1000 + 250);
        s.drift_ppm = 120;
        s.run_scale = {1.0, 1.45, 0.95}; // measurement mode: off, interpolate (a frame later), extrapolate
        apply_fault(s, fault);
        devices.push_back(
            std::make_unique<EmulatedDevice>(std::make_unique<VendorGadget>(s), DriverBinding{}));
        testbed.add(1, 9, fgsr_identity(), *devices.back());
    }
    if (gadget == "osltt" || gadget == "both") {
        OslttScenario s;
        for (size_t k = 0; k < count; ++k)
            s.latencies_us.push_back(ms[k % ms.size()] * 1000 + 120 + 5 * uint32_t(k % 7));
        s.samples = 9000;
        s.interval_ms = 20;
        apply_fault(s, fault);
        devices.push_back(
            std::make_unique<EmulatedDevice>(std::make_unique<OslttGadget>(s), osltt_drivers()));
        testbed.add(1, 7, osltt_identity(), *devices.back());
    }

    const pid_t pid = fork();
    if (pid < 0) return 1;
    if (pid == 0) {
        execvp(argv[i], argv + i);
        std::fprintf(stderr, "fgsr_probe_emulator: cannot run %s: %s\n", argv[i], std::strerror(errno));
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
