// End to end: vkcube and fgsr_layer_app under Xvfb (lavapipe) with VK_LAYER_FGSR_frame_generation
// (build/share in XDG_DATA_DIRS, enabled by FGSR_ENABLE=1) and a real fgsrd. Each test reads the
// layer's stats file (FGSR_LAYER_STATS) and the application's output. Skipped only when Xvfb or
// vkcube is not installed.
#include <fgsr/core/clock.hpp>
#include <fgsr/core/presentmon.hpp>
#include <fgsr/testing/fgsrd_process.hpp>

#include <httplib.h>
#include <cstring>

#include <fcntl.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace {

using fgsr::test::FgsrdProcess;

bool have(const char* program) {
    return std::system((std::string("command -v ") + program + " >/dev/null 2>&1").c_str()) == 0;
}

std::string read_file(const std::string& path) {
    std::ifstream f(path);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// A number field of a flat JSON object (-1 when absent).
double json_number(const std::string& j, const std::string& key) {
    const size_t p = j.find("\"" + key + "\":");
    if (p == std::string::npos) return -1;
    return std::strtod(j.c_str() + p + key.size() + 3, nullptr);
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

// An Xvfb on a display it picks itself (-displayfd), killed with the object.
class Xvfb {
  public:
    bool start() {
        int fds[2];
        if (pipe(fds) != 0) return false;
        pid_ = fork();
        if (pid_ == 0) {
            close(fds[0]);
            const std::string fd = std::to_string(fds[1]);
            const int devnull = open("/dev/null", O_WRONLY);
            dup2(devnull, 1);
            dup2(devnull, 2);
            execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1920x1080x24", "-nolisten",
                   "tcp", static_cast<char*>(nullptr));
            _exit(127);
        }
        close(fds[1]);
        char buf[32] = {};
        ssize_t n = 0, got;
        while (n < 31 && (got = read(fds[0], buf + n, size_t(31 - n))) > 0) {
            n += got;
            if (std::memchr(buf, '\n', size_t(n))) break;
        }
        close(fds[0]);
        if (n <= 0) return false;
        display_ = ":" + std::string(buf, size_t(n - (buf[n - 1] == '\n' ? 1 : 0)));
        return true;
    }
    ~Xvfb() {
        if (pid_ > 0) {
            kill(pid_, SIGTERM);
            waitpid(pid_, nullptr, 0);
        }
    }
    const std::string& display() const { return display_; }

  private:
    pid_t pid_ = -1;
    std::string display_;
};

// All CPUs' time in /proc/stat's first line, and the part of it the hypervisor ran other guests in
// (steal time), in clock ticks. Both 0 when the line is not there.
struct CpuTimes {
    double steal = 0, total = 0;
};

// "cpu  user nice system idle iowait irq softirq steal guest guest_nice": guest and guest_nice are
// already counted in user and nice, so the total is the first eight.
CpuTimes parse_cpu_times(const std::string& proc_stat) {
    CpuTimes t;
    if (proc_stat.rfind("cpu ", 0) != 0) return t;
    std::istringstream line(proc_stat.substr(4, proc_stat.find('\n') - 4));
    double v = 0;
    for (int i = 0; i < 8 && line >> v; ++i) {
        t.total += v;
        if (i == 7) t.steal = v;
    }
    return t;
}

CpuTimes cpu_times() {
    return parse_cpu_times(read_file("/proc/stat"));
}

// The fraction of the CPU time between two readings that the host gave to others.
double steal_fraction(const CpuTimes& before, const CpuTimes& after) {
    const double total = after.total - before.total;
    return total > 0 ? (after.steal - before.steal) / total : 0;
}

// Above this much steal over a run, a run counted to 2 % says more about the host than about fgsr.
constexpr double kHeavySteal = 0.10;

struct AppRun {
    int status = -1;  // the wait status
    std::string json; // the application's JSON line (fgsr_layer_app), if any
    std::string log;  // stdout + stderr
    std::string stats;
    double steal = 0;      // steal_fraction over the run
    std::string contended; // why the test cannot judge its timing, when every run had heavy steal
};

// Empty when presents are within 2 % of app_presents * multiplier, else what missed.
std::string multiplied_miss(const AppRun& r, double multiplier, double frames) {
    const double presents = json_number(r.stats, "presents");
    if (json_number(r.stats, "app_presents") == frames &&
        std::fabs(presents - frames * multiplier) <= 0.02 * frames * multiplier)
        return {};
    char what[96];
    std::snprintf(what, sizeof what, "%.0f application presents, %.0f presents of %.0f",
                  json_number(r.stats, "app_presents"), presents, frames * multiplier);
    return what;
}

class LayerE2E : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!have("Xvfb")) GTEST_SKIP() << "Xvfb is not installed (tools/setup.sh installs xvfb)";
        ASSERT_TRUE(x_.start()) << "Xvfb did not start";
        dir_ = std::filesystem::temp_directory_path() /
               ("fgsr-layer-" + std::to_string(getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        if (!HasFailure()) std::filesystem::remove_all(dir_, ec);
    }

    // With --warm-up, as the systemd unit starts it: on a cold shader cache, llvmpipe compiling
    // the colour-only pipelines at the first frames would drop the first seconds' generated frames.
    void start_daemon(const std::vector<std::string>& extra = {}) {
        std::vector<std::string> args = {"--log-level", "info", "--warm-up"};
        args.insert(args.end(), extra.begin(), extra.end());
        daemon_ = FgsrdProcess::start(args);
        ASSERT_TRUE(daemon_) << FgsrdProcess::last_error();
    }
    // fgsrd's /metrics (started with --http 127.0.0.1:0: the URL is in its log).
    std::string daemon_metrics() {
        const std::string log = daemon_->stderr_text();
        const size_t at = log.find("dashboard at http://127.0.0.1:");
        if (at == std::string::npos) return {};
        const int port = std::atoi(log.c_str() + at + std::strlen("dashboard at http://127.0.0.1:"));
        httplib::Client c("127.0.0.1", port);
        auto r = c.Get("/metrics");
        return r && r->status == 200 ? r->body : std::string();
    }

    // Runs `command` with the layer enabled (plus `env`, "NAME=value" words) on the test's display.
    AppRun run(const std::string& command, const std::vector<std::string>& env = {}, bool validation = true) {
        const std::string stats = (dir_ / "stats.json").string();
        std::string line =
            "env DISPLAY=" + x_.display() +
            " XDG_DATA_DIRS=" FGSR_LAYER_SHARE_DIR ":/usr/local/share:/usr/share" +
            " FGSR_ENABLE=1 FGSR_LAYER_STATS=" + stats + " FGSR_CONFIG=" + (dir_ / "none.toml").string() +
            " FGSR_SOCKET=" + (daemon_ ? daemon_->socket_path() : (dir_ / "absent.sock").string());
        if (validation) line += " VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation";
        for (const std::string& e : env) line += " " + e;
        line += " " + command + " > " + (dir_ / "out.log").string() + " 2>&1";
        AppRun r;
        std::filesystem::remove(stats);
        const CpuTimes before = cpu_times();
        r.status = std::system(line.c_str());
        r.steal = steal_fraction(before, cpu_times());
        r.log = read_file((dir_ / "out.log").string());
        r.stats = read_file(stats);
        std::istringstream lines(r.log);
        for (std::string l; std::getline(lines, l);)
            if (l.rfind("{\"frames\"", 0) == 0) r.json = l;
        std::printf("[ layer    ] %s\n[ stats    ] %s", command.c_str(), r.stats.c_str());
        if (!r.json.empty()) std::printf("[ app      ] %s\n", r.json.c_str());
        std::printf("[ steal    ] %.1f %% of the CPU time went to the host's other guests\n", 100 * r.steal);
        return r;
    }

    // A run that expect_multiplied counts. How many generated frames reach the screen in time depends
    // on the CPU time the processes get: on a virtual machine whose host takes much of it (steal
    // above kHeavySteal), a run misses the 2 % bound with nothing wrong in fgsr (seen at 44 % steal).
    // Such a run is repeated, three runs at most. A miss with less steal is returned to fail; when
    // every run missed under heavy steal, `contended` says so and the test skips.
    AppRun run_multiplied(const std::string& command, const std::vector<std::string>& env, bool validation,
                          double multiplier, double frames) {
        std::string misses;
        for (int attempt = 1;; ++attempt) {
            AppRun r = run(command, env, validation);
            const std::string miss = r.status == 0 ? multiplied_miss(r, multiplier, frames) : std::string();
            if (miss.empty() || r.steal < kHeavySteal) return r;
            char line[160];
            std::snprintf(line, sizeof line, "run %d: %s at %.0f %% steal; ", attempt, miss.c_str(),
                          100 * r.steal);
            std::printf("[ steal    ] %s\n", line);
            misses += line;
            if (attempt == 3) {
                r.contended = "the host took too much of the CPU time to judge the timing: " + misses;
                return r;
            }
        }
    }

    static std::string app() { return FGSR_LAYER_APP; }

    Xvfb x_;
    std::filesystem::path dir_;
    std::unique_ptr<FgsrdProcess> daemon_;
};

