// Scenarios 1 and 2 of `fgsr stress --service`: the hostile client (malformed messages, fd games,
// hostile ring entries, bytes flipped in shared memory while frames run) and the flag attack on
// the session eventfds. After each attack the daemon must answer a fresh HELLO within 100 ms and
// serve a well-behaved client; the attacker gets an error or is disconnected.
#include "service_internal.hpp"

#include <atomic>
#include <cstring>
#include <fcntl.h>
#include <random>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fgsr::stress::service {

namespace {

// The attacker was refused: an ERROR message or a closed connection.
bool refused(const std::string& event) {
    return event.rfind("error", 0) == 0 || event == "closed";
}

// One attack on the control socket: connect, `act`, then what the daemon did.
void socket_attack(Run& r, const std::string& name, const std::function<bool(const raw::Connection&)>& act) {
    std::string why;
    auto c = raw::Connection::connect(r.socket(), &why);
    if (!r.check(bool(c), name + ": connect: " + why)) return;
    if (!r.check(act(*c), name + ": sending the attack failed")) return;
    const std::string event = c->next_event(5000);
    r.result.metrics["attacks"][name] = event;
    r.note(name + " -> " + event);
    r.check(refused(event), name + ": expected an error or a disconnect, got '" + event + "'");
    r.served(name);
}

bool send_hello_with_fds(const raw::Connection& c, int count) {
    fgsr_hello h{};
    h.header = fgsr_msg_header_for(FGSR_MSG_HELLO, sizeof(h), 1);
    h.major = FGSR_PROTOCOL_MAJOR;
    h.minor = FGSR_PROTOCOL_MINOR;
    const int fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
    const std::vector<int> fds(size_t(count), fd);
    const bool ok = c.send(&h, sizeof(h), fds);
    close(fd);
    return ok;
}

// One attack through a session's rings: open a session, `act` on it, then what happened: the
// connection's next event, or the status of the submit's completion.
void ring_attack(Run& r, const std::string& name, const std::function<void(raw::Session&)>& act) {
    std::string why;
    auto a = raw::open_client(r.socket(), raw::small_desc(64, 64), &why);
    if (!r.check(bool(a), name + ": attacker session: " + why)) return;
    act(*a->session);
    std::string event = a->conn.next_event(3000);
    if (event.empty()) { // still connected: the submit must have been rejected with a status
        auto c = a->session->wait(2000);
        event = c ? std::string("completion ") + fgsr_status_string(c->status) : "nothing";
        r.check(c && c->status != FGSR_STATUS_OK, name + ": expected a rejection, got " + event);
    } else {
        r.check(refused(event), name + ": expected an error or a disconnect, got '" + event + "'");
    }
    r.result.metrics["attacks"][name] = event;
    r.note(name + " -> " + event);
    r.served(name);
}

// Frames run back to back in one session while another thread flips random bytes in its input
// slots, its ring entries and now and then a ring position.
void flip_attack(Run& r, double seconds) {
    std::string why;
    auto a = raw::open_client(r.socket(), raw::small_desc(64, 64), &why);
    if (!r.check(bool(a), "flip: attacker session: " + why)) return;
    raw::Session& s = *a->session;
    std::atomic<bool> stop{false};
    std::atomic<uint64_t> flips{0};
    std::thread scribbler([&] {
        std::mt19937_64 rng(15);
        const fgsr_pool_layout& l = s.layout();
        const fgsr_rings_layout& rl = s.rings_layout();
        const uint64_t input_bytes = l.input_pool_size, ring_bytes = rl.total_size;
        while (!stop) {
            const uint64_t pick = rng() % 16;
            if (pick < 10) { // an input byte
                s.input_slot(0)[rng() % input_bytes] ^= std::byte(1u << (rng() % 8));
            } else if (pick < 15) { // a ring byte (entries and positions alike)
                s.rings()[rng() % ring_bytes] ^= std::byte(1u << (rng() % 8));
            } else { // a submit entry's slot index out of range
                auto* e = reinterpret_cast<fgsr_submit_entry*>(s.rings() + rl.submit_entries);
                e[rng() % l.ring_capacity].input_slot = uint32_t(rng());
            }
            ++flips;
            if (flips % 64 == 0) usleep(200);
        }
    });
    const uint64_t t0 = raw::now_ns();
    uint32_t frames = 0, completed = 0;
    bool dropped = false;
    while (raw::ms_since(t0) < seconds * 1000) {
        auto v = raw::roundtrip(s, float(frames), frames % 3, 1, 3000);
        ++frames;
        completed += v.empty() ? 0 : 1;
        if (a->conn.next_event(0) == "closed" || (v.empty() && a->conn.closed_by_daemon(500))) {
            dropped = true;
            break;
        }
    }
    stop = true;
    scribbler.join();
    r.result.metrics["flip"] = {{"submits", frames},
                                {"completed", completed},
                                {"flips", flips.load()},
                                {"attacker_dropped", dropped}};
    r.note(fmt::format("flip: {} bytes flipped, {} submits, {} completed, attacker {}", flips.load(), frames,
                       completed, dropped ? "dropped" : "still connected"));
    r.served("flip");
}

} // namespace

