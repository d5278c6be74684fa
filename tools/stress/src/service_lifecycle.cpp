// Scenarios 5 and 6 of `fgsr stress --service`: clients killed with SIGKILL at every protocol
// state (the daemon's fd and mapping counts return to their baseline), and the daemon killed with
// SIGKILL and restarted on the same socket under running libfgsr_client clients (they see an
// error, not a hang, and reconnect).
#include "service_internal.hpp"

#include <fgsr/client.h>

#include <atomic>
#include <csignal>
#include <poll.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fgsr::stress::service {

namespace {

struct Usage {
    int fds = 0, maps = 0;
    long memfd_bytes = 0, rss_kib = 0;
};

Usage usage(const FgsrdProcess& d) {
    return {d.fd_count(), d.mapping_count(), d.memfd_mapped_bytes(), d.rss_kib()};
}

// Waits up to 10 s for the counts to equal `base` with no session memory mapped.
Usage settle(const FgsrdProcess& d, const Usage& base) {
    Usage u;
    for (int i = 0; i < 500; ++i) {
        u = usage(d);
        if (u.fds == base.fds && u.maps == base.maps && u.memfd_bytes == 0) break;
        usleep(20000);
    }
    return u;
}

// Waits until no session memory is mapped and the counts hold still for 100 ms.
Usage quiesce(const FgsrdProcess& d) {
    Usage u = usage(d);
    for (int i = 0; i < 100; ++i) {
        usleep(100000);
        const Usage v = usage(d);
        if (v.fds == u.fds && v.maps == u.maps && v.memfd_bytes == 0) return v;
        u = v;
    }
    return u;
}

enum class State { connected, hello, session, submitted, holding_outputs };
const char* state_name(State s) {
    switch (s) {
    case State::connected:
        return "connected";
    case State::hello:
        return "after-hello";
    case State::session:
        return "after-create-session";
    case State::submitted:
        return "frame-submitted";
    case State::holding_outputs:
        return "holding-output-slots";
    }
    return "?";
}

// A child process that reaches `state`, writes a byte to `ready` and waits to be killed.
pid_t spawn_client(const std::string& socket, State state, int ready) {
    const pid_t pid = fork();
    if (pid != 0) return pid;
    auto reached = [&] {
        const char b = 1;
        (void)!write(ready, &b, 1);
        for (;;) pause();
    };
    auto c = raw::Connection::connect(socket);
    if (!c) _exit(1);
    if (state == State::connected) reached();
    auto h = c->hello();
    if (!h || h->status != FGSR_STATUS_OK) _exit(1);
    if (state == State::hello) reached();
    fgsr_session_desc d = raw::small_desc(64, 64);
    d.output_slots = 4;
    auto s = raw::create_session(*c, d);
    if (!s) _exit(1);
    if (state == State::session) reached();
    raw::roundtrip(*s, 0, 0, 0, 30000); // a first frame, so that the next ones interpolate
    s->fill(1, 2);
    fgsr_submit_entry e = s->entry(1);
    e.interp_count = 3;
    for (uint32_t k = 0; k < 3; ++k) e.interp_alphas[k] = float(k + 1) / 4.f;
    s->push({e});
    if (state == State::submitted) reached();
    if (s->wait_submit(30000).size() < 3) _exit(1); // outputs held, never released
    reached();
    _exit(0);
}

} // namespace

