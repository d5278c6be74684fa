// Attacks on fgsrd from other processes (issue: no client can stall fgsrd, one heavy client cannot
// starve the rest). Each test reproduces one attack against a real daemon and checks that the
// daemon, its other clients and its shutdown are unaffected.
#include "raw_client.hpp"

#include <fgsr/testing/fgsrd_process.hpp>

#include <algorithm>
#include <atomic>
#include <fcntl.h>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>

namespace fgsr::test {
namespace {

// Milliseconds for a fresh connection's HELLO round trip; -1 when it is not answered in timeout.
double hello_ms(const std::string& path, int timeout_ms = 5000) {
    const uint64_t t0 = monotonic_ns();
    auto r = Raw::connect(path);
    if (!r) return -1;
    const fgsr_hello h = hello_message("");
    if (!r->send(&h, sizeof(h))) return -1;
    auto m = r->recv(nullptr, nullptr, timeout_ms);
    if (m.size() != sizeof(fgsr_hello_reply)) return -1;
    return double(monotonic_ns() - t0) * 1e-6;
}

// The daemon is still whole: a new client is served at once, and SIGTERM ends it cleanly.
void expect_responsive_and_stoppable(FgsrdProcess& d) {
    const double ms = hello_ms(d.socket_path(), 2000);
    EXPECT_GE(ms, 0) << "a new client's HELLO was not answered";
    EXPECT_LT(ms, 1000);
    const int status = d.terminate(5000);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << "\n" << d.stderr_text();
}

// Attack 1a: the client clears O_NONBLOCK on the submit eventfd (it shares the open file
// description) and signals; a daemon that read() the eventfd blocked there for good.
TEST(DaemonHostile, BlockingSubmitEventfdCannotStallTheDaemon) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto attacker = open_session(d->socket_path());
    ASSERT_TRUE(attacker);
    const int efd = attacker->s->fds[FGSR_FD_SUBMIT_EVENT].fd;
    ASSERT_EQ(fcntl(efd, F_SETFL, fcntl(efd, F_GETFL) & ~O_NONBLOCK), 0);
    // Frames still round-trip for the attacker itself (the eventfd is only a wake-up).
    auto v = roundtrip(*attacker->s, 0.f);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
    v = roundtrip(*attacker->s, 1.f);
    ASSERT_EQ(v.size(), 1u);
    auto other = open_session(d->socket_path());
    ASSERT_TRUE(other);
    EXPECT_EQ(roundtrip(*other->s, 0.f).size(), 1u);
    expect_responsive_and_stoppable(*d);
}

// Attack 1b: O_NONBLOCK cleared on the complete eventfd and its counter filled to 2^64-2: the
// daemon's write() would block for good. The daemon must drop the attacker and go on.
TEST(DaemonHostile, BlockingCompleteEventfdDropsTheAttackerOnly) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto attacker = open_session(d->socket_path());
    auto other = open_session(d->socket_path());
    ASSERT_TRUE(attacker && other);
    const int efd = attacker->s->fds[FGSR_FD_COMPLETE_EVENT].fd;
    ASSERT_EQ(fcntl(efd, F_SETFL, fcntl(efd, F_GETFL) & ~O_NONBLOCK), 0);
    const uint64_t full = 0xfffffffffffffffeull;
    ASSERT_EQ(write(efd, &full, 8), 8);
    attacker->s->fill(0, 0.f);
    attacker->s->push(attacker->s->entry(0, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    EXPECT_TRUE(attacker->raw.closed_by_daemon(10000));
    auto v = roundtrip(*other->s, 0.f);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
    EXPECT_NE(d->stderr_text().find("complete eventfd blocked"), std::string::npos) << d->stderr_text();
    expect_responsive_and_stoppable(*d);
}

// A session of `side` x `side`, scale 1, interpolation only, 4 input and 8 output slots.
fgsr_session_desc square_desc(uint32_t side) {
    fgsr_session_desc desc = default_desc();
    desc.width = desc.height = side;
    desc.scale = 1.f;
    desc.modes = FGSR_MODE_INTERPOLATE;
    desc.input_slots = 4;
    desc.output_slots = 8;
    return desc;
}

// Fills input slot i of a session of any size with a moving ramp.
void fill_any(RawSession& s, uint32_t i, float shift) {
    const fgsr_pool_layout& l = s.layout();
    const uint32_t w = l.color.row_pitch / 16, h = uint32_t(l.color.size / l.color.row_pitch);
    auto* c = reinterpret_cast<float*>(s.slot(i) + l.color.offset);
    auto* dp = reinterpret_cast<float*>(s.slot(i) + l.depth.offset);
    auto* m = reinterpret_cast<float*>(s.slot(i) + l.mv.offset);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            const float v = float((x + uint32_t(shift) + y / 3) % 37) / 36.f;
            c[4 * p] = v;
            c[4 * p + 1] = 1.f - v;
            c[4 * p + 2] = 0.25f;
            c[4 * p + 3] = 1.f;
            dp[p] = 10.f + float(x % 7);
            m[2 * p] = -2.f;
            m[2 * p + 1] = 0.f;
        }
}

// Submits frames with `interps` interpolated outputs until stop, keeping `depth` submits queued
// (input slots 0..depth); returns the engine milliseconds (start to complete) of every submit
// that produced outputs.
std::vector<double> keep_busy(RawSession& s, uint32_t interps, const std::atomic<bool>& stop,
                              uint32_t depth = 1) {
    std::vector<double> ms;
    uint32_t outstanding = 0;
    for (uint32_t frame = 0; !stop || outstanding > 0; ++frame) {
        if (!stop && outstanding < depth) {
            const uint32_t slot = frame % (depth + 1);
            fill_any(s, slot, float(frame * 2));
            fgsr_submit_entry e = s.entry(slot);
            e.interp_count = frame == 0 ? 0 : interps;
            for (uint32_t k = 0; k < e.interp_count; ++k)
                e.interp_alphas[k] = float(k + 1) / float(interps + 1);
            s.push(e);
            ++outstanding;
            if (outstanding < depth) continue;
        }
        auto v = s.wait_submit(120000);
        if (v.empty()) break;
        --outstanding;
        for (const auto& c : v)
            if (c.output_slot != FGSR_NO_SLOT) s.release(c.output_slot);
        if (v.back().status == FGSR_STATUS_OK && v.back().telemetry.frame_type == FGSR_FRAME_INTERPOLATED)
            ms.push_back(double(v.back().telemetry.complete_ns - v.back().telemetry.start_ns) * 1e-6);
    }
    return ms;
}

// Attack 2: a heavy session (1024x1024, eight interpolated frames per submit, on the bulk lane)
// runs back to back. HELLO, STATS and a small client's frames must not wait for its submits.
TEST(DaemonHostile, AHeavySessionDoesNotHoldUpHelloOrSmallClients) {
    auto d = FgsrdProcess::start({"--interactive-pixels", "65536"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto heavy = open_session(d->socket_path(), square_desc(1024));
    auto small = open_session(d->socket_path());
    ASSERT_TRUE(heavy && small);
    std::atomic<bool> stop{false};
    std::vector<double> heavy_ms;
    std::thread t([&] { heavy_ms = keep_busy(*heavy->s, 8, stop); });
    usleep(300000);
    std::vector<double> hello, frame;
    for (int i = 0; i < 20; ++i) {
        hello.push_back(hello_ms(d->socket_path()));
        const uint64_t t0 = monotonic_ns();
        auto v = roundtrip(*small->s, float(i));
        EXPECT_EQ(v.size(), 1u);
        frame.push_back(double(monotonic_ns() - t0) * 1e-6);
        usleep(50000);
    }
    stop = true;
    t.join();
    ASSERT_GE(heavy_ms.size(), 1u) << "the heavy session produced nothing";
    std::sort(heavy_ms.begin(), heavy_ms.end());
    const double heavy_median = heavy_ms[heavy_ms.size() / 2];
    const double worst_hello = *std::max_element(hello.begin(), hello.end());
    const double worst_frame = *std::max_element(frame.begin(), frame.end());
    // A daemon that ran the engine on its own thread waited a heavy submit for both.
    EXPECT_GE(*std::min_element(hello.begin(), hello.end()), 0.0);
    EXPECT_LT(worst_hello, std::min(250.0, heavy_median / 2))
        << "heavy submit median " << heavy_median << " ms";
    EXPECT_LT(worst_frame, heavy_median / 2) << "heavy submit median " << heavy_median << " ms";
    expect_responsive_and_stoppable(*d);
}

// The long frame of SigtermDoesNotWaitForALongFrame: on a new 2048x2048 session, a first input
// (waited for), then a second one with 8 interpolated frames (seconds on a CPU device), pushed at
// `pushed` (monotonic ns) and not waited for. Returns the session.
std::optional<Conn> push_long_frame(const FgsrdProcess& d, uint64_t& pushed) {
    auto heavy = open_session(d.socket_path(), square_desc(2048));
    if (!heavy) return std::nullopt;
    RawSession& s = *heavy->s;
    fill_any(s, 0, 0.f);
    s.push(s.entry(0));
    EXPECT_EQ(s.wait_submit().size(), 1u);
    fill_any(s, 1, 4.f);
    fgsr_submit_entry e = s.entry(1);
    e.interp_count = 8;
    for (uint32_t k = 0; k < 8; ++k) e.interp_alphas[k] = float(k + 1) / 9.f;
    pushed = monotonic_ns();
    s.push(e);
    return heavy;
}

// SIGTERM while a long frame runs (2048x2048, eight outputs: seconds on lavapipe): clients are
// disconnected at once and the daemon exits after --shutdown-grace, not after the frame.
TEST(DaemonHostile, SigtermDoesNotWaitForALongFrame) {
    // What is timed is the daemon's exit, not LeakSanitizer's scan of its heap at the exit (the
    // other daemon tests check for leaks): with the scan, an ASan build under load took 2.0 s.
    const AsanOptionForChildren no_leak_scan("detect_leaks=0");
    auto d = FgsrdProcess::start({"--shutdown-grace", "0.2"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    uint64_t submitted = 0;
    auto heavy = push_long_frame(*d, submitted);
    ASSERT_TRUE(heavy);
    RawSession& s = *heavy->s;
    usleep(300000); // the frame is running
    const uint64_t t0 = monotonic_ns();
    const int status = d->terminate(30000);
    const double exit_ms = double(monotonic_ns() - t0) * 1e-6;
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    EXPECT_TRUE(heavy->raw.closed_by_daemon(10));
    const bool finished = s.wait(0).has_value();
    EXPECT_NE(access(d->socket_path().c_str(), F_OK), 0) << "socket file left behind";
    std::printf("[ measured ] SIGTERM to exit %.0f ms, %.0f ms after the submit\n", exit_ms,
                double(monotonic_ns() - submitted) * 1e-6);
    if (finished) return; // this machine ran eight 2048x2048 frames in 300 ms: nothing to test
    EXPECT_NE(d->stderr_text().find("exiting without waiting"), std::string::npos) << d->stderr_text();
#if defined(FGSR_TEST_ASAN) || defined(FGSR_TEST_TSAN)
    const double bound_ms = 3000.0; // an instrumented daemon's teardown is slower (the frame is not)
#else
    const double bound_ms = 1500.0;
#endif
    if (exit_ms < bound_ms) return;
    // Past the bound: a daemon that waited for the frame, or a loaded machine, which slows the
    // exit and the frame alike (CI once measured 3345 ms under a build's load). The frame itself,
    // run to its end on a second daemon now, tells them apart: a daemon that waited took the rest
    // of the frame (all of it less 300 ms) to exit, one that did not, a small part of it.
    auto d2 = FgsrdProcess::start();
    ASSERT_TRUE(d2) << FgsrdProcess::last_error();
    uint64_t pushed = 0;
    auto again = push_long_frame(*d2, pushed);
    ASSERT_TRUE(again);
    const auto done = again->s->wait_submit(300000);
    const double frame_ms = double(monotonic_ns() - pushed) * 1e-6;
    ASSERT_TRUE(!done.empty() && (done.back().flags & FGSR_COMPLETION_LAST) != 0)
        << "the long frame did not finish on the second daemon";
    std::printf("[ measured ] exit %.0f ms is past %.0f ms; the frame takes %.0f ms now\n", exit_ms, bound_ms,
                frame_ms);
    EXPECT_LT(exit_ms, 0.5 * frame_ms) << "SIGTERM to exit took " << exit_ms << " ms, the frame " << frame_ms
                                       << " ms: the daemon waited for the frame";
}

// Fairness: two sessions on the same lane, one with 64 times the pixels of the other, both always
// ready (up to three submits queued each, so that a client thread delayed by a loaded machine
// still has work waiting). Each should get about half of the lane's time, not half of its frames:
// frame-fair round robin measured 30.7 here (112 big and 115 small frames).
TEST(DaemonHostile, LaneTimeIsSharedFairlyWhateverTheFrameSize) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto big = open_session(d->socket_path(), square_desc(512));
    auto little = open_session(d->socket_path(), square_desc(64));
    ASSERT_TRUE(big && little);
    std::atomic<bool> stop{false};
    std::vector<double> big_ms, little_ms;
    std::thread tb([&] { big_ms = keep_busy(*big->s, 1, stop, 3); });
    std::thread tl([&] { little_ms = keep_busy(*little->s, 1, stop, 3); });
    usleep(4000000);
    stop = true;
    tb.join();
    tl.join();
    double big_total = 0, little_total = 0;
    for (double v : big_ms) big_total += v;
    for (double v : little_ms) little_total += v;
    ASSERT_GT(little_ms.size(), 2u);
    ASSERT_GT(big_ms.size(), 0u);
    // Per-frame cost ratio, and the lane-time ratio: frame-fair scheduling gives the big session
    // the cost ratio; time-fair gives about 1 (the small client also spends time between frames).
    const double cost_ratio = (big_total / double(big_ms.size())) / (little_total / double(little_ms.size()));
    const double time_ratio = big_total / little_total;
    EXPECT_GT(cost_ratio, 8.0) << "the sizes do not differ enough in cost for this test";
    EXPECT_LT(time_ratio, 4.0) << big_ms.size() << " big frames, " << little_ms.size() << " small frames";
    std::printf(
        "[ measured ] lane time big/small %.2f at a per-frame cost ratio of %.1f (%zu and %zu frames)\n",
        time_ratio, cost_ratio, big_ms.size(), little_ms.size());
    expect_responsive_and_stoppable(*d);
}

fgsr_create_session_reply create(Raw& raw, const fgsr_session_desc& desc, std::vector<Fd>* fds = nullptr) {
    fgsr_create_session m{};
    m.header = header(FGSR_MSG_CREATE_SESSION, sizeof(m), 2);
    m.desc = desc;
    EXPECT_TRUE(raw.send(&m, sizeof(m)));
    return as<fgsr_create_session_reply>(raw.recv(fds));
}

// Limits: an 8192x8192 session is refused before anything is allocated (by default: above 4096 x
// 4096 pixels); so is one above the memory limit; beyond the total memory budget a session gets
// BUSY.
TEST(DaemonHostile, SessionLimitsRefuseWithAReason) {
    auto d = FgsrdProcess::start({"--max-session-memory", "600", "--max-total-memory", "700"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto raw = Raw::connect(d->socket_path());
    ASSERT_TRUE(raw);
    ASSERT_EQ(raw->hello().status, FGSR_STATUS_OK);
    fgsr_session_desc huge = square_desc(8192); // compact planes: within the pool limits
    huge.color_format = huge.output_format = FGSR_COLOR_RGBA8_SRGB;
    huge.mv_format = FGSR_MV_RG16F;
    huge.input_slots = huge.output_slots = 1;
    auto r = create(*raw, huge);
    EXPECT_EQ(r.status, FGSR_STATUS_UNSUPPORTED);
    EXPECT_NE(std::string(r.reason).find("--max-session-pixels"), std::string::npos) << r.reason;
    r = create(*raw, square_desc(2048));
    EXPECT_EQ(r.status, FGSR_STATUS_UNSUPPORTED);
    EXPECT_NE(std::string(r.reason).find("--max-session-memory"), std::string::npos) << r.reason;
    std::vector<Fd> fds;
    r = create(*raw, square_desc(1024), &fds);
    ASSERT_EQ(r.status, FGSR_STATUS_OK) << r.reason;
    auto second = Raw::connect(d->socket_path());
    ASSERT_TRUE(second);
    ASSERT_EQ(second->hello().status, FGSR_STATUS_OK);
    r = create(*second, square_desc(1024));
    EXPECT_EQ(r.status, FGSR_STATUS_BUSY);
    EXPECT_NE(std::string(r.reason).find("--max-total-memory"), std::string::npos) << r.reason;
    r = create(*second, default_desc());
    EXPECT_EQ(r.status, FGSR_STATUS_OK) << r.reason; // small ones still fit
    expect_responsive_and_stoppable(*d);
}

// Attack 3: connections that say HELLO and then idle. Per uid they are limited; idle ones are
// closed after --idle-timeout, and when the daemon is full a new client evicts the longest idle.
TEST(DaemonHostile, IdleClientsCannotLockOthersOut) {
    auto d =
        FgsrdProcess::start({"--max-clients", "4", "--max-clients-per-uid", "3", "--idle-timeout", "1.5"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    std::vector<Raw> idle;
    for (int i = 0; i < 3; ++i) {
        auto r = Raw::connect(d->socket_path());
        ASSERT_TRUE(r);
        ASSERT_EQ(r->hello().status, FGSR_STATUS_OK);
        idle.push_back(std::move(*r));
    }
    auto fourth = Raw::connect(d->socket_path());
    ASSERT_TRUE(fourth);
    EXPECT_EQ(fourth->hello().status, FGSR_STATUS_BUSY) << "per-uid limit";
    // A working client is not idle; the idle ones are closed after the timeout.
    for (auto& r : idle) EXPECT_TRUE(r.closed_by_daemon(5000));
    auto busy = open_session(d->socket_path());
    ASSERT_TRUE(busy);
    for (int i = 0; i < 8; ++i) {
        EXPECT_EQ(roundtrip(*busy->s, float(i)).size(), 1u);
        usleep(300000);
    }
    EXPECT_FALSE(busy->raw.closed_by_daemon(10)) << "a client that submits frames is not idle";
    EXPECT_NE(d->stderr_text().find("idle for"), std::string::npos);
    expect_responsive_and_stoppable(*d);
}

TEST(DaemonHostile, AFullDaemonEvictsTheLongestIdleClientWithoutSessions) {
    auto d = FgsrdProcess::start({"--max-clients", "2"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto a = Raw::connect(d->socket_path());
    ASSERT_TRUE(a);
    ASSERT_EQ(a->hello().status, FGSR_STATUS_OK);
    auto b = open_session(d->socket_path()); // has a session: never evicted
    ASSERT_TRUE(b);
    usleep(1200000);
    auto c = Raw::connect(d->socket_path());
    ASSERT_TRUE(c);
    EXPECT_EQ(c->hello().status, FGSR_STATUS_OK);
    EXPECT_TRUE(a->closed_by_daemon(2000));
    EXPECT_EQ(roundtrip(*b->s, 0.f).size(), 1u);
    auto e = Raw::connect(d->socket_path());
    ASSERT_TRUE(e);
    EXPECT_EQ(e->hello().status, FGSR_STATUS_BUSY) << "c is not idle for a second yet, b has a session";
}

// Runs fgsrd with `args` and `env` expecting it to refuse to start; returns its stderr.
std::string refused_start(const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
    char dir[] = "/tmp/fgsrd-refuse-XXXXXX";
    EXPECT_NE(mkdtemp(dir), nullptr);
    const std::string log = std::string(dir) + "/stderr.log";
    std::vector<std::string> argv = {std::string(FGSR_BIN_DIR) + "/fgsrd"};
    argv.insert(argv.end(), args.begin(), args.end());
    const pid_t pid = FgsrdProcess::spawn(argv, log, env);
    int status = 0;
    for (int i = 0; i < 600 && waitpid(pid, &status, WNOHANG) == 0; ++i) usleep(50000);
    if (kill(pid, 0) == 0) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        ADD_FAILURE() << "fgsrd started";
    }
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << status;
    std::ifstream f(log);
    std::stringstream ss;
    ss << f.rdbuf();
    std::filesystem::remove_all(dir);
    return ss.str();
}

// Attack 4: a regular file or a symlink where the socket would go is never replaced.
TEST(DaemonHostile, AFileOrSymlinkAtTheSocketPathIsNotReplaced) {
    char dir[] = "/tmp/fgsrd-stale-XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    const std::string file = std::string(dir) + "/precious", link = std::string(dir) + "/link";
    std::ofstream(file) << "do not lose me";
    ASSERT_EQ(symlink(file.c_str(), link.c_str()), 0);
    std::string err = refused_start({"--socket", file});
    EXPECT_NE(err.find("is not a socket (a regular file)"), std::string::npos) << err;
    err = refused_start({"--socket", link});
    EXPECT_NE(err.find("is not a socket (a symbolic link)"), std::string::npos) << err;
    std::ifstream in(file);
    std::string content;
    std::getline(in, content);
    EXPECT_EQ(content, "do not lose me");
    struct stat st {};
    ASSERT_EQ(lstat(link.c_str(), &st), 0);
    EXPECT_TRUE(S_ISLNK(st.st_mode));
    std::filesystem::remove_all(dir);
}

// Attack 6b: a runtime directory others can write is refused, not used silently.
TEST(DaemonHostile, AWorldWritableRuntimeDirectoryIsRefused) {
    char dir[] = "/tmp/fgsrd-xdg-XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    const std::string sub = std::string(dir) + "/fgsr";
    ASSERT_EQ(mkdir(sub.c_str(), 0700), 0);
    ASSERT_EQ(chmod(sub.c_str(), 0777), 0);
    const std::string err = refused_start({}, {"XDG_RUNTIME_DIR=" + std::string(dir)});
    EXPECT_NE(err.find("refusing to use"), std::string::npos) << err;
    EXPECT_NE(err.find("mode 0777"), std::string::npos) << err;
    std::filesystem::remove_all(dir);
}

// Attack 5: a HELLO name with a newline and terminal escapes cannot forge log lines.
TEST(DaemonHostile, ClientNamesCannotForgeLogLines) {
    auto d = FgsrdProcess::start({"--log-level", "debug"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto raw = Raw::connect(d->socket_path());
    ASSERT_TRUE(raw);
    const fgsr_hello h = hello_message("evil\nfgsrd: error: forged\x1b[2J\xc2\x9b");
    ASSERT_TRUE(raw->send(&h, sizeof(h)));
    EXPECT_EQ(as<fgsr_hello_reply>(raw->recv()).status, FGSR_STATUS_OK);
    raw.reset();
    expect_responsive_and_stoppable(*d);
    const std::string err = d->stderr_text();
    EXPECT_NE(err.find("evil\\x0afgsrd: error: forged\\x1b[2J\\xc2\\x9b (pid"), std::string::npos) << err;
    EXPECT_EQ(err.find("\nfgsrd: error: forged"), std::string::npos);
    EXPECT_EQ(err.find('\x1b'), std::string::npos);
}

// Attack 6a: more than 16 fds on one message is named as such.
TEST(DaemonHostile, TooManyAttachedFdsAreNamedAsSuch) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto raw = Raw::connect(d->socket_path());
    ASSERT_TRUE(raw);
    fgsr_hello h = hello_message("fds");
    std::vector<int> fds(20, open("/dev/null", O_RDONLY | O_CLOEXEC));
    iovec iov{&h, sizeof(h)};
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    std::vector<char> control(CMSG_SPACE(sizeof(int) * fds.size()));
    m.msg_control = control.data();
    m.msg_controllen = control.size();
    cmsghdr* cm = CMSG_FIRSTHDR(&m);
    cm->cmsg_level = SOL_SOCKET;
    cm->cmsg_type = SCM_RIGHTS;
    cm->cmsg_len = CMSG_LEN(sizeof(int) * fds.size());
    std::memcpy(CMSG_DATA(cm), fds.data(), sizeof(int) * fds.size());
    ASSERT_EQ(sendmsg(raw->sock.fd, &m, MSG_NOSIGNAL), ssize_t(sizeof(h)));
    close(fds[0]);
    auto reply = as<fgsr_reply>(raw->recv());
    EXPECT_EQ(reply.status, FGSR_STATUS_PROTOCOL_ERROR);
    EXPECT_NE(std::string(reply.reason).find("more than 16 file descriptors"), std::string::npos)
        << reply.reason;
    expect_responsive_and_stoppable(*d);
}

} // namespace
} // namespace fgsr::test