void hostile_client(Run& r) {
    if (!r.start()) return;
    socket_attack(r, "garbage", [](const raw::Connection& c) {
        std::mt19937 rng(1);
        std::vector<uint8_t> junk(200);
        for (auto& b : junk) b = uint8_t(rng());
        return c.send(junk.data(), junk.size());
    });
    socket_attack(r, "truncated-header", [](const raw::Connection& c) {
        const fgsr_msg_header h = fgsr_msg_header_for(FGSR_MSG_HELLO, sizeof(fgsr_hello), 1);
        return c.send(&h, 10);
    });
    socket_attack(r, "truncated-hello", [](const raw::Connection& c) {
        fgsr_hello h{};
        h.header = fgsr_msg_header_for(FGSR_MSG_HELLO, 30, 1);
        return c.send(&h, 30);
    });
    socket_attack(r, "oversized", [](const raw::Connection& c) {
        std::vector<std::byte> big(FGSR_MAX_MESSAGE_SIZE * 2);
        const fgsr_msg_header h = fgsr_msg_header_for(FGSR_MSG_HELLO, uint32_t(big.size()), 1);
        std::memcpy(big.data(), &h, sizeof(h));
        return c.send(big.data(), big.size());
    });
    socket_attack(r, "wrong-magic", [](const raw::Connection& c) {
        fgsr_hello h{};
        h.header = fgsr_msg_header_for(FGSR_MSG_HELLO, sizeof(h), 1);
        h.header.magic = 0xdeadbeef;
        h.major = FGSR_PROTOCOL_MAJOR;
        return c.send(&h, sizeof(h));
    });
    socket_attack(r, "before-hello", [](const raw::Connection& c) {
        fgsr_create_session m{};
        m.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION, sizeof(m), 1);
        m.desc = raw::small_desc(64, 64);
        return c.send(&m, sizeof(m));
    });
    socket_attack(r, "one-fd", [](const raw::Connection& c) { return send_hello_with_fds(c, 1); });
    socket_attack(r, "twenty-fds", [](const raw::Connection& c) { return send_hello_with_fds(c, 20); });
    ring_attack(r, "input-slot-out-of-range", [](raw::Session& s) {
        s.fill(0, 0);
        fgsr_submit_entry e = s.entry(0);
        e.input_slot = 1000;
        s.push({e});
    });
    ring_attack(r, "submit-head-out-of-range",
                [](raw::Session& s) { s.publish_submit_head(s.submit_head + s.layout().ring_capacity + 7); });
    ring_attack(r, "release-slot-out-of-range", [](raw::Session& s) { s.release(1000); });
    ring_attack(r, "release-of-unheld-slot", [](raw::Session& s) { s.release(0); });
    ring_attack(r, "sequence-going-back", [](raw::Session& s) {
        raw::roundtrip(s, 0, 0, 0, 10000);
        s.fill(1, 1);
        fgsr_submit_entry e = s.entry(1);
        e.sequence = 1;
        s.push({e});
    });
    flip_attack(r, r.opt.quick ? 2.0 : 6.0);
    const size_t attacks = r.result.metrics["attacks"].size() + 1;
    r.result.measured = fmt::format(
        "{} attacks, attacker refused in each; worst fresh HELLO after them {:.1f} ms", attacks, [&] {
            double w = 0;
            for (auto& [k, v] : r.result.metrics["hello_after_ms"].items()) w = std::max(w, v.get<double>());
            return w;
        }());
}

