// `fgsr stress`: the numerical stress cases (fgsr/capture/stress.hpp) fed to the engine, with a
// report of every case (PASS/FAIL, what was checked, the stated reasons of rejected inputs, the
// drift of the long SR run). Exit status 1 when any case fails. --daemon feeds the same cases
// through fgsrd (its own or --socket's).
#pragma once

#include <fgsr/capture/stress.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace fgsr::cli {

struct StressCli {
    size_t sr_frames = 1000; // the full run: 100000
    bool json = false;
    bool quiet = false;
    bool reduced = false; // the test suite's case sizes (no 1920x1080 frame)
    std::string device;
    std::string filter;  // run only cases whose name contains this
    bool daemon = false; // feed the cases through fgsrd (tools/fgsr/src/stress_daemon.cpp)
    std::string socket;  // with daemon: an fgsrd already listening; empty: spawn one next to fgsr
    // --service: the reliability scenarios of fgsrd (fgsr/stress/service.hpp;
    // tools/fgsr/src/stress_service.cpp).
    bool service = false;
    bool quick = false;       // about a minute: small heavy session, fewer frames and kills
    uint32_t heavy_size = 0;  // 0: 4096 (quick: 1024)
    uint32_t max_clients = 8; // idle-clients scenario
    double soak = 0;          // seconds; > 0: the soak instead of the scenarios
    std::string soak_csv;
};

CLI::App* add_stress_command(CLI::App& app, StressCli& o);
int stress_main(const StressCli& o);
// The --daemon run: the cases fed through fgsrd with libfgsr_client; exit status as stress_main.
int stress_daemon_main(const StressCli& o);
// The --service run: exit status 1 when any scenario (or the soak) fails.
int stress_service_main(const StressCli& o);
// Runs the cases selected by `o` with `run`, stopping early when `stop` (may be empty) says so
// after a case, and prints the report (`title` first; `header` holds the JSON report's fields
// naming the target). Returns 1 when any selected case failed or did not run, else 0.
int run_and_report(
    const StressCli& o, const std::string& title, nlohmann::json header,
    const std::function<stress::CaseResult(const stress::Case&, const stress::RunOptions&)>& run,
    const std::function<bool()>& stop = {});

} // namespace fgsr::cli
