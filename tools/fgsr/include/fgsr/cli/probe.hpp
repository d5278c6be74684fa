// `fgsr probe`: click-to-photon latency measured at the screen by a hardware probe over USB
// (fgsr_probe, tools/probe; docs/PROBE.md): the options, their help (both protocols), and the run,
// which sends every sample to fgsrd when one listens (fgsr_report_probe_samples) and goes on
// without it otherwise. Ctrl-C stops a run at the next reply (the probe is told to stop, the
// kernel driver given back).
#pragma once

#include <fgsr/probe/session.hpp>

#include <string>

namespace CLI {
class App;
}

namespace fgsr::cli {

struct ProbeCli {
    probe::ProbeCommand command;
    std::string socket; // --socket: fgsrd (default: $FGSR_SOCKET, else $XDG_RUNTIME_DIR/fgsr/fgsrd.sock)
    bool quiet = false;
};

CLI::App* add_probe_command(CLI::App& app, ProbeCli& c);
int probe_main(ProbeCli& c);

} // namespace fgsr::cli
