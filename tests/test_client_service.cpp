// libfgsr_client with a real fgsrd (tests/fgsrd_process.hpp): outputs equal the in-process engine's
// (bit-identical rgba32f), two and eight concurrent client processes, the daemon killed under a
// client and a reconnect to a new one, fifo and mailbox semantics, fds back to baseline, and
// `fgsr replay` printing the same metrics as in-process `fgsr eval`.
#include "run_process.hpp"
#include <fgsr/testing/fgsrd_process.hpp>

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/session_desc.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/client.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using fgsr::test::FgsrdProcess;

using fgsr::test::count_fds;

// A small synthetic capture (engine's internal conventions) and the in-process engine's frames
// halfway between each pair of inputs.
struct Expected {
    fgsr::capture::Capture cap;
    std::vector<std::vector<float>> interp; // interp[i]: between inputs i and i + 1
};

const Expected& expected() {
    static Expected* e = [] {
        auto* x = new Expected;
        fgsr::capture::SceneOptions so;
        so.width = 48;
        so.height = 32;
        so.supersample = 1;
        auto cap = fgsr::capture::make_synthetic_capture(so, 4);
        if (!cap) return x;
        x->cap = std::move(*cap);
        auto engine = fgsr::Engine::create();
        if (!engine) return x;
        auto s = (*engine)->create_session(x->cap.format);
        if (!s) return x;
        for (size_t i = 0; i < x->cap.inputs.size(); ++i) {
            if (!(*s)->submit(x->cap.inputs[i].view())) return x;
            if (i == 0) continue;
            const float a[] = {0.5f};
            auto out = (*s)->interpolate(a);
            if (!out) return x;
            x->interp.push_back((*out)[0].color.rgba);
        }
        return x;
    }();
    return *e;
}

fgsr_session_desc desc_for(const fgsr::FrameFormat& f, uint32_t policy = FGSR_QUEUE_FIFO) {
    fgsr_session_desc d = fgsr::capture::session_desc(f, fgsr::Params{}, FGSR_MODE_INTERPOLATE);
    d.queue_policy = policy;
    return d;
}

// The default Params (colour_agree on since change 41) ask fgsrd for agreement exactly where it is
// used: with vectors, at scale 1 or in a session that generates frames (ISR, ESR: change 45); and
// make a description fgsrd accepts at every scale, with or without vectors and in every mode (the
// flag is refused with NO_MVS, and with a scale other than 1 in a session that only upscales).
TEST(SessionDesc, DefaultParamsAskForAgreementOnlyWhereItApplies) {
    for (const float scale : {1.f, 2.f})
        for (const bool vectors : {true, false})
            for (const uint32_t generated :
                 {0u, uint32_t(FGSR_MODE_INTERPOLATE), uint32_t(FGSR_MODE_EXTRAPOLATE)}) {
                if (scale == 1.f && generated == 0u) continue; // a session at scale 1 generates
                fgsr::FrameFormat f;
                f.width = 64;
                f.height = 32;
                f.has_vectors = f.has_depth = vectors;
                fgsr::Params p;
                p.scale = scale;
                const uint32_t modes = generated | (scale != 1.f ? FGSR_MODE_SR : 0u);
                const fgsr_session_desc in = fgsr::capture::session_desc(f, p, modes);
                EXPECT_EQ((in.flags & FGSR_SESSION_COLOUR_AGREE) != 0, vectors && generated != 0u)
                    << "scale " << scale << (vectors ? ", vectors" : ", colour only") << ", modes " << modes;
                fgsr_session_desc out{};
                char why[256] = {};
                EXPECT_EQ(fgsr_session_desc_normalize(&in, &out, why, sizeof why), FGSR_STATUS_OK) << why;
                p.colour_agree = false;
                EXPECT_EQ(fgsr::capture::session_desc(f, p, modes).flags & FGSR_SESSION_COLOUR_AGREE, 0u);
            }
}

