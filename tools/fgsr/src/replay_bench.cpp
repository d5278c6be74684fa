// `fgsr replay --bench`: the service overhead of fgsrd, with spinning off and on in the same run.
//
// Per size, a synthetic capture (two rendered frames repeated) is replayed with one frame in flight
// (closed loop) through two configurations: "off" (fgsrd --spin-us 0, FGSR_WAIT_SPIN_US=0) and "on"
// (both at --bench-spin-us), alternating which goes first from run to run. Without --socket it
// starts the two fgsrd itself (the fgsrd next to this executable) and reads their threads' CPU time
// from /proc/<pid>/task/*/schedstat (nanoseconds); with --socket only the client's spin differs and
// the daemon's CPU time is not known. Prints one line per run and the medians over the runs.
#include <fgsr/cli/replay.hpp>

#include <fgsr/capture/fgsr_format.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/testing/fgsrd_process.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <dirent.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

namespace fgsr::cli {

namespace {

using daemon_process::FgsrdProcess;

// CPU time (ns) of a process's threads: the I/O thread (tid == pid) and all of them together.
struct DaemonCpu {
    uint64_t io_ns = 0, total_ns = 0;
    bool known = false;
};

DaemonCpu daemon_cpu(pid_t pid) {
    DaemonCpu c;
    if (pid <= 0) return c;
    const std::string dir = "/proc/" + std::to_string(pid) + "/task";
    DIR* d = opendir(dir.c_str());
    if (!d) return c;
    while (const dirent* e = readdir(d)) {
        if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
        std::ifstream f(dir + "/" + e->d_name + "/schedstat");
        uint64_t run_ns = 0;
        if (!(f >> run_ns)) continue;
        c.total_ns += run_ns;
        if (std::string(e->d_name) == std::to_string(pid)) c.io_ns = run_ns;
        c.known = true;
    }
    closedir(d);
    return c;
}

struct Config {
    const char* name;
    uint32_t spin_us;
    FgsrdProcess* daemon; // null: the daemon at options.socket
    std::string socket;
};

struct RunFigures {
    double rtt_p50_us, rtt_p99_us, ovh_p50_us, ovh_p99_us, wake_us, handoff_us, return_us;
    double io_cpu_us, daemon_cpu_us, client_cpu_us; // per submit; negative: unknown
};

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string cpu_text(double us) {
    return us < 0 ? std::string("n/a") : fmt::format("{:.1f}", us);
}

void print_row(const std::string& label, const RunFigures& f) {
    std::printf("%-24s %9.1f %9.1f %9.1f %9.1f %7.1f %7.1f %7.1f %9s %10s %9s\n", label.c_str(), f.rtt_p50_us,
                f.rtt_p99_us, f.ovh_p50_us, f.ovh_p99_us, f.wake_us, f.handoff_us, f.return_us,
                cpu_text(f.io_cpu_us).c_str(), cpu_text(f.daemon_cpu_us).c_str(),
                cpu_text(f.client_cpu_us).c_str());
    std::fflush(stdout);
}

// The fgsrd next to this executable with `args`, on a socket in a fresh temporary directory.
Result<std::unique_ptr<FgsrdProcess>> start_daemon(const std::vector<std::string>& args) {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path fgsrd = exe.parent_path() / "fgsrd";
    if (ec || access(fgsrd.c_str(), X_OK) != 0)
        return make_error(Errc::io,
                          "no executable fgsrd next to " + exe.string() + " (build it, or pass --socket)");
    auto d = FgsrdProcess::start_at(fgsrd.string(), args, 60000, "fgsr-replay-bench");
    if (!d) return make_error(Errc::io, "cannot start fgsrd: " + FgsrdProcess::last_error());
    return d;
}

} // namespace

Result<std::vector<std::pair<uint32_t, uint32_t>>> parse_bench_sizes(const std::string& text) {
    std::vector<std::pair<uint32_t, uint32_t>> sizes;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t comma = std::min(text.find(',', pos), text.size());
        const std::string item = text.substr(pos, comma - pos);
        unsigned w = 0, h = 0;
        char tail = 0;
        if (std::sscanf(item.c_str(), "%ux%u%c", &w, &h, &tail) != 2 || w < 8 || h < 8 || w > 4096 ||
            h > 4096)
            return make_error(Errc::invalid_argument,
                              "bench size '" + item + "': expected WxH with sides from 8 to 4096");
        sizes.emplace_back(w, h);
        pos = comma + 1;
    }
    return sizes;
}

