// `fgsr stress --service`: the reliability scenarios of fgsrd (fgsr/stress/service.hpp), one line
// per scenario on stdout (or a JSON summary with --json), progress on stderr. Without --socket
// each scenario starts the fgsrd next to this executable.
#include <fgsr/cli/stress.hpp>

#include <fgsr/stress/service.hpp>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <unistd.h>

namespace fgsr::cli {

namespace {

nlohmann::json to_json(const stress::ScenarioResult& r) {
    nlohmann::json j;
    j["name"] = r.name;
    j["pass"] = r.pass;
    j["skipped"] = r.skipped;
    j["measured"] = r.measured;
    if (!r.pass) j["failure"] = r.failure;
    j["metrics"] = r.metrics;
    j["seconds"] = r.seconds;
    return j;
}

void print_line(const stress::ScenarioResult& r) {
    const char* tag = r.skipped ? "SKIP" : r.pass ? "PASS" : "FAIL";
    std::printf("%s  %-16s %s (%.1f s)\n", tag, r.name.c_str(), r.measured.c_str(), r.seconds);
    if (!r.pass) std::printf("      FAILED: %s\n", r.failure.c_str());
}

} // namespace

int stress_service_main(const StressCli& o) {
    stress::ServiceOptions so;
    so.quick = o.quick;
    so.heavy_size = o.heavy_size;
    so.max_clients = o.max_clients;
    so.filter = o.filter;
    so.soak_seconds = o.soak;
    so.soak_csv = o.soak_csv;
    if (!o.quiet) so.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    if (o.socket.empty()) {
        std::error_code ec;
        const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        const std::filesystem::path fgsrd = exe.parent_path() / "fgsrd";
        if (ec || access(fgsrd.c_str(), X_OK) != 0) {
            std::fprintf(stderr, "fgsr: no executable fgsrd next to %s (build it, or pass --socket)\n",
                         exe.string().c_str());
            return 1;
        }
        so.fgsrd = fgsrd.string();
    } else {
        so.socket = o.socket;
    }
    // The client library's notes on disconnects would interleave with the report.
    setenv("FGSR_CLIENT_QUIET", "1", 1);

    std::vector<stress::ScenarioResult> results;
    if (o.soak > 0)
        results.push_back(stress::run_service_soak(so));
    else
        results = stress::run_service_scenarios(so);
    size_t passed = 0, failed = 0, skipped = 0;
    double seconds = 0;
    for (const auto& r : results) {
        skipped += r.skipped && r.pass;
        passed += r.pass && !r.skipped;
        failed += !r.pass;
        seconds += r.seconds;
    }
    if (o.json) {
        nlohmann::json j;
        j["target"] = o.socket.empty() ? "own fgsrd per scenario" : o.socket;
        j["quick"] = o.quick;
        j["passed"] = passed;
        j["failed"] = failed;
        j["skipped"] = skipped;
        j["seconds"] = seconds;
        j["scenarios"] = nlohmann::json::array();
        for (const auto& r : results) j["scenarios"].push_back(to_json(r));
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("fgsr stress --service%s (%s)\n",
                    o.soak > 0 ? " --soak"
                    : o.quick  ? " --quick"
                               : "",
                    o.socket.empty() ? "own fgsrd per scenario" : o.socket.c_str());
        for (const auto& r : results) print_line(r);
        std::printf("%zu scenarios: %zu passed, %zu skipped, %zu failed, %.1f s\n", results.size(), passed,
                    skipped, failed, seconds);
    }
    return failed || results.empty() ? 1 : 0;
}

} // namespace fgsr::cli