void flag_attack(Run& r) {
    if (!r.start()) return;
    std::string why;
    // (a) O_NONBLOCK cleared on the submit eventfd, then signal: the daemon never reads it.
    {
        auto a = raw::open_client(r.socket(), raw::small_desc(64, 64), &why);
        if (!r.check(bool(a), "attacker session: " + why)) return;
        const int efd = a->session->fd(FGSR_FD_SUBMIT_EVENT);
        r.check(fcntl(efd, F_SETFL, fcntl(efd, F_GETFL) & ~O_NONBLOCK) == 0, "fcntl on the submit eventfd");
        const auto v1 = raw::roundtrip(*a->session, 0, 0);
        const auto v2 = raw::roundtrip(*a->session, 1, 1);
        r.note(fmt::format("blocking submit eventfd: attacker's own frames {} and {} completions", v1.size(),
                           v2.size()));
        r.served("submit-eventfd-blocking");
    }
    // (b) O_NONBLOCK cleared on the complete eventfd and its counter at 2^64-2, then submit: the
    // daemon's write would block; it must drop the attacker instead.
    {
        auto a = raw::open_client(r.socket(), raw::small_desc(64, 64), &why);
        if (!r.check(bool(a), "attacker session: " + why)) return;
        const int efd = a->session->fd(FGSR_FD_COMPLETE_EVENT);
        r.check(fcntl(efd, F_SETFL, fcntl(efd, F_GETFL) & ~O_NONBLOCK) == 0, "fcntl on the complete eventfd");
        const uint64_t full = 0xfffffffffffffffeull;
        r.check(write(efd, &full, 8) == 8, "filling the complete eventfd");
        a->session->fill(0, 0);
        a->session->push({a->session->entry(0)});
        const uint64_t t0 = raw::now_ns();
        const bool dropped = a->conn.closed_by_daemon(10000);
        r.result.metrics["attacker_dropped_after_ms"] = dropped ? raw::ms_since(t0) : -1.0;
        r.check(dropped, "the attacker with a blocking, full complete eventfd was not dropped");
        r.served("complete-eventfd-full");
    }
    if (!r.daemon) {
        r.result.measured = "attacker dropped; SIGTERM not tried (not our daemon)";
        return;
    }
    const uint64_t t0 = raw::now_ns();
    const int st = r.daemon->terminate(5000);
    const double ms = raw::ms_since(t0);
    r.result.metrics["sigterm_ms"] = ms;
    r.check(WIFEXITED(st) && WEXITSTATUS(st) == 0,
            fmt::format("SIGTERM: wait status {} after {:.0f} ms", st, ms));
    double worst = 0;
    for (auto& [k, v] : r.result.metrics["hello_after_ms"].items()) worst = std::max(worst, v.get<double>());
    r.result.measured =
        fmt::format("attacker dropped after {:.0f} ms; worst fresh HELLO {:.1f} ms; SIGTERM exit in "
                    "{:.0f} ms",
                    r.result.metrics["attacker_dropped_after_ms"].get<double>(), worst, ms);
}

} // namespace fgsr::stress::service
