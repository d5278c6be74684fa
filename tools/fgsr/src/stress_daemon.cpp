// `fgsr stress --daemon`: the stress cases fed through fgsrd (fgsr/stress/daemon.hpp). Without
// --socket it spawns the fgsrd next to this executable on a socket in a fresh temporary directory,
// with its stderr in a file there (read for the rejection reasons), and stops it (SIGTERM) after.
#include <fgsr/cli/stress.hpp>

#include <fgsr/capture/stress.hpp>
#include <fgsr/stress/daemon.hpp>
#include <fgsr/testing/fgsrd_process.hpp>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <unistd.h>

namespace fgsr::cli {

namespace {

// Frames above this many pixels are not fed through the daemon (the 1920x1080 case of the full
// table: the engine feeder covers it; through the daemon it only adds copies).
constexpr size_t kMaxDaemonPixels = 1u << 20;

using daemon_process::FgsrdProcess;

// The fgsrd next to this executable, started on a socket in a fresh temporary directory
// (fgsr/testing/fgsrd_process.hpp). Nullptr and `error` when it cannot be started.
std::unique_ptr<FgsrdProcess> start_own_daemon(std::string& error) {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path fgsrd = exe.parent_path() / "fgsrd";
    if (ec || access(fgsrd.c_str(), X_OK) != 0) {
        error = "no executable fgsrd next to " + exe.string() + " (build it, or pass --socket)";
        return nullptr;
    }
    auto d = FgsrdProcess::start_at(fgsrd.string(), {}, 60000, "fgsr-stress");
    if (!d) error = FgsrdProcess::last_error();
    return d;
}

// Stops the daemon when the run ends: SIGTERM, then SIGKILL after 10 s.
struct StopOnExit {
    FgsrdProcess* daemon = nullptr;
    ~StopOnExit() {
        if (daemon) daemon->terminate(10000);
    }
};

} // namespace

int stress_daemon_main(const StressCli& o) {
    std::unique_ptr<FgsrdProcess> own;
    stress::DaemonTarget target;
    if (o.socket.empty()) {
        std::string error;
        own = start_own_daemon(error);
        if (!own) {
            std::fprintf(stderr, "fgsr: cannot start fgsrd: %s\n", error.c_str());
            return 1;
        }
        target.socket = own->socket_path();
        target.log = [d = own.get()] { return d->stderr_text(); };
        target.alive = [d = own.get()] { return d->running(); };
        if (!o.quiet)
            std::fprintf(stderr, "fgsrd started on %s (log %s)\n", own->socket_path().c_str(),
                         own->stderr_path().c_str());
    } else {
        target.socket = o.socket;
        if (!o.quiet)
            std::fprintf(stderr,
                         "fgsrd at %s: its log is not readable here, rejection reasons are unchecked\n",
                         o.socket.c_str());
    }
    const StopOnExit stop{own.get()};
    // The client library's own notes (e.g. "fgsrd refused the session") would interleave with the
    // report: the feeder reads the reasons from the daemon's log instead.
    setenv("FGSR_CLIENT_QUIET", "1", 1);

    nlohmann::json header;
    header["target"] = "fgsrd";
    header["socket"] = target.socket;
    return run_and_report(
        o, "fgsr stress through fgsrd (" + target.socket + ")", header,
        [&](const stress::Case& c, const stress::RunOptions& ro) {
            return stress::run_on_daemon(target, c, ro, kMaxDaemonPixels);
        },
        [&] {
            if (!own || own->running()) return false;
            std::fprintf(stderr, "fgsr: fgsrd died (wait status %d); its log:\n%s\n", own->exit_status(),
                         own->stderr_text().c_str());
            return true;
        });
}

} // namespace fgsr::cli