void kill_nine_clients(Run& r) {
    if (!r.own_daemon_possible()) return r.skip("needs its own daemon (/proc counts)");
    if (!r.start()) return;
    FgsrdProcess& d = *r.daemon;
    // Warm up (driver caches, every pipeline variant), then the baseline.
    {
        std::string why;
        auto c = raw::open_client(r.socket(), raw::small_desc(64, 64), &why);
        if (!r.check(bool(c), "warm-up session: " + why)) return;
        for (uint32_t f = 0; f < 6; ++f)
            r.check(!raw::roundtrip(*c->session, float(std::min(f, 3u)), f % 3).empty(), "warm-up frame");
    }
    const Usage base = quiesce(d);
    r.result.metrics["baseline"] = {{"fds", base.fds}, {"maps", base.maps}, {"rss_kib", base.rss_kib}};
    int cycles = 0;
    for (State st :
         {State::connected, State::hello, State::session, State::submitted, State::holding_outputs}) {
        for (int round = 0; round < (r.opt.quick ? 1 : 3); ++round) {
            int p[2];
            if (!r.check(pipe2(p, O_CLOEXEC) == 0, "pipe")) return;
            const pid_t child = spawn_client(r.socket(), st, p[1]);
            close(p[1]);
            char b = 0;
            pollfd pf{p[0], POLLIN, 0};
            const bool ready = poll(&pf, 1, 30000) == 1 && read(p[0], &b, 1) == 1;
            close(p[0]);
            const Usage during = usage(d);
            kill(child, SIGKILL);
            int status = 0;
            waitpid(child, &status, 0);
            if (!r.check(ready, std::string("client did not reach state ") + state_name(st))) continue;
            const Usage after = settle(d, base);
            ++cycles;
            r.note(fmt::format("{}: fds {} -> {} -> {}, maps {} -> {} -> {}, rss {} -> {} KiB",
                               state_name(st), base.fds, during.fds, after.fds, base.maps, during.maps,
                               after.maps, base.rss_kib, after.rss_kib));
            nlohmann::json& m = r.result.metrics["states"][state_name(st)];
            m = {{"fds_during", during.fds},
                 {"fds_after", after.fds},
                 {"maps_during", during.maps},
                 {"maps_after", after.maps},
                 {"rss_after_kib", after.rss_kib}};
            r.check(after.fds == base.fds && after.maps == base.maps && after.memfd_bytes == 0,
                    fmt::format("{}: fds {} (baseline {}), maps {} (baseline {}), memfd bytes {}",
                                state_name(st), after.fds, base.fds, after.maps, base.maps,
                                after.memfd_bytes));
        }
    }
    const Usage end = usage(d);
    r.result.measured =
        fmt::format("{} kills at 5 states: fds back to {} and maps to {} each time; RSS {} -> {} KiB", cycles,
                    base.fds, base.maps, base.rss_kib, end.rss_kib);
    r.served("kill-9-clients");
}

namespace {

// A libfgsr_client client that runs frames until the daemon goes away, then reconnects.
struct RestartClient {
    std::atomic<uint32_t> frames_before{0}, frames_after{0};
    std::atomic<bool> saw_error{false}, reconnected{false}, hung{false};
    std::atomic<int32_t> error_status{0};
    std::atomic<uint64_t> error_ns{0};
    uint64_t epoch_before = 0, epoch_after = 0;
    std::string failure;
};

// Frames on one session until `stop` or an error; returns the first non-OK status (OK on stop).
// TIMEOUT is waited through for up to hang_ms (longer: `hung`).
fgsr_status run_frames(fgsr_session* s, std::atomic<uint32_t>& frames, const std::atomic<bool>& stop,
                       std::atomic<bool>& hung, uint32_t hang_ms) {
    for (uint32_t f = 0; !stop; ++f) {
        fgsr_input_slot in{};
        fgsr_status st = fgsr_acquire_input(s, 5000, &in);
        if (st != FGSR_STATUS_OK) return st;
        fgsr_submit_info si{};
        si.struct_size = sizeof(si);
        si.input_slot = in.index;
        const float alpha = 0.5f;
        si.interp_count = f == 0 ? 0 : 1;
        si.interp_alphas = &alpha;
        st = fgsr_submit(s, &si, nullptr);
        if (st != FGSR_STATUS_OK) return st;
        const uint64_t t0 = raw::now_ns();
        for (;;) {
            fgsr_output out{};
            st = fgsr_wait(s, 500, &out);
            if (st == FGSR_STATUS_TIMEOUT) {
                if (raw::ms_since(t0) > hang_ms) {
                    hung = true;
                    return st;
                }
                if (stop) return FGSR_STATUS_OK;
                continue;
            }
            if (st != FGSR_STATUS_OK) return st;
            if (out.output_slot != FGSR_NO_SLOT) fgsr_release_output(s, out.output_slot);
            if (out.flags & FGSR_COMPLETION_LAST) break;
        }
        ++frames;
        usleep(10000);
    }
    return FGSR_STATUS_OK;
}

struct Connected {
    fgsr_connection* c = nullptr;
    fgsr_session* s = nullptr;
    uint64_t epoch = 0;
    ~Connected() {
        if (s) fgsr_session_destroy(s);
        if (c) fgsr_disconnect(c);
    }
};

fgsr_status connect_session(const std::string& socket, Connected& k) {
    fgsr_connect_info ci{};
    ci.struct_size = sizeof(ci);
    ci.socket_path = socket.c_str();
    ci.client_name = "fgsr-stress-restart";
    ci.timeout_ms = 2000;
    fgsr_status st = fgsr_connect(&ci, &k.c);
    if (st != FGSR_STATUS_OK) return st;
    fgsr_daemon_info info{};
    fgsr_daemon_info_get(k.c, &info);
    k.epoch = info.epoch;
    fgsr_session_desc d = raw::small_desc(64, 64);
    return fgsr_session_create(k.c, &d, &k.s);
}

} // namespace

