// Shared pieces of the service scenarios (tools/stress/src/service_*.cpp); not installed.
#pragma once

#include <fgsr/stress/raw_client.hpp>
#include <fgsr/stress/service.hpp>
#include <fgsr/testing/fgsrd_process.hpp>

#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

namespace fgsr::stress::service {

using daemon_process::FgsrdProcess;

// The targets: a fresh HELLO within 100 ms, a small client's p99 with a heavy session
// running within 2x of its p99 alone. --quick is the test suite's smoke run, on a machine busy
// with other tests: it gates only what no load explains (10x the targets) and reports the figures.
inline double hello_limit_ms(const ServiceOptions& o) {
    return o.quick ? 1000.0 : 100.0;
}
inline double p99_ratio_limit(const ServiceOptions& o) {
    return o.quick ? 20.0 : 2.0;
}

// A scenario in progress: its result, the checks, and the daemon it runs against.
class Run {
  public:
    Run(const ServiceOptions& o, std::string name) : opt(o) { result.name = std::move(name); }
    const ServiceOptions& opt;
    ScenarioResult result;
    std::unique_ptr<FgsrdProcess> daemon; // null when the scenario uses opt.socket

    bool own_daemon_possible() const { return !opt.fgsrd.empty(); }
    // Starts the scenario's daemon with `args` (or takes opt.socket); false and a failure if not.
    bool start(const std::vector<std::string>& args = {});
    const std::string& socket() const { return daemon ? daemon->socket_path() : opt.socket; }
    // Records a failed check (the first one is the scenario's failure); returns ok.
    bool check(bool ok, const std::string& what);
    void note(const std::string& line) const {
        if (opt.progress) opt.progress("  " + result.name + ": " + line);
    }
    void skip(const std::string& why) {
        result.skipped = true;
        result.measured = "skipped: " + why;
    }
    // The daemon is alive (own daemon) and serves: a fresh HELLO within hello_limit_ms() (the worst of
    // a few tries is reported), and a well-behaved libfgsr_client session completes frames.
    bool served(const std::string& after);
    // The daemon's stderr (own daemon), or "".
    std::string log() const { return daemon ? daemon->stderr_text() : std::string(); }
    int failures = 0;
};

// A well-behaved client with libfgsr_client: connect, a w x h session, `frames` frames each with
// one interpolated output, destroy, disconnect. "" when every frame completed OK, else why.
std::string library_frames(const std::string& socket, uint32_t w, uint32_t h, uint32_t frames);

// Percentile (0..100) of values (copied and sorted); 0 for none.
double percentile(std::vector<double> v, double p);
double max_of(const std::vector<double>& v);

// The scenarios (service_hostile.cpp, service_load.cpp, service_lifecycle.cpp).
void hostile_client(Run& r);
void flag_attack(Run& r);
void heavy_session(Run& r);
void idle_clients(Run& r);
void kill_nine_clients(Run& r);
void daemon_restart(Run& r);

} // namespace fgsr::stress::service