// Submits input i of the capture (interp at 0.5 from the second frame on).
fgsr_status submit_frame(fgsr::client::Session& s, const fgsr_pool_layout& l, const fgsr::capture::Frame& f,
                         bool interp, uint64_t* seq = nullptr) {
    fgsr_input_slot in{};
    fgsr_status st = s.acquire_input(30000, in);
    if (st != FGSR_STATUS_OK) return st;
    const size_t rows = l.output_height; // scale 1: the input height
    const size_t cb = f.color.size() / rows, db = f.depth.size() / rows;
    for (size_t y = 0; y < rows; ++y) {
        std::memcpy(static_cast<char*>(in.color) + y * l.color.row_pitch, f.color.data() + y * cb, cb);
        std::memcpy(static_cast<char*>(in.depth) + y * l.depth.row_pitch, f.depth.data() + y * db, db);
        if (!f.mv.empty()) {
            const size_t mb = f.mv.size() / rows;
            std::memcpy(static_cast<char*>(in.mv) + y * l.mv.row_pitch, f.mv.data() + y * mb, mb);
        }
    }
    static const float half[] = {0.5f};
    fgsr_submit_info si{};
    si.struct_size = sizeof(si);
    si.input_slot = in.index;
    si.flags = f.mv.empty() ? 0u : FGSR_SUBMIT_HAS_MV;
    si.interp_count = interp ? 1 : 0;
    si.interp_alphas = half;
    return s.submit(si, seq);
}

// Streams the capture through a session and compares each output with the engine's; returns
// the number of mismatching outputs (or -1 on a client error).
int stream_and_compare(const std::string& socket) {
    const Expected& e = expected();
    fgsr::client::Connection c;
    if (c.connect(socket.c_str(), "test") != FGSR_STATUS_OK) return -1;
    fgsr::client::Session s;
    if (s.create(c, desc_for(e.cap.format)) != FGSR_STATUS_OK) return -1;
    fgsr_pool_layout l{};
    s.layout(l);
    int bad = 0;
    for (size_t i = 0; i < e.cap.inputs.size(); ++i) {
        if (submit_frame(s, l, e.cap.inputs[i], i > 0) != FGSR_STATUS_OK) return -1;
        for (;;) {
            fgsr_output out{};
            if (s.wait(60000, out) != FGSR_STATUS_OK) return -1;
            if (i > 0) {
                if (out.status != FGSR_STATUS_OK || out.output_slot == FGSR_NO_SLOT) return -1;
                const std::vector<float>& want = e.interp[i - 1];
                for (uint32_t y = 0; y < out.height; ++y)
                    if (std::memcmp(static_cast<const char*>(out.pixels) + size_t(y) * out.row_pitch,
                                    want.data() + size_t(y) * out.width * 4, size_t(out.width) * 16) != 0) {
                        ++bad;
                        break;
                    }
                s.release_output(out.output_slot);
            }
            if (out.flags & FGSR_COMPLETION_LAST) break;
        }
    }
    return bad;
}

class ClientService : public ::testing::Test {
  protected:
    void SetUp() override {
        ASSERT_EQ(expected().interp.size(), 3u) << "in-process engine failed";
        setenv("FGSR_CLIENT_QUIET", "1", 1);
        daemon_ = FgsrdProcess::start({"--log-level", "warn"});
        ASSERT_TRUE(daemon_) << FgsrdProcess::last_error();
    }
    void TearDown() override { unsetenv("FGSR_CLIENT_QUIET"); }
    std::unique_ptr<FgsrdProcess> daemon_;
};

// CPU time of the calling thread, ns.
uint64_t thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

// One fgsr_wait with nothing outstanding under FGSR_WAIT_SPIN_US=spin: TIMEOUT, and this thread's
// CPU time in it.
uint64_t idle_wait_cpu_ns(const std::string& socket, const char* spin) {
    setenv("FGSR_WAIT_SPIN_US", spin, 1);
    fgsr::client::Connection c;
    fgsr::client::Session s;
    const bool made = c.connect(socket.c_str(), "test") == FGSR_STATUS_OK &&
                      s.create(c, desc_for(expected().cap.format)) == FGSR_STATUS_OK;
    unsetenv("FGSR_WAIT_SPIN_US");
    EXPECT_TRUE(made);
    if (!made) return 0;
    fgsr_output out{};
    const uint64_t c0 = thread_cpu_ns();
    EXPECT_EQ(s.wait(200, out), FGSR_STATUS_TIMEOUT);
    return thread_cpu_ns() - c0;
}

