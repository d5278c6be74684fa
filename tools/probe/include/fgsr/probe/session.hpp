// What `fgsr probe` does once its command line is parsed, without the command-line parser and
// without fgsrd (the caller passes a sink for the samples): list the probes, or find one (waiting
// for it with --wait), open it, run N measurements (or the measurement mode over a command), and
// produce the report text (probe, per-sample latencies, summary or the side-by-side table) and
// the CSV. tools/fgsr/src/probe_cmd.cpp is the front end; tests/probe runs it against emulated
// probes.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/probe/report.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace fgsr::probe {

struct ProbeCommand {
    bool list = false;
    std::string device;            // --device: VID:PID or BUS/ADDRESS, empty: the one probe there is
    std::string protocol = "auto"; // --protocol: auto, osltt, fgsr
    uint32_t count = 20;
    uint32_t interval_ms = 300;
    uint32_t threshold = 0;
    int timeout_ms = 2000;
    int start_timeout_ms = 60000; // OSLTT: wait for the button press
    double wait_s = 0;            // --wait: for a probe to be plugged in
    std::string csv;              // --csv FILE
    std::string run_command;      // --run-command: the measurement mode
    std::string modes = "off,interpolate,extrapolate";
    double warmup_s = 3;
    bool progress = true;
};

// Where the samples go as they arrive besides the report (fgsrd): mode (unknown outside the
// measurement mode), the sample, the measured command's pid (0 unknown).
using SampleSink = std::function<void(Mode, const Sample&, uint32_t pid)>;

// Runs the command; `report` receives what `fgsr probe` prints on stdout (also when it fails
// part-way: what was done until then). Progress goes to stderr.
Result<void> run_probe_command(const ProbeCommand& command, const SampleSink& sink, std::string& report,
                               const std::atomic<bool>* cancel = nullptr);

} // namespace fgsr::probe