// Every application frame presented, presents within 2 % of app_presents * multiplier (the bound of
// multiplied_miss, which run_multiplied retries on), and each present either the application's or
// a generated one.
void expect_multiplied(const AppRun& r, double multiplier, double frames) {
    EXPECT_EQ(multiplied_miss(r, multiplier, frames), "") << r.stats << r.log;
    EXPECT_EQ(json_number(r.stats, "presents"), frames + json_number(r.stats, "generated")) << r.stats;
}

struct PresentRow {
    bool real;
    uint64_t app_present, app_ns, intended_ns, actual_ns;
};

// FGSR_LAYER_PRESENTS: PresentMon's columns (report.hpp).
std::vector<PresentRow> read_presents(const std::string& path) {
    std::vector<PresentRow> rows;
    auto parsed = fgsr::parse_presentmon_csv(read_file(path));
    EXPECT_TRUE(parsed) << (parsed ? "" : parsed.error().message);
    if (!parsed) return rows;
    for (const fgsr::PresentRow& p : *parsed) {
        const auto ns = [](double s) { return uint64_t(std::llround(s * 1e9)); };
        const uint64_t actual = ns(p.time_s);
        rows.push_back({p.frame_type == "Application", p.sequence, actual - uint64_t(std::llround(p.ms_until_displayed * 1e6)),
                        ns(p.intended_s), actual});
    }
    return rows;
}