TEST_F(ClientService, SpinningDaemonAndClientGiveTheSameOutputsAndTheSpinIsBounded) {
    auto spinning = FgsrdProcess::start({"--log-level", "warn", "--spin-us", "1000"});
    ASSERT_TRUE(spinning) << FgsrdProcess::last_error();
    setenv("FGSR_WAIT_SPIN_US", "1000", 1);
    EXPECT_EQ(stream_and_compare(spinning->socket_path()), 0);
    setenv("FGSR_WAIT_SPIN_US", "not a number", 1); // logged, the default used
    EXPECT_EQ(stream_and_compare(spinning->socket_path()), 0);
    unsetenv("FGSR_WAIT_SPIN_US");
    // A 200 ms wait spins at most its 1 ms budget, then sleeps: far less CPU than the wait's length
    // (an unbounded spin would take about 200 ms). Not a timing figure: a bound 40 times the budget.
    EXPECT_LT(idle_wait_cpu_ns(spinning->socket_path(), "1000"), 40'000'000u);
    EXPECT_LT(idle_wait_cpu_ns(spinning->socket_path(), "0"), 40'000'000u);
    EXPECT_EQ(spinning->terminate(), 0);
}

TEST_F(ClientService, OutputsEqualTheInProcessEngineAndFdsReturnToBaseline) {
    const int base = count_fds();
    EXPECT_EQ(stream_and_compare(daemon_->socket_path()), 0);
    EXPECT_EQ(count_fds(), base);
}

void concurrent_clients(const std::string& socket, int n) {
    std::vector<pid_t> kids;
    for (int k = 0; k < n; ++k) {
        const pid_t pid = fork();
        if (pid == 0) {
            const int bad = stream_and_compare(socket);
            _exit(bad == 0 ? 0 : bad < 0 ? 2 : 1);
        }
        ASSERT_GT(pid, 0);
        kids.push_back(pid);
    }
    for (pid_t pid : kids) {
        int status = -1;
        ASSERT_EQ(waitpid(pid, &status, 0), pid);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
            << "client " << pid << " status " << status;
    }
}

TEST_F(ClientService, TwoConcurrentClientProcesses) {
    concurrent_clients(daemon_->socket_path(), 2);
}

TEST_F(ClientService, EightConcurrentClientProcesses) {
    concurrent_clients(daemon_->socket_path(), 8);
}

TEST_F(ClientService, DaemonKilledUnderAClientThenReconnect) {
    const Expected& e = expected();
    const int base = count_fds();
    {
        fgsr::client::Connection c;
        ASSERT_EQ(c.connect(daemon_->socket_path().c_str()), FGSR_STATUS_OK);
        fgsr_daemon_info first{};
        c.daemon_info(first);
        fgsr::client::Session s;
        ASSERT_EQ(s.create(c, desc_for(e.cap.format)), FGSR_STATUS_OK);
        daemon_->kill9();
        fgsr_output out{};
        EXPECT_EQ(s.wait(10000, out), FGSR_STATUS_DISCONNECTED);
        fgsr_pool_layout l{};
        s.layout(l);
        const fgsr_status st = submit_frame(s, l, e.cap.inputs[0], false);
        EXPECT_TRUE(st == FGSR_STATUS_DISCONNECTED || st == FGSR_STATUS_OK) << fgsr_status_string(st);
        fgsr_session_stats stats{};
        EXPECT_EQ(s.stats(stats), FGSR_STATUS_DISCONNECTED);

        // A new daemon (new epoch) serves a new connection.
        daemon_ = FgsrdProcess::start({"--log-level", "warn"});
        ASSERT_TRUE(daemon_) << FgsrdProcess::last_error();
        fgsr::client::Connection c2;
        ASSERT_EQ(c2.connect(daemon_->socket_path().c_str()), FGSR_STATUS_OK);
        fgsr_daemon_info second{};
        c2.daemon_info(second);
        EXPECT_NE(first.epoch, second.epoch);
    }
    EXPECT_EQ(stream_and_compare(daemon_->socket_path()), 0);
    EXPECT_EQ(count_fds(), base);
}

// A layer polls: fgsr_acquire_input and fgsr_wait with timeout 0, every frame. They must see a
// daemon that died with every input slot in flight (found by the layer's kill test under load: the
// calls answered NO_SLOT / TIMEOUT for good, and the layer never noticed nor reconnected).
TEST_F(ClientService, ZeroTimeoutCallsSeeADaemonThatDiedWithEverySlotHeld) {
    const Expected& e = expected();
    fgsr::client::Connection c;
    ASSERT_EQ(c.connect(daemon_->socket_path().c_str()), FGSR_STATUS_OK);
    fgsr::client::Session held, idle;
    ASSERT_EQ(held.create(c, desc_for(e.cap.format)), FGSR_STATUS_OK);
    ASSERT_EQ(idle.create(c, desc_for(e.cap.format)), FGSR_STATUS_OK);
    fgsr_pool_layout l{};
    held.layout(l);
    fgsr_input_slot in{};
    for (uint32_t i = 0; i < l.input_slot_count; ++i)
        ASSERT_EQ(held.acquire_input(0, in), FGSR_STATUS_OK) << i;
    EXPECT_EQ(held.acquire_input(0, in), FGSR_STATUS_NO_SLOT); // alive: none free, no wait
    fgsr_output out{};
    EXPECT_EQ(idle.wait(0, out), FGSR_STATUS_TIMEOUT);
    daemon_->kill9();
    EXPECT_EQ(held.acquire_input(0, in), FGSR_STATUS_DISCONNECTED);
    EXPECT_EQ(idle.wait(0, out), FGSR_STATUS_DISCONNECTED);
}

