// The measurement mode of `fgsr probe --run-command CMD --modes off,interpolate,extrapolate`: for
// each mode, CMD is started (`/bin/sh -c CMD`, in a process group of its own) with the environment
// of fgsr's Vulkan layer for that mode (mode_environment: README "Unmodified applications"), left
// to come up for the warm-up, measured with the probe, and stopped (SIGTERM to its group, SIGKILL
// after 2 s); then the next mode. CMD must flash on each injected click (fgsr_layer_app
// --flash-on-click does).
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/probe/probe.hpp>
#include <fgsr/probe/report.hpp>

#include <sys/types.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace fgsr::probe {

// The variables set for a mode: off: FGSR_DISABLE=1; interpolate / extrapolate: FGSR_ENABLE=1 and
// FGSR_MODE=<mode>. The variables of the other modes are removed from the child's environment.
std::vector<std::pair<std::string, std::string>> mode_environment(Mode m);

// A command run by /bin/sh -c in its own process group; stopped (and reaped) when destroyed.
class ChildProcess {
  public:
    static Result<ChildProcess> spawn(const std::string& command,
                                      const std::vector<std::pair<std::string, std::string>>& set_env,
                                      const std::vector<std::string>& unset_env);
    ChildProcess(ChildProcess&& o) noexcept;
    ChildProcess& operator=(ChildProcess&& o) noexcept;
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;
    ~ChildProcess();

    pid_t pid() const { return pid_; }
    // Whether it still runs; when it has exited, its status (as waitpid's) is kept for exit_text().
    bool running();
    std::string exit_text() const; // "exited with status 3", "killed by signal 9"
    // SIGTERM to the group, SIGKILL after grace_ms; returns how it ended.
    std::string stop(int grace_ms = 2000);

  private:
    explicit ChildProcess(pid_t p) : pid_(p) {}
    pid_t pid_ = -1;
    int status_ = 0;
    bool exited_ = false;
};

struct MeasureOptions {
    std::string command;
    std::vector<Mode> modes;
    double warmup_s = 3;
    RunOptions run; // on_sample is replaced: see on_sample below
    // Each sample as it arrives, with the mode and the command's pid.
    std::function<void(Mode, const Sample&, uint32_t pid)> on_sample;
};

struct ModeRun {
    Mode mode = Mode::unknown;
    uint32_t pid = 0;
    RunResult result;
    LatencySummary summary;
};

// Runs the command once per mode and measures it. Fails when the command cannot be started, exits
// before or during its measurement, or the probe fails (the command is stopped in every case).
Result<std::vector<ModeRun>> run_modes(Probe& probe, const MeasureOptions& options);

} // namespace fgsr::probe