// Generated frames of `rows` that reached the screen strictly between two CLOCK_MONOTONIC times.
int generated_between(const std::vector<PresentRow>& rows, uint64_t from_ns, uint64_t to_ns) {
    int n = 0;
    for (const PresentRow& p : rows) n += !p.real && p.actual_ns > from_ns && p.actual_ns < to_ns;
    return n;
}

// Where generated frames fall between the real presents around them: for each generated frame j
// (1-based within its gap) of a gap between two real presents, |fraction - j / m|; their median.
double median_pacing_error(const std::vector<PresentRow>& rows, double m) {
    std::vector<double> errors;
    for (size_t i = 0; i < rows.size(); ++i) {
        if (!rows[i].real) continue;
        size_t k = i + 1;
        while (k < rows.size() && !rows[k].real) ++k;
        if (k >= rows.size() || k == i + 1) continue;
        const double span = double(rows[k].actual_ns) - double(rows[i].actual_ns);
        for (size_t g = i + 1; g < k; ++g)
            errors.push_back(std::fabs((double(rows[g].actual_ns) - double(rows[i].actual_ns)) / span -
                                       double(g - i) / m));
    }
    if (errors.empty()) return 1.0;
    std::sort(errors.begin(), errors.end());
    return errors[errors.size() / 2];
}

} // namespace

TEST_F(LayerE2E, VkcubePresentsDoubleWithValidationClean) {
    if (!have("vkcube")) GTEST_SKIP() << "vkcube is not installed (tools/setup.sh installs vulkan-tools)";
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP()
        << "vkcube is not built with this build's sanitizer, so this build's layer cannot load into it";
#endif
    start_daemon();
    // 80 frames: 160 presents within 2 % leaves room for the first frame (no predecessor) and 2 more.
    // 128x128 at 8 fps: fgsrd (motion estimation included) keeps up on two cores shared with other
    // work (the CI machine's load reaches 8).
    const AppRun r = run_multiplied("vkcube --c 80 --width 128 --height 128",
                                    {"FGSR_FPS_LIMIT=8", "FGSR_MULTIPLIER=2"}, true, 2, 80);
    if (!r.contended.empty()) GTEST_SKIP() << r.contended;
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    EXPECT_NE(r.log.find("connected to fgsrd"), std::string::npos) << r.log;
    expect_multiplied(r, 2, 80);
}

// A labelled sample of a Prometheus text body (-1 when absent).
double metric(const std::string& text, const std::string& sample) {
    const size_t p = text.find("\n" + sample + " ");
    return p == std::string::npos ? -1 : std::strtod(text.c_str() + p + sample.size() + 2, nullptr);
}

TEST_F(LayerE2E, AppInterpolatesThreeTimesWithValidationClean) {
    start_daemon({"--http", "127.0.0.1:0"});
    const std::string presents = (dir_ / "presents.csv").string();
    const AppRun r = run_multiplied(app() + " --frames 75 --width 128 --height 72 --fps 8",
                                    {"FGSR_MULTIPLIER=3", "FGSR_LAYER_PRESENTS=" + presents}, true, 3, 75);
    if (!r.contended.empty()) GTEST_SKIP() << r.contended;
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    EXPECT_NE(r.stats.find("\"mode\": \"interpolate\""), std::string::npos);
    expect_multiplied(r, 3, 75);
    // Paced: the two generated frames of a gap at about 1/3 and 2/3 of it, and before the real
    // frame they were made with (interpolation).
    const std::vector<PresentRow> rows = read_presents(presents);
    ASSERT_EQ(rows.size(), size_t(json_number(r.stats, "presents")));
    const double error = median_pacing_error(rows, 3);
    std::printf("[ pacing   ] median |position - j/m| of generated frames: %.3f of the gap\n", error);
    EXPECT_LT(error, 0.15);
    for (size_t i = 0; i + 1 < rows.size(); ++i)
        if (!rows[i].real) {
            EXPECT_EQ(rows[i].app_present, rows[i + 1].app_present) << "row " << i;
        }
    // The layer's present records reached fgsrd's telemetry: its own frames and the generated
    // ones, as the layer counted them (the last batch, at most 16 reports, may be cut by the exit).
    const std::string m = daemon_metrics();
    ASSERT_FALSE(m.empty()) << daemon_->stderr_text();
    const double app = metric(m, "fgsr_presents_total{type=\"application\"}");
    const double gen = metric(m, "fgsr_presents_total{type=\"interpolated\"}");
    EXPECT_LE(app, 75);
    EXPECT_GE(app, 75 - 16) << m;
    EXPECT_LE(gen, json_number(r.stats, "generated"));
    EXPECT_GE(gen, json_number(r.stats, "generated") - 16) << m;
    EXPECT_EQ(metric(m, "fgsr_reports_invalid_total"), 0) << m;
    EXPECT_GT(metric(m, "fgsr_latency_seconds_count{kind=\"displayed\"}"), 0) << m;
}