void daemon_restart(Run& r) {
    if (!r.own_daemon_possible()) return r.skip("needs its own daemon (kill -9 and restart)");
    if (!r.start()) return;
    constexpr int kClients = 3;
    constexpr uint32_t kHangMs = 5000;
    std::vector<std::unique_ptr<RestartClient>> clients;
    std::vector<std::thread> threads;
    std::atomic<bool> restarted{false}, stop{false};
    const std::string socket = r.socket();
    for (int i = 0; i < kClients; ++i) {
        clients.push_back(std::make_unique<RestartClient>());
        threads.emplace_back([&, cl = clients.back().get()] {
            {
                Connected k;
                fgsr_status st = connect_session(socket, k);
                if (st != FGSR_STATUS_OK) {
                    cl->failure = std::string("first session: ") + fgsr_status_string(st);
                    return;
                }
                cl->epoch_before = k.epoch;
                st = run_frames(k.s, cl->frames_before, stop, cl->hung, kHangMs);
                cl->error_status = st;
                cl->error_ns = raw::now_ns();
                cl->saw_error = st != FGSR_STATUS_OK;
            }
            while (!restarted && !stop) usleep(20000);
            const uint64_t t0 = raw::now_ns();
            while (!stop && raw::ms_since(t0) < 30000) {
                Connected k;
                if (connect_session(socket, k) != FGSR_STATUS_OK) {
                    usleep(100000);
                    continue;
                }
                cl->epoch_after = k.epoch;
                cl->reconnected = true;
                std::atomic<bool> enough{false};
                std::thread limit([&] {
                    while (cl->frames_after < 5 && !stop) usleep(10000);
                    enough = true;
                });
                run_frames(k.s, cl->frames_after, enough, cl->hung, kHangMs);
                limit.join();
                break;
            }
        });
    }
    // Every client running frames, then SIGKILL.
    const uint64_t t0 = raw::now_ns();
    auto all = [&](auto pred) {
        for (auto& c : clients)
            if (!pred(*c)) return false;
        return true;
    };
    while (!all([](RestartClient& c) { return c.frames_before >= 3 || !c.failure.empty(); }) &&
           raw::ms_since(t0) < 30000)
        usleep(20000);
    const uint64_t kill_ns = raw::now_ns();
    r.daemon->kill9();
    while (!all([](RestartClient& c) { return c.saw_error || c.hung || !c.failure.empty(); }) &&
           raw::ms_since(kill_ns) < 15000)
        usleep(10000);
    const bool back = r.daemon->restart();
    r.check(back, "restart: " + FgsrdProcess::last_error());
    restarted = true;
    const uint64_t t1 = raw::now_ns();
    while (!all([](RestartClient& c) { return c.frames_after >= 5 || !c.failure.empty(); }) &&
           raw::ms_since(t1) < 40000)
        usleep(20000);
    stop = true;
    for (auto& t : threads) t.join();
    double worst_error_ms = 0;
    for (int i = 0; i < kClients; ++i) {
        RestartClient& c = *clients[size_t(i)];
        const double error_ms = c.saw_error ? double(c.error_ns - kill_ns) * 1e-6 : -1;
        worst_error_ms = std::max(worst_error_ms, error_ms);
        r.result.metrics["clients"].push_back({{"frames_before", c.frames_before.load()},
                                               {"error", fgsr_status_string(c.error_status)},
                                               {"error_after_kill_ms", error_ms},
                                               {"reconnected", c.reconnected.load()},
                                               {"frames_after", c.frames_after.load()},
                                               {"new_epoch", c.epoch_after != c.epoch_before}});
        r.note(fmt::format(
            "client {}: {} frames, then {} {:.0f} ms after the kill; reconnected {}, {} frames after", i,
            c.frames_before.load(), fgsr_status_string(c.error_status), error_ms,
            c.reconnected.load() ? "yes" : "no", c.frames_after.load()));
        r.check(c.failure.empty(), fmt::format("client {}: {}", i, c.failure));
        r.check(!c.hung, fmt::format("client {}: hung (only TIMEOUT for {} ms)", i, kHangMs));
        r.check(c.saw_error, fmt::format("client {}: saw no error after the daemon was killed", i));
        r.check(c.reconnected && c.frames_after >= 5,
                fmt::format("client {}: did not continue after the restart", i));
        r.check(c.epoch_after != c.epoch_before, fmt::format("client {}: same epoch after the restart", i));
    }
    r.result.measured =
        fmt::format("{} libfgsr_client clients: error within {:.0f} ms of SIGKILL, reconnected and "
                    "ran 5 frames each on the restarted daemon (new epoch)",
                    kClients, worst_error_ms);
    if (back) r.served("daemon-restart");
}

} // namespace fgsr::stress::service