Result<void> run_replay_bench(const ReplayBenchOptions& o) {
    if (o.frames < 3 || o.runs < 1)
        return make_error(Errc::invalid_argument, "--bench-frames >= 3, --bench-runs >= 1");
    std::unique_ptr<FgsrdProcess> off_daemon, on_daemon;
    std::vector<Config> configs;
    if (o.socket.empty()) {
        auto off = start_daemon({"--spin-us", "0", "--log-level", "warn"});
        if (!off) return off.error();
        auto on = start_daemon({"--spin-us", std::to_string(o.spin_us), "--log-level", "warn"});
        if (!on) return on.error();
        off_daemon = std::move(*off);
        on_daemon = std::move(*on);
        configs = {{"off", 0, off_daemon.get(), off_daemon->socket_path()},
                   {"on", o.spin_us, on_daemon.get(), on_daemon->socket_path()}};
    } else {
        configs = {{"off", 0, nullptr, o.socket}, {"on", o.spin_us, nullptr, o.socket}};
    }
    // The caller's own setting is put back at the end.
    const char* prior = std::getenv("FGSR_WAIT_SPIN_US");
    const std::string prior_value = prior ? prior : "";
    struct Restore {
        bool had;
        std::string value;
        ~Restore() {
            if (had)
                setenv("FGSR_WAIT_SPIN_US", value.c_str(), 1);
            else
                unsetenv("FGSR_WAIT_SPIN_US");
        }
    } restore{prior != nullptr, prior_value};

    std::printf(
        "service overhead, one frame in flight, %d submits a run, %d runs; spin on = fgsrd --spin-us %u "
        "and FGSR_WAIT_SPIN_US=%u%s\n",
        o.frames, o.runs, o.spin_us, o.spin_us,
        o.socket.empty() ? "" : " (client only: the daemon at --socket keeps its own --spin-us)");
    std::printf("%-24s %9s %9s %9s %9s %7s %7s %7s %9s %10s %9s\n", "size spin run", "rtt p50", "rtt p99",
                "ovh p50", "ovh p99", "wake", "handoff", "return", "io cpu", "fgsrd cpu", "wait cpu");
    std::vector<std::pair<std::string, RunFigures>> medians;
    for (const auto& [w, h] : o.sizes) {
        capture::SceneOptions so;
        so.width = w;
        so.height = h;
        so.supersample = 1;
        auto two = capture::make_synthetic_capture(so, 2);
        if (!two) return two.error();
        capture::Capture cap = *two;
        cap.name = fmt::format("bench-{}x{}", w, h);
        cap.inputs.clear();
        for (int i = 0; i < o.frames; ++i) cap.inputs.push_back(two->inputs[size_t(i % 2 == 0 ? 1 : 0)]);
        cap.inputs[0].mv.clear();
        cap.ground_truth.clear();
        cap.ground_truth_kind = capture::GroundTruth::halfway; // no references: nothing scored
        const std::filesystem::path tmp =
            std::filesystem::temp_directory_path() / fmt::format("fgsr-bench-{}-{}x{}", getpid(), w, h);
        auto saved = capture::save_fgsr(cap, tmp);
        struct Remove {
            std::filesystem::path p;
            ~Remove() {
                std::error_code ec;
                std::filesystem::remove_all(p, ec);
            }
        } remove{tmp};
        if (!saved) return saved.error();
        std::vector<RunFigures> per[2];
        for (int run = 0; run < o.runs; ++run) {
            for (int k = 0; k < 2; ++k) {
                const Config& c = configs[size_t(run % 2 == 0 ? k : 1 - k)];
                const int ci = &c == &configs[0] ? 0 : 1;
                setenv("FGSR_WAIT_SPIN_US", std::to_string(c.spin_us).c_str(), 1);
                if (o.progress)
                    std::fprintf(stderr, "[bench] %ux%u spin %s, run %d/%d\n", w, h, c.name, run + 1, o.runs);
                ReplayOptions ro;
                ro.capture = tmp.string();
                ro.mode = EvalMode::interp;
                ro.socket = c.socket;
                ro.progress = false;
                ro.closed_loop = true;
                const DaemonCpu before = daemon_cpu(c.daemon ? c.daemon->pid() : -1);
                auto r = run_replay(ro);
                const DaemonCpu after = daemon_cpu(c.daemon ? c.daemon->pid() : -1);
                if (!r) return r.error();
                const double n = double(std::max<size_t>(1, r->submitted));
                const bool cpu = before.known && after.known;
                RunFigures f{r->latency_p50_ms * 1e3,
                             r->latency_p99_ms * 1e3,
                             r->overhead_p50_ms * 1e3,
                             r->overhead_p99_ms * 1e3,
                             r->wake_p50_us,
                             r->handoff_p50_us,
                             r->return_p50_us,
                             cpu ? double(after.io_ns - before.io_ns) * 1e-3 / n : -1,
                             cpu ? double(after.total_ns - before.total_ns) * 1e-3 / n : -1,
                             double(r->client_wait_cpu_ns) * 1e-3 / n};
                per[ci].push_back(f);
                print_row(fmt::format("{}x{} {} {}", w, h, c.name, run + 1), f);
            }
        }
        for (int ci = 0; ci < 2; ++ci) {
            const auto med = [&](double RunFigures::*m) {
                std::vector<double> v;
                for (const RunFigures& f : per[ci]) v.push_back(f.*m);
                return median(v);
            };
            medians.emplace_back(fmt::format("{}x{} {} median", w, h, configs[size_t(ci)].name),
                                 RunFigures{med(&RunFigures::rtt_p50_us), med(&RunFigures::rtt_p99_us),
                                            med(&RunFigures::ovh_p50_us), med(&RunFigures::ovh_p99_us),
                                            med(&RunFigures::wake_us), med(&RunFigures::handoff_us),
                                            med(&RunFigures::return_us), med(&RunFigures::io_cpu_us),
                                            med(&RunFigures::daemon_cpu_us),
                                            med(&RunFigures::client_cpu_us)});
        }
    }
    std::printf("medians over %d runs:\n", o.runs);
    for (const auto& [label, f] : medians) print_row(label, f);
    std::printf(
        "us. rtt: submit to fgsr_wait returning the output; ovh: rtt minus the daemon's work on it "
        "(telemetry "
        "start_ns..complete_ns), p50/p99 over the run's outputs; its steps (medians): wake = submit to the "
        "daemon reading it, handoff = to the lane starting it, return = completion published to fgsr_wait "
        "returning it. CPU per submit: io = fgsrd's I/O thread, fgsrd = all its threads (engine included), "
        "wait = the client's thread inside fgsr_wait/fgsr_acquire_input.\n");
    return {};
}

} // namespace fgsr::cli