// VK_KHR_present_wait, where the driver has it (here emulated by a test layer below the fgsr layer,
// tests/layer_app/present_wait_emulation.cpp, which declares each present displayed 15 ms after
// its call returned): the layer enables it, and the time of each present becomes its display time.
TEST_F(LayerE2E, PresentWaitGivesDisplayTimes) {
    start_daemon();
    const std::string presents = (dir_ / "presents.csv").string();
    const AppRun r = run(app() + " --frames 40 --width 128 --height 72 --fps 8",
                         {"FGSR_MULTIPLIER=2", "FGSR_LAYER_PRESENTS=" + presents,
                          "VK_ADD_LAYER_PATH=" FGSR_TEST_LAYER_DIR,
                          "VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation:VK_LAYER_FGSR_test_present_wait",
                          "FGSR_TEST_DISPLAY_DELAY_MS=15"});
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    EXPECT_NE(r.stats.find("\"present_wait\": true"), std::string::npos) << r.stats << r.log;
    const double total = json_number(r.stats, "presents");
    const double displayed = json_number(r.stats, "displayed_by_present_wait");
    EXPECT_GE(displayed, 0.9 * total) << r.stats; // the last presents may end with the swapchain
    auto parsed = fgsr::parse_presentmon_csv(read_file(presents));
    ASSERT_TRUE(parsed) << parsed.error().message;
    ASSERT_EQ(parsed->size(), size_t(total));
    std::vector<double> after_call; // display time minus the present call's return, ms
    for (const fgsr::PresentRow& p : *parsed) after_call.push_back((p.time_s - p.call_s) * 1e3);
    std::sort(after_call.begin(), after_call.end());
    const double median = after_call[after_call.size() / 2];
    std::printf("[ present  ] display time after the present call: median %.2f ms (emulated delay 15 ms)\n",
                median);
    // Displayed when the driver said, found within a few polls of it. The driver's 15 ms count from
    // its own return, which the layer's clock reads a little later: a present preempted in between
    // (a loaded machine) shows less than 15, so the median is held to 14.5, not 15.
    EXPECT_GE(median, 14.5);
    EXPECT_LT(median, 15.0 + 10.0);
    // A fallback's display time is its call time (0 ms after it); a present the driver timed is
    // 15 ms after its call less that preemption, which is never half of it.
    size_t at_call = 0;
    for (double d : after_call) at_call += d < 7.5 ? 1 : 0;
    EXPECT_LE(double(at_call), total - displayed) << "only fallbacks carry their call time";
}

TEST_F(LayerE2E, WithoutPresentWaitTimesAreThePresentCalls) {
    start_daemon();
    const std::string presents = (dir_ / "presents.csv").string();
    const AppRun r = run(app() + " --frames 12 --width 128 --height 72 --fps 10",
                         {"FGSR_MULTIPLIER=2", "FGSR_LAYER_PRESENTS=" + presents});
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_NE(r.stats.find("\"present_wait\": false"), std::string::npos) << r.stats; // lavapipe has none
    auto parsed = fgsr::parse_presentmon_csv(read_file(presents));
    ASSERT_TRUE(parsed) << parsed.error().message;
    ASSERT_FALSE(parsed->empty());
    for (const fgsr::PresentRow& p : *parsed) EXPECT_NEAR(p.time_s, p.call_s, 1e-6);
}

TEST_F(LayerE2E, AppExtrapolatesWithValidationClean) {
    start_daemon();
    const std::string presents = (dir_ / "presents.csv").string();
    // With the fast motion estimation (FGSR_MOTION=fast: session flag FGSR_SESSION_FAST_MOTION).
    const AppRun r = run_multiplied(
        app() + " --frames 75 --width 128 --height 72 --fps 8",
        {"FGSR_MODE=extrapolate", "FGSR_MOTION=fast", "FGSR_LAYER_PRESENTS=" + presents}, true, 2, 75);
    if (!r.contended.empty()) GTEST_SKIP() << r.contended;
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    EXPECT_NE(r.stats.find("\"mode\": \"extrapolate\""), std::string::npos);
    EXPECT_NE(r.stats.find("\"motion\": \"fast\""), std::string::npos) << r.stats;
    EXPECT_NE(daemon_->stderr_text().find("colour only, fast motion)"), std::string::npos)
        << daemon_->stderr_text();
    expect_multiplied(r, 2, 75);
    // Generated frames follow the real frame they were made from, about halfway to the next one.
    const std::vector<PresentRow> rows = read_presents(presents);
    ASSERT_FALSE(rows.empty());
    for (size_t i = 1; i < rows.size(); ++i)
        if (!rows[i].real) {
            EXPECT_EQ(rows[i].app_present, rows[i - 1].app_present) << "row " << i;
        }
    const double error = median_pacing_error(rows, 2);
    std::printf("[ pacing   ] median |position - j/m| of generated frames: %.3f of the gap\n", error);
    EXPECT_LT(error, 0.15);
}

