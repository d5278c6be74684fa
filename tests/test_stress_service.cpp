// `fgsr stress --service --quick --json` end to end (the binary, as a person runs it): it exits 0,
// and its JSON report has every reliability scenario of issue 15, each run (not skipped) and passed,
// with the figures the issue asks for.
#include "run_process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <map>

namespace fgsr::test {
namespace {

TEST(StressService, QuickRunPassesEveryScenario) {
    const auto t0 = std::chrono::steady_clock::now();
    const ProcessRun run =
        run_process(std::string(FGSR_BIN_DIR) + "/fgsr stress --service --quick --json --quiet");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(run.status, 0) << run.out;
    const nlohmann::json j = nlohmann::json::parse(run.out, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << run.out;
    std::map<std::string, nlohmann::json> by_name;
    for (const auto& s : j.at("scenarios")) by_name[s.at("name").get<std::string>()] = s;
    for (const char* name : {"hostile-client", "flag-attack", "heavy-session", "idle-clients",
                             "kill-9-clients", "daemon-restart"}) {
        ASSERT_TRUE(by_name.count(name)) << name << " missing:\n" << run.out;
        const nlohmann::json& s = by_name[name];
        EXPECT_TRUE(s.at("pass").get<bool>()) << name << ": " << s.value("failure", "");
        EXPECT_FALSE(s.at("skipped").get<bool>()) << name;
    }
    EXPECT_EQ(j.at("failed").get<int>(), 0);
    // Every hostile attack was refused (an error or a disconnect), the flipping one included.
    const nlohmann::json& attacks = by_name["hostile-client"]["metrics"]["attacks"];
    EXPECT_GE(attacks.size(), 13u);
    for (const auto& [attack, event] : attacks.items())
        EXPECT_TRUE(event.get<std::string>().rfind("error", 0) == 0 || event == "closed")
            << attack << ": " << event;
    // The quick run's gates are loose (the suite runs it beside other tests on 2 cores); the
    // issue's targets (p99 ratio <= 2, HELLO <= 100 ms) are the full run's, reported in
    // docs/RELIABILITY.md.
    const nlohmann::json& heavy = by_name["heavy-session"]["metrics"];
    EXPECT_LE(heavy.at("p99_ratio").get<double>(), 20.0);
    EXPECT_LE(heavy.at("hello_max_ms").get<double>(), 1000.0);
    EXPECT_GT(heavy.at("small_frames_with_heavy").get<int>(), 0);
    const nlohmann::json& kill = by_name["kill-9-clients"]["metrics"];
    EXPECT_EQ(kill.at("states").size(), 5u);
    for (const auto& [state, m] : kill.at("states").items()) {
        EXPECT_EQ(m.at("fds_after"), kill.at("baseline").at("fds")) << state;
        EXPECT_EQ(m.at("maps_after"), kill.at("baseline").at("maps")) << state;
    }
    for (const auto& c : by_name["daemon-restart"]["metrics"]["clients"]) {
        EXPECT_TRUE(c.at("reconnected").get<bool>());
        EXPECT_GE(c.at("error_after_kill_ms").get<double>(), 0.0);
    }
    std::printf("[ measured ] fgsr stress --service --quick: %.1f s\n", seconds);
}

} // namespace
} // namespace fgsr::test
