#include <fgsr/cli/stress.hpp>

#include <fgsr/capture/stress.hpp>
#include <fgsr/engine/engine.hpp>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>

namespace fgsr::cli {

CLI::App* add_stress_command(CLI::App& app, StressCli& o) {
    auto* cmd = app.add_subcommand(
        "stress", "Numerical stress cases (non-finite and extreme inputs, sizes, rejections, long SR drift) "
                  "fed to the engine or, with --daemon, to fgsrd; exit status 1 on any failure");
    cmd->add_option("--sr-frames", o.sr_frames,
                    "Frames of the long SR run on a looped static capture (full run: 100000)")
        ->check(CLI::Range(size_t(1), size_t(100000000)))
        ->capture_default_str();
    cmd->add_flag("--json", o.json, "Print one JSON object on stdout");
    cmd->add_option(
        "--device", o.device,
        "Vulkan device index or name substring (default: FGSR_DEVICE, else first GPU, else lavapipe)");
    cmd->add_option("--filter", o.filter, "Run only the cases whose name contains this text");
    cmd->add_flag("--reduced", o.reduced, "The test suite's sizes (no 1920x1080 frame)");
    cmd->add_flag("--quiet", o.quiet, "No progress on stderr");
    cmd->add_flag("--daemon", o.daemon,
                  "Feed the cases through fgsrd with libfgsr_client (spawns build/bin/fgsrd on a temporary "
                  "socket unless --socket is given)");
    cmd->add_option(
        "--socket", o.socket,
        "With --daemon or --service: the socket of an fgsrd already running (--service then skips "
        "the scenarios that kill, restart or configure the daemon)");
    cmd->add_flag(
        "--service", o.service,
        "Reliability scenarios of fgsrd as a service (issue 15): hostile client, flag attack, heavy "
        "session, idle clients, kill -9 of clients, daemon restart; each starts its own fgsrd next to "
        "this executable");
    cmd->add_flag("--quick", o.quick,
                  "With --service: the short run of the test suite (about a minute; heavy session "
                  "1024x1024; timing gates at 10x the targets, figures reported)");
    cmd->add_option("--heavy-size", o.heavy_size,
                    "With --service: side of the heavy session (default 4096, "
                    "--quick 1024)")
        ->check(CLI::Range(64u, 16384u));
    cmd->add_option("--max-clients", o.max_clients,
                    "With --service: idle connections of the idle-clients scenario")
        ->check(CLI::Range(1u, 256u))
        ->capture_default_str();
    cmd->add_option(
           "--soak", o.soak,
           "With --service: run the soak for this many seconds instead of the scenarios (short sessions "
           "back to back; fd, mapping and RSS slopes of the daemon)")
        ->check(CLI::Range(1.0, 7.0 * 86400.0));
    cmd->add_option("--soak-csv", o.soak_csv,
                    "With --soak: write the samples here (and a PNG plot next to it)");
    return cmd;
}

int stress_main(const StressCli& o) {
    if (o.service || o.soak > 0) return stress_service_main(o);
    if (o.daemon || !o.socket.empty()) return stress_daemon_main(o);
    DeviceOptions d;
    d.device = o.device;
    auto engine = Engine::create(d);
    if (!engine) {
        std::fprintf(stderr, "fgsr: %s: %s\n", errc_name(engine.error().code),
                     engine.error().message.c_str());
        return 1;
    }
    nlohmann::json header;
    header["device"] = (*engine)->device_name();
    return run_and_report(o, "fgsr stress on " + (*engine)->device_name(), header,
                          [&](const stress::Case& c, const stress::RunOptions& ro) {
                              return stress::run_on_engine(**engine, c, ro);
                          });
}

int run_and_report(
    const StressCli& o, const std::string& title, nlohmann::json header,
    const std::function<stress::CaseResult(const stress::Case&, const stress::RunOptions&)>& run,
    const std::function<bool()>& stop) {
    stress::CaseOptions co;
    co.sr_frames = o.sr_frames;
    co.reduced = o.reduced;
    std::vector<stress::Case> cases = stress::make_cases(co);
    stress::RunOptions ro;
    if (!o.quiet) ro.progress = [](const std::string& line) { std::fprintf(stderr, "  %s\n", line.c_str()); };

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<stress::CaseResult> results;
    size_t selected = 0;
    for (const stress::Case& c : cases) selected += c.name.find(o.filter) != std::string::npos;
    for (const stress::Case& c : cases) {
        if (c.name.find(o.filter) == std::string::npos) continue;
        if (!o.quiet) std::fprintf(stderr, "[%zu/%zu] %s\n", results.size() + 1, selected, c.name.c_str());
        results.push_back(run(c, ro));
        if (!o.quiet && !results.back().pass)
            std::fprintf(stderr, "  FAIL: %s\n", results.back().failure.c_str());
        if (stop && stop()) break;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    size_t passed = 0, failed = 0, na = 0;
    for (const auto& r : results) {
        failed += r.pass ? 0 : 1;
        na += r.pass && !r.applicable ? 1 : 0;
        passed += r.pass && r.applicable ? 1 : 0;
    }
    failed += selected - results.size(); // not run: the run stopped early

    if (o.json) {
        nlohmann::json& j = header;
        j["sr_frames"] = o.sr_frames;
        j["passed"] = passed;
        j["not_applicable"] = na;
        j["failed"] = failed;
        j["seconds"] = seconds;
        j["cases"] = nlohmann::json::array();
        for (const auto& r : results) {
            nlohmann::json c;
            c["name"] = r.name;
            c["pass"] = r.pass;
            c["applicable"] = r.applicable;
            c["checks"] = r.checks;
            if (!r.pass) c["failure"] = r.failure;
            c["rejections"] = r.rejections;
            c["not_applicable_steps"] = r.not_applicable;
            c["steps"] = r.steps_run;
            c["outputs_checked"] = r.outputs_checked;
            c["values_checked"] = r.values_checked;
            if (r.drift_db) c["drift_db"] = *r.drift_db;
            if (r.max_cpu_difference) c["max_cpu_difference"] = *r.max_cpu_difference;
            c["seconds"] = r.seconds;
            j["cases"].push_back(std::move(c));
        }
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("%s\n", title.c_str());
        for (const auto& r : results) {
            const char* tag = !r.pass ? "FAIL" : r.applicable ? "PASS" : "N/A ";
            std::printf("%s  %-40s %s", tag, r.name.c_str(), r.checks.c_str());
            if (r.drift_db) std::printf(" [drift: %.2f dB]", *r.drift_db);
            if (r.max_cpu_difference) std::printf(" [GPU-CPU: %.2g]", *r.max_cpu_difference);
            if (r.applicable)
                std::printf(" (%zu outputs, %llu values finite, %.2f s)\n", r.outputs_checked,
                            static_cast<unsigned long long>(r.values_checked), r.seconds);
            else
                std::printf("\n");
            for (const auto& why : r.rejections) std::printf("        rejected: %s\n", why.c_str());
            for (const auto& why : r.not_applicable) std::printf("        n/a here: %s\n", why.c_str());
            if (!r.pass) std::printf("        FAILED: %s\n", r.failure.c_str());
        }
        std::printf("%zu cases: %zu passed, %zu n/a, %zu failed, %.1f s\n", selected, passed, na, failed,
                    seconds);
    }
    return failed ? 1 : 0;
}

} // namespace fgsr::cli