TEST_F(LayerE2E, NoDaemonTheAppKeepsAllItsFrames) {
    const AppRun r = run(app() + " --frames 30 --width 192 --height 108 --fps 30");
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 30);
    EXPECT_EQ(json_number(r.stats, "presents"), 30);
    EXPECT_EQ(json_number(r.stats, "generated"), 0);
    EXPECT_EQ(count(r.log, "no fgsrd"), 1u) << r.log; // one line, however many retries
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
}

TEST_F(LayerE2E, DaemonKilledMidRunTheAppKeepsAllItsFrames) {
    start_daemon();
    // Killed about 2 s (some 20 application frames at 10 fps) after the layer's session opened,
    // not at a fixed time from the start, which under load may come before the application
    // connects. (This test's failures under load were the client library's: with every input slot
    // in flight at the kill, the layer's zero-timeout calls never reported the hang-up;
    // ClientService.ZeroTimeoutCallsSeeADaemonThatDiedWithEverySlotHeld.)
    // The layer learns of the death when the kernel closes the daemon's sockets, and Linux unmaps a
    // killed process's memory before it closes its files: an ASan fgsrd on a loaded machine took
    // 3-4 s for that (the hang-up came after the application's last frame, and the test failed
    // with no "went away"). So the application runs 9 s, leaving 6 s or more after the kill.
    uint64_t killed_ns = 0; // CLOCK_MONOTONIC, the clock of the layer's present log
    std::thread killer([&] {
        const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
        // fgsrd logs "client N (name): session S WxH xM on the <lane> lane (...)" when it opens one.
        while (daemon_->stderr_text().find(" lane (") == std::string::npos &&
               std::chrono::steady_clock::now() < give_up)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        std::this_thread::sleep_for(std::chrono::milliseconds(2000));
        killed_ns = fgsr::monotonic_ns();
        daemon_->kill9();
    });
    const std::string presents = (dir_ / "presents.csv").string();
    const AppRun r =
        run(app() + " --frames 90 --width 192 --height 108 --fps 10", {"FGSR_LAYER_PRESENTS=" + presents});
    killer.join();
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 90);
    const double generated = json_number(r.stats, "generated");
    EXPECT_EQ(json_number(r.stats, "presents"), 90 + generated);
    EXPECT_EQ(count(r.log, "fgsrd went away"), 1u) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    // Generated frames before the kill, none after it (half a second after, for one the daemon
    // finished just before).
    const std::vector<PresentRow> rows = read_presents(presents);
    ASSERT_EQ(rows.size(), size_t(90 + generated));
    const int before = generated_between(rows, 0, killed_ns);
    const int after = generated_between(rows, killed_ns + 500'000'000ull, UINT64_MAX);
    std::printf("[ kill     ] generated frames: %d before the kill, %d after it, %.0f in all\n", before,
                after, generated);
    EXPECT_GT(before, 5) << "frames were generated before the kill";
    EXPECT_EQ(after, 0) << "and none after it";
}

TEST_F(LayerE2E, StalledDaemonDoesNotSlowTheApplication) {
    start_daemon();
    // fgsrd frozen for 2 s in the middle of the run. The times are CLOCK_MONOTONIC, the clock of the
    // layer's present log.
    uint64_t stopped_ns = 0, continued_ns = 0;
    std::thread staller([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1500));
        stopped_ns = fgsr::monotonic_ns();
        daemon_->signal(SIGSTOP);
        std::this_thread::sleep_for(std::chrono::milliseconds(2000));
        continued_ns = fgsr::monotonic_ns();
        daemon_->signal(SIGCONT);
    });
    // 60 frames at 10 fps: the application starts after the staller, so its last 2.5 s come after
    // the daemon is thawed.
    const std::string presents = (dir_ / "presents.csv").string();
    const AppRun r =
        run(app() + " --frames 60 --width 192 --height 108 --fps 10", {"FGSR_LAYER_PRESENTS=" + presents});
    staller.join();
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 60);
    // The application kept its 10 frames a second (6 s for 60 frames), its presents never waiting
    // for the frozen daemon.
    EXPECT_LT(json_number(r.json, "seconds"), 6.5) << r.json;
    const double generated = json_number(r.stats, "generated");
    EXPECT_EQ(json_number(r.stats, "presents"), 60 + generated);
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    // When generated frames reached the screen: none while fgsrd was frozen (half a second after the
    // stop, for a frame it finished just before it), and again after it was thawed. How many depends
    // on the CPU time this machine gives the daemon (an ASan build under steal made 16 of about 30),
    // so the test asserts on when they came, not on how many.
    const std::vector<PresentRow> rows = read_presents(presents);
    ASSERT_EQ(rows.size(), size_t(60 + generated));
    const int during = generated_between(rows, stopped_ns + 500'000'000ull, continued_ns);
    const int after = generated_between(rows, continued_ns, UINT64_MAX);
    std::printf("[ stall    ] generated frames: %d while frozen, %d after, %.0f in all\n", during, after,
                generated);
    EXPECT_EQ(during, 0);
    EXPECT_GE(after, 3) << "generation resumes once fgsrd runs again";
}