TEST_F(ClientService, FifoAndMailboxSemantics) {
    const Expected& e = expected();
    for (uint32_t policy : {uint32_t(FGSR_QUEUE_FIFO), uint32_t(FGSR_QUEUE_MAILBOX)}) {
        fgsr::client::Connection c;
        ASSERT_EQ(c.connect(daemon_->socket_path().c_str()), FGSR_STATUS_OK);
        fgsr::client::Session s;
        fgsr_session_desc d = desc_for(e.cap.format, policy);
        d.input_slots = 4;
        ASSERT_EQ(s.create(c, d), FGSR_STATUS_OK);
        fgsr_pool_layout l{};
        s.layout(l);
        // Four submits back to back, then collect: every submit ends with exactly one LAST
        // completion; fifo produces every output in order; mailbox may drop superseded submits but
        // never the newest.
        for (size_t i = 0; i < 4; ++i) ASSERT_EQ(submit_frame(s, l, e.cap.inputs[i], i > 0), FGSR_STATUS_OK);
        std::vector<int32_t> fate(5, -1);
        uint64_t last_seq = 0;
        size_t done = 0;
        while (done < 4) {
            fgsr_output out{};
            ASSERT_EQ(s.wait(60000, out), FGSR_STATUS_OK);
            ASSERT_GE(out.sequence, 1u);
            ASSERT_LE(out.sequence, 4u);
            EXPECT_GE(out.sequence, last_seq) << "completions out of order";
            last_seq = out.sequence;
            if (out.output_slot != FGSR_NO_SLOT) s.release_output(out.output_slot);
            if (out.flags & FGSR_COMPLETION_LAST) {
                EXPECT_EQ(fate[out.sequence], -1) << "two LAST completions";
                fate[out.sequence] = out.status;
                ++done;
            }
        }
        for (uint64_t q = 1; q <= 4; ++q) {
            if (policy == FGSR_QUEUE_FIFO) {
                EXPECT_EQ(fate[q], FGSR_STATUS_OK) << "fifo, sequence " << q;
            } else {
                EXPECT_TRUE(fate[q] == FGSR_STATUS_OK || fate[q] == FGSR_STATUS_DROPPED ||
                            fate[q] == FGSR_STATUS_NOT_READY)
                    << "mailbox " << q;
            }
        }
        // The newest submit is processed, never dropped. In mailbox mode its predecessors may all have
        // been dropped (not ingested), so interpolation may have no previous frame: NOT_READY.
        EXPECT_TRUE(fate[4] == FGSR_STATUS_OK ||
                    (policy == FGSR_QUEUE_MAILBOX && fate[4] == FGSR_STATUS_NOT_READY))
            << "newest: " << fgsr_status_string(fate[4]);
        fgsr_session_stats st{};
        ASSERT_EQ(s.stats(st), FGSR_STATUS_OK);
        EXPECT_EQ(st.frames_submitted, 4u);
        if (policy == FGSR_QUEUE_FIFO) {
            EXPECT_EQ(st.frames_dropped, 0u);
        }
    }
}

// `fgsr eval --json` of the fgsr method on a saved capture, in process and through fgsrd (replay's
// code path); both must exit 0.
std::pair<fgsr::test::ProcessRun, fgsr::test::ProcessRun> eval_both_ways(const fs::path& cap,
                                                                         const std::string& socket) {
    const std::string bin = std::string(FGSR_BIN_DIR) + "/fgsr";
    auto ev = fgsr::test::run_process(bin + " eval --quiet --json --methods fgsr --capture " + cap.string());
    EXPECT_EQ(ev.status, 0) << ev.out;
    auto rp = fgsr::test::run_process(bin + " eval --quiet --json --capture " + cap.string() + " --socket " +
                                      socket);
    EXPECT_EQ(rp.status, 0) << rp.out;
    return {std::move(ev), std::move(rp)};
}

