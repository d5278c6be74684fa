// `fgsr stress --service`: the reliability scenarios of fgsrd as a service (issue 15), run against
// real daemons from outside: the hostile client, the flag attack on the eventfds, a heavy session
// next to a small one, idle clients, kill -9 of clients at every protocol state, daemon restart
// under clients, and a soak that fits the daemon's fd, mapping and RSS slopes.
//
// Each scenario starts its own fgsrd (ServiceOptions::fgsrd, in a fresh temporary directory, with
// the flags the scenario needs) unless a socket of a running daemon is given; scenarios that must
// kill, restart or configure the daemon are then skipped. Results are values; nothing throws.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fgsr::stress {

struct ServiceOptions {
    std::string fgsrd;        // executable to start for each scenario (empty: use `socket`)
    std::string socket;       // a running daemon's socket (when fgsrd is empty)
    bool quick = false;       // small heavy session and fewer frames: the whole run in about a minute
    uint32_t heavy_size = 0;  // side of the heavy session; 0: 4096 (quick: 1024)
    uint32_t max_clients = 8; // idle clients scenario: the daemon's --max-clients
    std::string filter;       // only scenarios whose name contains this
    double soak_seconds = 0;  // > 0: run the soak instead of the scenarios
    std::string soak_csv;     // samples of the soak (and a PNG next to it when gnuplot runs)
    std::function<void(const std::string&)> progress; // lines for stderr (may be empty)
};

struct ScenarioResult {
    std::string name;
    bool pass = false;
    bool skipped = false;
    std::string measured; // one line: what was measured
    std::string failure;  // why it failed (first failed check)
    nlohmann::json metrics = nlohmann::json::object();
    double seconds = 0;
};

// The scenario names in run order.
std::vector<std::string> service_scenario_names();
// Runs the selected scenarios in order.
std::vector<ScenarioResult> run_service_scenarios(const ServiceOptions& o);
// The soak (needs its own daemon: o.fgsrd).
ScenarioResult run_service_soak(const ServiceOptions& o);

} // namespace fgsr::stress