TEST_F(LayerE2E, DaemonStartedLaterIsConnectedTo) {
    const std::string socket = (dir_ / "late.sock").string();
    pid_t late = -1;
    std::thread starter([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1500));
        late = FgsrdProcess::spawn({FGSR_BIN_DIR "/fgsrd", "--socket", socket}, (dir_ / "late.log").string());
    });
    // The layer retries every 2 s. An fgsrd started at 1.5 s on a loaded machine can miss the retry
    // at 4 s (a CI run with evals beside it got "generated": 0 from 60 frames), so the app runs
    // long enough for at least two retries after the start. fgsrd listens within a fraction of a
    // second of its start because it creates pipelines at their first use: when it created all 81
    // first (4.6-6 s on 2 cores), it answered only the retry at 8 s and 6-8 frames were generated.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
    const std::string frames = "150"; // an instrumented fgsrd takes seconds more to start
#else
    const std::string frames = "90";
#endif
    const AppRun r =
        run(app() + " --frames " + frames + " --width 192 --height 108 --fps 10", {"FGSR_SOCKET=" + socket});
    starter.join();
    if (late > 0) {
        kill(late, SIGTERM);
        waitpid(late, nullptr, 0);
    }
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "no fgsrd"), 1u) << r.log;
    EXPECT_EQ(count(r.log, "connected to fgsrd"), 1u) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), std::stod(frames));
    EXPECT_GT(json_number(r.stats, "generated"), 10) << "frames generated once fgsrd was there";
    EXPECT_LT(json_number(r.stats, "generated"), std::stod(frames) - 1) << "and none before";
}

TEST_F(LayerE2E, ResizeRecreatesTheSwapchainAndGoesOn) {
    start_daemon();
    const AppRun r = run(app() + " --frames 40 --width 192 --height 108 --fps 10 --resize-at 20:160x90");
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_NE(r.json.find("\"extent\": \"160x90\""), std::string::npos) << r.json;
    EXPECT_GE(json_number(r.json, "recreations"), 1);
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    // Each swapchain's first frame has no predecessor: one more drop than without the resize.
    EXPECT_EQ(json_number(r.stats, "app_presents"), 40);
    EXPECT_GE(json_number(r.stats, "generated"), 30);
    EXPECT_NE(daemon_->stderr_text().find("160x90"), std::string::npos) << "a session of the new size";
}

TEST_F(LayerE2E, TwoSwapchainsEachGetTheirFrames) {
    start_daemon();
    const AppRun r = run(app() + " --frames 30 --width 128 --height 72 --fps 10 --windows 2");
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 60);
    // Each application frame is followed by one generated frame, shown or dropped (a swapchain's
    // first frame has none to pair with, and a loaded machine drops those that come too late).
    const double generated = json_number(r.stats, "generated");
    EXPECT_EQ(generated + json_number(r.stats, "dropped"), 60) << r.stats;
    EXPECT_EQ(json_number(r.stats, "presents"), 60 + generated) << r.stats;
    // One swapchain alone makes at most 29: more than that, and both got frames.
    EXPECT_GE(generated, 30) << r.stats;
    // And fgsrd made each of its two sessions' frames (logged as each closes with its swapchain:
    // "session S of client C destroyed (F frames, O outputs, ...)").
    std::vector<long> outputs;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (;;) {
        const std::string log = daemon_->stderr_text();
        outputs.clear();
        for (size_t at = log.find(" destroyed ("); at != std::string::npos;
             at = log.find(" destroyed (", at + 1)) {
            const size_t comma = log.find(" frames, ", at);
            if (comma != std::string::npos) outputs.push_back(std::atol(log.c_str() + comma + 9));
        }
        if (outputs.size() >= 2 || std::chrono::steady_clock::now() > give_up) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_EQ(outputs.size(), 2u) << daemon_->stderr_text();
    std::printf("[ sessions ] fgsrd outputs: %ld and %ld\n", outputs[0], outputs[1]);
    for (long o : outputs) EXPECT_GE(o, 15) << daemon_->stderr_text(); // of 29 each
}