// A synthetic 64x36 capture of `inputs` frames (`supersample` samples per pixel), `edit`ed, saved
// as dir / "cap" in a fresh directory under /tmp; the caller removes dir.
fs::path saved_capture(const char* prefix, size_t inputs, uint32_t supersample,
                       const std::function<void(fgsr::capture::Capture&)>& edit = {}) {
    std::string tmpl = std::string("/tmp/") + prefix + "-XXXXXX";
    const fs::path dir = mkdtemp(tmpl.data());
    fgsr::capture::SceneOptions so;
    so.width = 64;
    so.height = 36;
    so.supersample = supersample;
    auto cap = fgsr::capture::make_synthetic_capture(so, inputs);
    EXPECT_TRUE(cap);
    if (!cap) return dir;
    if (edit) edit(*cap);
    EXPECT_TRUE(fgsr::capture::save_fgsr(*cap, dir / "cap"));
    return dir;
}

// A recorded scene cut (capture format "reset") is honoured in process and through fgsrd: the
// pair across the cut is not generated, the others are, with the same scores both ways.
TEST_F(ClientService, SceneCutsOfACaptureAreHonouredByEvalAndReplay) {
    const fs::path dir =
        saved_capture("fgsr-cut", 5, 4, [](fgsr::capture::Capture& cap) { cap.inputs[2].reset = true; });
    const auto [ev, rp] = eval_both_ways(dir / "cap", daemon_->socket_path());
    ASSERT_EQ(ev.status, 0);
    ASSERT_EQ(rp.status, 0);
    const auto a = nlohmann::json::parse(ev.out, nullptr, false),
               b = nlohmann::json::parse(rp.out, nullptr, false);
    ASSERT_FALSE(a.is_discarded() || b.is_discarded());
    EXPECT_EQ(a["frames"].get<int>(), 3) << "4 pairs, one across the cut";
    EXPECT_EQ(b["frames"].get<int>(), 3);
    EXPECT_EQ(a["methods"]["fgsr"]["psnr"], b["methods"]["fgsr"]["psnr"]);
    std::error_code ec;
    fs::remove_all(dir, ec);
}

// `fgsr eval --json --methods fgsr` on a small saved capture three ways: in process with `option`,
// through fgsrd with it, and through fgsrd without it; each parsed (nullopt, and a test failure,
// where one fails).
struct OptionRuns {
    nlohmann::json in_process, daemon, plain;
    std::string daemon_out, plain_out;
};
// `off` is the plain run's option (the option's switch turned off: colour_agree is on by default).
std::optional<OptionRuns> eval_three_ways(const char* prefix, const std::string& option,
                                          const std::string& socket, const std::string& off) {
    const fs::path dir = saved_capture(prefix, 4, 4);
    const std::string common = std::string(FGSR_BIN_DIR) +
                               "/fgsr eval --quiet --json --methods fgsr --capture " + (dir / "cap").string();
    auto ev = fgsr::test::run_process(common + " " + option);
    auto rp = fgsr::test::run_process(common + " " + option + " --socket " + socket);
    auto plain = fgsr::test::run_process(common + " " + off + " --socket " + socket);
    std::error_code ec;
    fs::remove_all(dir, ec);
    EXPECT_EQ(ev.status, 0) << ev.out;
    EXPECT_EQ(rp.status, 0) << rp.out;
    EXPECT_EQ(plain.status, 0) << plain.out;
    OptionRuns r{nlohmann::json::parse(ev.out, nullptr, false), nlohmann::json::parse(rp.out, nullptr, false),
                 nlohmann::json::parse(plain.out, nullptr, false), rp.out, plain.out};
    const bool ok = ev.status == 0 && rp.status == 0 && plain.status == 0 && !r.in_process.is_discarded() &&
                    !r.daemon.is_discarded() && !r.plain.is_discarded();
    EXPECT_TRUE(ok);
    if (!ok) return std::nullopt;
    return r;
}