TEST_F(LayerE2E, TwoSwapchainsInOnePresentPassThrough) {
    start_daemon();
    const AppRun r = run(app() + " --frames 20 --width 192 --height 108 --fps 10 --windows 2 --one-present");
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
    // One call for both (their semaphores are waited once): presented as the application asked.
    EXPECT_EQ(json_number(r.stats, "app_presents"), 40);
    EXPECT_EQ(json_number(r.stats, "presents"), 40);
    EXPECT_EQ(json_number(r.stats, "generated"), 0);
}

TEST_F(LayerE2E, ExitWithoutDestroyingTheSwapchainStillWritesStats) {
    start_daemon();
    const AppRun r = run(app() + " --frames 20 --width 192 --height 108 --fps 10 --no-destroy", {}, false);
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 20) << r.log;
    EXPECT_GT(json_number(r.stats, "generated"), 10);
}

// A launcher that probes the GPUs first (instances created and destroyed) still gets frame
// generation: the loader loads and unloads the layer with each instance, and each load makes its
// process-wide state afresh (the unload frees it; an ASan build's leak check at the exit sees
// every load's).
TEST_F(LayerE2E, InstancesCreatedAndDestroyedFirstEachLoadTheLayerAfresh) {
    start_daemon();
    const AppRun r =
        run(app() + " --probe-instances 3 --frames 20 --width 192 --height 108 --fps 10", {}, false);
    ASSERT_EQ(r.status, 0) << r.log;
    // Each load reads and logs its configuration once: three probes, then the run.
    EXPECT_EQ(count(r.log, "fgsr layer: configuration ("), 4u) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 20) << r.log;
    EXPECT_GT(json_number(r.stats, "generated"), 10) << r.log;
}

TEST_F(LayerE2E, ProfileMatchesTheExecutableAndEnvOverridesIt) {
    start_daemon();
    std::ofstream(dir_ / "fgsr.toml")
        << "[global]\nmultiplier = 2\n\n[[profile]]\nactive_in = [\"fgsr_layer_app\"]\n"
           "multiplier = 3\nfps_limit = 8\n\n[[profile]]\nactive_in = [\"vkcube\"]\n"
           "multiplier = 4\n";
    const std::string config = "FGSR_CONFIG=" + (dir_ / "fgsr.toml").string();
    // 50 frames: the first has no predecessor (2 of 150 presents missing, 1.3 %).
    // 75 frames: the first has no predecessor (2 of 225 presents missing, 0.9 %).
    const AppRun profiled =
        run_multiplied(app() + " --frames 75 --width 128 --height 72", {config}, false, 3, 75);
    if (!profiled.contended.empty()) GTEST_SKIP() << profiled.contended;
    ASSERT_EQ(profiled.status, 0) << profiled.log;
    EXPECT_EQ(json_number(profiled.stats, "multiplier"), 3);
    EXPECT_NE(profiled.log.find("profile fgsr_layer_app"), std::string::npos) << profiled.log;
    expect_multiplied(profiled, 3, 75);
    const AppRun overridden = run_multiplied(app() + " --frames 75 --width 128 --height 72",
                                             {config, "FGSR_MULTIPLIER=2"}, false, 2, 75);
    if (!overridden.contended.empty()) GTEST_SKIP() << overridden.contended;
    ASSERT_EQ(overridden.status, 0) << overridden.log;
    EXPECT_EQ(json_number(overridden.stats, "multiplier"), 2);
    expect_multiplied(overridden, 2, 75);
}

TEST_F(LayerE2E, MailboxAndImmediatePresentModes) {
    start_daemon();
    for (const char* mode : {"mailbox", "immediate"}) {
        const AppRun r =
            run(app() + " --frames 30 --width 192 --height 108 --fps 10 --present-mode " + std::string(mode));
        ASSERT_EQ(r.status, 0) << mode << ": " << r.log;
        EXPECT_EQ(count(r.log, "Validation Error"), 0u) << mode << ": " << r.log;
        EXPECT_EQ(json_number(r.stats, "app_presents"), 30) << mode;
        EXPECT_GE(json_number(r.stats, "generated"), 22) << mode << ": " << r.stats;
    }
}

TEST_F(LayerE2E, ConfigChangesArePickedUpWhileRunning) {
    start_daemon();
    const std::filesystem::path config = dir_ / "fgsr.toml";
    std::ofstream(config) << "[global]\nmultiplier = 2\n";
    std::thread editor([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(2500));
        std::ofstream(config) << "[global]\nmultiplier = 3\n";
    });
    const AppRun r =
        run(app() + " --frames 60 --width 192 --height 108 --fps 10", {"FGSR_CONFIG=" + config.string()});
    editor.join();
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "configuration reloaded"), 1u) << r.log;
    EXPECT_EQ(json_number(r.stats, "multiplier"), 3);
    // Every application frame after the first asks for multiplier - 1 generated frames, shown or
    // dropped: one each for the ~25 frames before the edit, two each after it. Shown frames alone
    // depend on the CPU time fgsrd gets (an ASan CI run beside other guests showed 45 and dropped 52).
    const double generated = json_number(r.stats, "generated");
    const double requested = generated + json_number(r.stats, "dropped");
    EXPECT_GT(requested, 75) << "two per frame after the edit: " << r.stats;
    EXPECT_LT(requested, 115) << "one per frame before it: " << r.stats;
    EXPECT_GT(generated, 15) << "and frames were generated: " << r.stats;
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
}

TEST_F(LayerE2E, ConfigErrorLogsOnceAndPassesThrough) {
    start_daemon();
    std::ofstream(dir_ / "fgsr.toml") << "[global]\nmultiplier = 7\n";
    const AppRun r = run(app() + " --frames 20 --width 192 --height 108 --fps 30",
                         {"FGSR_CONFIG=" + (dir_ / "fgsr.toml").string()});
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(count(r.log, "configuration error"), 1u) << r.log;
    EXPECT_NE(r.log.find("2, 3 or 4"), std::string::npos) << r.log;
    EXPECT_EQ(json_number(r.stats, "app_presents"), 20);
    EXPECT_EQ(json_number(r.stats, "presents"), 20);
    EXPECT_EQ(json_number(r.stats, "generated"), 0);
    EXPECT_EQ(count(r.log, "Validation Error"), 0u) << r.log;
}

TEST_F(LayerE2E, DisableEnvironmentUnloadsTheLayer) {
    const AppRun r = run(app() + " --frames 5 --width 192 --height 108", {"FGSR_DISABLE=1"}, false);
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_TRUE(r.stats.empty()) << "the layer wrote stats though disabled: " << r.stats;
    EXPECT_EQ(r.log.find("fgsr layer:"), std::string::npos) << r.log;
}

TEST_F(LayerE2E, GeneratedFramesScoreAgainstExactIntermediateFrames) {
    start_daemon();
    const std::string dump = (dir_ / "dump").string();
    std::filesystem::create_directories(dump);
    // 480x270 at 3 frames a second: fgsrd's motion estimation keeps up on two shared cores.
    const AppRun r =
        run(app() + " --frames 20 --width 480 --height 270 --fps 3", {"FGSR_LAYER_DUMP=" + dump}, false);
    ASSERT_EQ(r.status, 0) << r.log;
    AppRun score;
    {
        const std::string line = app() + " --score " + dump + " > " + (dir_ / "score.log").string() + " 2>&1";
        score.status = std::system(line.c_str());
        score.log = read_file((dir_ / "score.log").string());
    }
    ASSERT_EQ(score.status, 0) << score.log;
    std::printf("[ score    ] %s", score.log.c_str());
    // Scored over at least 8 of the 19 pairs. How many of them fgsrd makes in time depends on the CPU
    // time it gets: an ASan build beside two busy processes on two cores made 12-15 (37.5 dB).
    EXPECT_GE(json_number(score.log, "generated"), 8);
    const double gen = json_number(score.log, "psnr_generated"), blend = json_number(score.log, "psnr_blend");
    EXPECT_GT(gen, 15.0) << "generated frames are images of the scene";
    const double repeat = json_number(score.log, "psnr_repeat");
    EXPECT_GT(gen, repeat + 1.0) << "better than repeating the nearest real frame: " << score.log;
    if (json_number(score.log, "psnr_to_linear_blend") > 40.0) {
        // fgsrd blends colour-only sessions (no motion estimation yet): its blend is in linear light,
        // within 1 dB of the 50/50 blend of display values, not above it.
        std::printf("[ score    ] fgsrd blends (no motion estimation): generated %.2f dB, blend %.2f dB\n",
                    gen, blend);
        EXPECT_GT(gen, blend - 1.0) << score.log;
    } else {
        EXPECT_GT(gen, blend + 0.5) << "motion-estimated frames beat the 50/50 blend: " << score.log;
    }
}

// The steal reading that decides whether a timing miss is the host's (run_multiplied): fields
// counted by hand from a line of this machine's /proc/stat.
TEST(LayerE2ESteal, ReadsStealTimeFromProcStat) {
    const CpuTimes a =
        parse_cpu_times("cpu  2882307 253394 308880 1073071 4111 0 6028 18785 7 9\ncpu0 1 2 3\n");
    EXPECT_EQ(a.total, 2882307.0 + 253394 + 308880 + 1073071 + 4111 + 0 + 6028 + 18785);
    EXPECT_EQ(a.steal, 18785);
    // 100 ticks later, 44 of them stolen.
    const CpuTimes b = parse_cpu_times("cpu  2882330 253394 308890 1073093 4111 0 6029 18829 0 0\n");
    EXPECT_NEAR(steal_fraction(a, b), 0.44, 1e-12);
    EXPECT_EQ(parse_cpu_times("intr 1 2 3\n").total, 0);
    EXPECT_EQ(steal_fraction(CpuTimes{}, CpuTimes{}), 0);
    // Older kernels without a steal column: no steal.
    EXPECT_EQ(parse_cpu_times("cpu  1 2 3 4\n").steal, 0);
    // This machine's own file parses to a positive total.
    EXPECT_GT(cpu_times().total, 0);
}