// `--correct-vectors` through fgsrd (the session flag FGSR_SESSION_CORRECT_MVS, as `fgsr replay
// --correct-vectors` sends it): the motion passes run in the daemon and the scores equal the
// in-process ones with the same option; without it no motion pass runs (colour_agree off in all
// three runs, whose twin would run them).
TEST_F(ClientService, CorrectedVectorsGoThroughTheDaemon) {
    const auto r = eval_three_ways("fgsr-correct", "--colour-agree=false --correct-vectors",
                                   daemon_->socket_path(), "--colour-agree=false");
    ASSERT_TRUE(r);
    const auto &a = r->in_process["methods"]["fgsr"], &b = r->daemon["methods"]["fgsr"],
               &c = r->plain["methods"]["fgsr"];
    EXPECT_EQ(a["psnr"], b["psnr"]);
    for (const char* pass : {"luma", "match", "flow"}) {
        EXPECT_TRUE(b["pass_ms"].contains(pass)) << pass << " in " << r->daemon_out;
        EXPECT_FALSE(c["pass_ms"].contains(pass)) << pass << " in " << r->plain_out;
    }
    // The correction keeps given vectors where no estimate beats them: nothing to refine.
    EXPECT_FALSE(b["pass_ms"].contains("polish")) << r->daemon_out;
}

// colour_agree (on by default) through fgsrd: `fgsr eval --socket` and `fgsr replay` send the
// session flag FGSR_SESSION_COLOUR_AGREE without being asked; the scores equal the in-process ones,
// and the agree pass and the colour twin's motion passes ran in the daemon; with
// `--colour-agree=false` neither ran.
TEST_F(ClientService, AgreeingInterpolationGoesThroughTheDaemon) {
    const auto r = eval_three_ways("fgsr-agree", "", daemon_->socket_path(), "--colour-agree=false");
    ASSERT_TRUE(r);
    const auto &a = r->in_process["methods"]["fgsr"], &b = r->daemon["methods"]["fgsr"],
               &c = r->plain["methods"]["fgsr"];
    EXPECT_EQ(a["psnr"], b["psnr"]);
    EXPECT_EQ(a["ssim"], b["ssim"]);
    for (const char* pass : {"agree", "luma", "match", "flow"}) {
        EXPECT_TRUE(a["pass_ms"].contains(pass)) << pass;
        EXPECT_TRUE(b["pass_ms"].contains(pass)) << pass << " in " << r->daemon_out;
        EXPECT_FALSE(c["pass_ms"].contains(pass)) << pass << " in " << r->plain_out;
    }
}

// `fgsr replay` and `fgsr eval` on the same small capture print the same PSNR and SSIM.
TEST_F(ClientService, ReplayPrintsTheSameMetricsAsEval) {
    const fs::path dir = saved_capture("fgsr-replay", 5, 2);
    const std::string bin = std::string(FGSR_BIN_DIR) + "/fgsr";
    const auto [ev, rp] = eval_both_ways(dir / "cap", daemon_->socket_path());
    ASSERT_EQ(ev.status, 0);
    ASSERT_EQ(rp.status, 0);
    auto field = [](const std::string& js, const std::string& key) {
        const size_t p = js.find("\"" + key + "\":");
        return p == std::string::npos ? std::string("missing")
                                      : js.substr(p, js.find_first_of(",}\n", p) - p);
    };
    EXPECT_NE(field(ev.out, "psnr"), "missing");
    EXPECT_EQ(field(ev.out, "psnr"), field(rp.out, "psnr"));
    EXPECT_EQ(field(ev.out, "ssim"), field(rp.out, "ssim"));
    EXPECT_EQ(field(ev.out, "frames"), field(rp.out, "frames"));
    // replay itself: summary and telemetry CSV with one row per output.
    auto r = fgsr::test::run_process(bin + " replay --quiet --capture " + (dir / "cap").string() +
                                     " --socket " + daemon_->socket_path() + " --telemetry " +
                                     (dir / "t.csv").string() + " --out " + (dir / "out").string());
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("p50"), std::string::npos) << r.out;
    std::ifstream csv(dir / "t.csv");
    std::string line;
    int rows = -1;
    while (std::getline(csv, line)) ++rows;
    EXPECT_GE(rows, 2); // half rate of 5 frames: 2 targets, plus first-frame completions
    EXPECT_TRUE(fs::exists(dir / "out" / "fgsr" / "0001.exr"));
    // --out also gets eval's metrics.json, with the same PSNR as in-process eval.
    std::ifstream mj(dir / "out" / "metrics.json");
    const std::string metrics((std::istreambuf_iterator<char>(mj)), std::istreambuf_iterator<char>());
    EXPECT_EQ(field(metrics, "psnr"), field(ev.out, "psnr")) << metrics;
    std::error_code ec;
    fs::remove_all(dir, ec);
}

} // namespace
