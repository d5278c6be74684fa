// Scheduling. One thread (this file) does all I/O: epoll over the listening socket, the signalfd,
// every client socket, every session's submit eventfd (edge-triggered, never read: see
// session.hpp) and a private eventfd the lanes signal. Engine calls run on lanes (lane.hpp): the
// interactive lane for sessions up to --interactive-pixels, the bulk lane (started on the first
// larger session, at lower CPU priority) for the rest. Each lane runs one frame at a time; when a
// lane is free the server starts the ready session of that lane that has used the least engine
// time (start-time fair queueing: a session's share of the lane does not depend on its frame
// size, a session that was idle does not bank credit). The server's thread never waits for the
// device, so HELLO, STATS, destruction and other lanes' completions are served while a frame
// runs; what bounds their latency is the loop's own work (ring copies, one completion batch) and
// the CPU share the server's thread gets, not frame times. A session that waits for output slots
// or completion-ring room is not ready and is skipped. After a round that handled events, while no
// lane runs a frame, the loop polls for the next event for up to --spin-us before it sleeps (a
// client's next submit that comes within it needs no wake-up); an idle daemon does not spin.
#include "server.hpp"

#include "listen.hpp"
#include "log.hpp"
#include "server_internal.hpp"

#include <fgsr/engine/engine.hpp>
#include <fgsr/ipc/socket.hpp>
#include <fgsr/ipc/spin.hpp>
#include <fgsr/wire.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <pthread.h>
#include <random>
#include <span>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

namespace fgsrd {

namespace detail {

namespace {

// The executable's name as the kernel keeps it (/proc/<pid>/comm), escaped for logs and pages;
// empty when it cannot be read (another pid namespace, the process already gone).
std::string process_name(pid_t pid) {
    char path[64];
    std::snprintf(path, sizeof(path), "/proc/%d/comm", int(pid));
    FILE* f = std::fopen(path, "re");
    if (!f) return {};
    char name[64] = {};
    const size_t n = std::fread(name, 1, sizeof(name) - 1, f);
    std::fclose(f);
    std::string s(name, n);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\0')) s.pop_back();
    return log::printable(s);
}

} // namespace

Server::~Server() {
    drain(UINT64_MAX);
    for (LaneState& l : lanes_) l.lane.reset();
    if (!created_socket_.empty()) unlink(created_socket_.c_str());
}

bool Server::drain(uint64_t timeout_ns) {
    // Every session is destroyed on its lane, before the lane's engine: drop the clients, then
    // run continuations (a creation that finishes for a dropped client posts its destruction)
    // until the lanes are idle and nothing is queued for this thread (a lane delivers a job's
    // continuation before it reads as idle, and continuations run here may post new jobs).
    while (!clients_.empty()) drop_client(clients_.begin()->first, nullptr);
    const uint64_t start = monotonic_ns();
    for (;;) {
        run_continuations();
        if (lanes_idle()) {
            std::lock_guard lock(done_mutex_);
            if (done_.empty()) return true;
        } else if (monotonic_ns() - start >= timeout_ns) {
            return false;
        } else {
            usleep(1000);
        }
    }
}

Lane* Server::lane(int index) {
    LaneState& l = lanes_[size_t(index)];
    if (!l.lane) {
        // The bulk lane starts on the first large session; its engine is created on its thread,
        // so the jobs posted meanwhile simply wait for it.
        auto made = Lane::start(Lane::Config{"bulk", opt_.device, opt_.bulk_nice}, deliver(), false);
        l.lane = std::move(*made); // cannot fail without waiting
        log::info("bulk lane started (sessions above {} pixels; nice +{})", opt_.interactive_pixels,
                  opt_.bulk_nice);
    }
    return l.lane.get();
}

bool Server::lanes_idle() const {
    for (const LaneState& l : lanes_)
        if (l.lane && !l.lane->idle()) return false;
    return true;
}

void Server::run_continuations() {
    uint64_t counter = 0;
    (void)!read(lanes_event_.get(), &counter, sizeof(counter));
    for (;;) {
        Lane::Continuation c;
        {
            std::lock_guard lock(done_mutex_);
            if (done_.empty()) return;
            c = std::move(done_.front());
            done_.pop_front();
        }
        c();
    }
}

bool Server::send_reply(Client& c, const void* msg, size_t size, const int* fds, size_t nfds) {
    const ssize_t n = fgsr::ipc::send_with_fds(c.fd.get(), msg, size, fds, nfds, MSG_DONTWAIT);
    if (n != ssize_t(size)) {
        log::warn("client {} ({}): reply not sent ({}); dropping it", c.id, c.name,
                  n < 0 ? std::strerror(errno) : "short write");
        return false;
    }
    return true;
}

void Server::violation(Client& c, uint32_t sequence, const std::string& reason) {
    log::warn("client {} ({}): protocol violation: {}; disconnecting it", c.id, c.name, reason);
    fgsr_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_ERROR, sizeof(r), sequence);
    r.status = FGSR_STATUS_PROTOCOL_ERROR;
    copy_reason(r.reason, sizeof(r.reason), reason);
    send_reply(c, &r, sizeof(r));
    drop_client(c.id, nullptr);
}

void Server::drop_client(uint64_t id, const char* why) {
    auto it = clients_.find(id);
    if (it == clients_.end()) return;
    Client& c = *it->second;
    if (why) log::info("client {} ({}): {}", c.id, c.name, why);
    while (!c.sessions.empty()) destroy_session(c, c.sessions.begin()->first);
    epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, c.fd.get(), nullptr);
    clients_.erase(it);
}

void Server::destroy_session(Client& c, uint32_t session_id) {
    auto it = c.sessions.find(session_id);
    if (it == c.sessions.end()) return;
    // The client holds other fds of the same eventfd: remove the registration explicitly.
    epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, it->second->submit_event_fd(), nullptr);
    const fgsr_session_stats st = it->second->stats();
    log::info("session {} of client {} destroyed ({} frames, {} outputs, {} dropped, {} rejected)",
              session_id, c.id, st.frames_submitted, st.outputs_written, st.frames_dropped,
              st.frames_rejected);
    const SessionRef ref = session_owner_.at(session_id);
    memory_ -= ref.memory;
    if (hub_) hub_->session_closed(session_id);
    session_owner_.erase(session_id);
    // Destroyed on its lane, after a frame it may be running (jobs run in order).
    std::shared_ptr<ServiceSession> doomed(std::move(it->second));
    c.sessions.erase(it);
    lane(ref.lane)->post([doomed](fgsr::Engine*) mutable {
        doomed.reset();
        return Lane::Continuation{};
    });
}

void Server::accept_clients() {
    for (;;) {
        UniqueFd fd(accept4(listen_.get(), nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK));
        if (!fd) {
            if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
                log::warn("accept: {}", std::strerror(errno));
            return;
        }
        ucred cred{};
        socklen_t len = sizeof(cred);
        if (getsockopt(fd.get(), SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0) {
            log::warn("SO_PEERCRED: {}", std::strerror(errno));
            continue;
        }
        auto c = std::make_unique<Client>();
        c->id = next_client_++;
        c->uid = cred.uid;
        c->pid = cred.pid;
        c->name = "pid " + std::to_string(cred.pid);
        c->application = process_name(cred.pid);
        epoll_event ev{};
        ev.events = EPOLLIN | EPOLLRDHUP;
        ev.data.u64 = tag(kClient, c->id);
        if (epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd.get(), &ev) != 0) {
            log::warn("epoll_ctl: {}", std::strerror(errno));
            continue;
        }
        c->fd = std::move(fd);
        c->connected_ns = monotonic_ns();
        log::debug("client {} connected (pid {}, uid {})", c->id, cred.pid, cred.uid);
        clients_[c->id] = std::move(c);
        // Ids grow with connection time, so the first pending client in the map is the oldest.
        size_t pending = 0;
        uint64_t oldest = 0;
        for (const auto& [cid, cl] : clients_)
            if (!cl->hello_done && pending++ == 0) oldest = cid;
        if (pending > opt_.max_pending)
            drop_client(oldest, "too many connections without HELLO (this was the oldest)");
    }
}

int Server::expire_connections() {
    const uint64_t now = monotonic_ns();
    const uint64_t hello_limit = uint64_t(opt_.hello_timeout_s * 1e9);
    const uint64_t idle_limit = uint64_t(opt_.idle_timeout_s * 1e9);
    std::vector<uint64_t> late, idle;
    uint64_t next = UINT64_MAX;
    for (const auto& [cid, c] : clients_) {
        if (!c->hello_done) {
            const uint64_t deadline = c->connected_ns + hello_limit;
            if (deadline <= now)
                late.push_back(cid);
            else
                next = std::min(next, deadline);
            continue;
        }
        bool working = c->creating > 0;
        for (const auto& [sid, sess] : c->sessions) working |= sess->has_work();
        if (working) continue;
        const uint64_t deadline = c->active_ns + idle_limit;
        if (deadline <= now)
            idle.push_back(cid);
        else
            next = std::min(next, deadline);
    }
    for (uint64_t cid : late) drop_client(cid, "no HELLO in time");
    for (uint64_t cid : idle)
        drop_client(
            cid, fmt::format("idle for {:g} s (--idle-timeout); disconnected", opt_.idle_timeout_s).c_str());
    return next == UINT64_MAX ? -1 : int(std::min<uint64_t>((next - now) / 1000000 + 1, 60000));
}

bool Server::evict_idle_client() {
    const uint64_t now = monotonic_ns();
    uint64_t victim = 0, oldest = UINT64_MAX;
    for (const auto& [cid, c] : clients_)
        if (c->hello_done && c->sessions.empty() && c->creating == 0 && c->active_ns + 1'000'000'000 <= now &&
            c->active_ns < oldest) {
            oldest = c->active_ns;
            victim = cid;
        }
    if (victim == 0) return false;
    drop_client(victim, "evicted: idle without sessions while the daemon was full");
    return true;
}

void Server::on_client(uint64_t id, uint32_t events) {
    // Messages first (a client may send and close), then hang-ups.
    alignas(16) std::byte buf[FGSR_MAX_MESSAGE_SIZE];
    for (;;) {
        auto it = clients_.find(id);
        if (it == clients_.end()) return;
        Client& c = *it->second;
        // Any fd a client sends is closed at once (when `received` goes); sending one is a violation.
        std::vector<UniqueFd> received;
        const ssize_t n = fgsr::ipc::recv_with_fds(c.fd.get(), buf, sizeof(buf), received, MSG_DONTWAIT);
        if (n < 0 && errno == EMSGSIZE) {
            violation(c, 0, "message larger than " + std::to_string(FGSR_MAX_MESSAGE_SIZE) + " bytes");
            return;
        }
        if (n < 0 && errno == EPROTO) {
            violation(c, 0,
                      "more than " + std::to_string(fgsr::ipc::kMaxPacketFds) +
                          " file descriptors attached (clients must not send any)");
            return;
        }
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK) break;
            drop_client(id, "socket error; disconnected");
            return;
        }
        if (n == 0) {
            drop_client(id, "disconnected");
            return;
        }
        if (!received.empty()) {
            violation(c, 0, "clients must not send file descriptors");
            return;
        }
        c.active_ns = monotonic_ns();
        if (!handle_message(c, buf, size_t(n))) return;
    }
    if (events & (EPOLLHUP | EPOLLRDHUP | EPOLLERR)) drop_client(id, "hung up");
}

bool Server::handle_message(Client& c, const std::byte* data, size_t size) {
    const Request request = parse_request(data, size, c.hello_done);
    if (const auto* v = std::get_if<Violation>(&request)) {
        violation(c, v->sequence, v->reason);
        return false;
    }
    if (const auto* create = std::get_if<CreateRequest>(&request)) return create_session(c, *create);
    if (const auto* session = std::get_if<SessionRequest>(&request)) return session_request(c, *session);
    if (const auto* rep = std::get_if<ReportRequest>(&request)) {
        report(c, *rep);
        return true;
    }
    if (const auto* probe = std::get_if<ProbeRequest>(&request)) {
        if (hub_) {
            const size_t kept = hub_->probe_samples(std::span<const fgsr_probe_sample>(probe->samples, probe->count));
            log::debug("client {} ({}): {} probe samples, {} kept", c.id, c.name, probe->count, kept);
        }
        return true;
    }
    const fgsr_hello& hello = std::get<HelloRequest>(request).hello;
    const uint32_t sequence = hello.header.sequence;
    // Kept escaped: it reaches logs and telemetry, and must not forge lines there.
    c.name = log::printable(hello.name) + " (pid " + std::to_string(c.pid) + ")";
    fgsr_hello_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_HELLO_REPLY, sizeof(r), sequence);
    r.major = FGSR_PROTOCOL_MAJOR;
    r.minor = FGSR_PROTOCOL_MINOR;
    r.capabilities = caps_;
    r.epoch = epoch_;
    copy_reason(r.device, sizeof(r.device), lanes_[kInteractive].lane->device_name());
    r.status = FGSR_STATUS_OK;
    if (hello.major != FGSR_PROTOCOL_MAJOR)
        r.status = FGSR_STATUS_VERSION_MISMATCH;
    else if (!opt_.allow_any_user && c.uid != getuid())
        r.status = FGSR_STATUS_PERMISSION_DENIED;
    else if (served_clients(c.uid, false) >= opt_.max_clients_per_uid)
        r.status = FGSR_STATUS_BUSY; // per uid: with --allow-any-user no user takes every place
    else if (served_clients(0, true) >= opt_.max_clients && !evict_idle_client())
        r.status = FGSR_STATUS_BUSY; // counted at HELLO: probes and half-open sockets do not count
    if (r.status != FGSR_STATUS_OK) {
        log::info("client {} ({}): refused: {} (client protocol {}.{}, uid {})", c.id, c.name,
                  fgsr_status_string(r.status), hello.major, hello.minor, c.uid);
        send_reply(c, &r, sizeof(r));
        drop_client(c.id, nullptr);
        return false;
    }
    c.hello_done = true;
    log::info("client {} ({}) connected, protocol {}.{}", c.id, c.name, hello.major, hello.minor);
    if (!send_reply(c, &r, sizeof(r))) {
        drop_client(c.id, nullptr);
        return false;
    }
    return true;
}

void Server::report(Client& c, const ReportRequest& request) {
    if (!hub_) return;
    if (c.sessions.find(request.session_id) == c.sessions.end()) {
        log::debug("client {} ({}): reports for session {}, which it does not own: ignored", c.id, c.name,
                   request.session_id);
        return;
    }
    hub_->reports(request.session_id, std::span<const fgsr_present_report>(request.reports, request.count));
}

bool Server::start_http(const std::string& device) {
    if (opt_.http_address.empty()) return true;
    HubOptions ho;
    ho.window_s = opt_.telemetry_window_s;
    ho.title = "fgsrd on " + device;
    hub_ = std::make_unique<TelemetryHub>(ho);
    HttpOptions h;
    h.address = opt_.http_address;
    h.allow_remote = opt_.http_allow_remote;
    h.trace_seconds = opt_.trace_seconds;
    auto server = HttpServer::start(h, *hub_);
    if (!server) {
        log::error("{}", server.error().message);
        return false;
    }
    http_ = std::move(*server);
    log::info("dashboard at {}", http_->url());
    // On stdout as well, for whoever started the daemon (and tests that ask for port 0).
    std::printf("fgsrd: dashboard at %s\n", http_->url().c_str());
    std::fflush(stdout);
    return true;
}

bool Server::session_request(Client& c, const SessionRequest& request) {
    const fgsr_session_ref& ref = request.ref;
    const uint32_t sequence = ref.header.sequence;
    auto it = c.sessions.find(ref.session_id);
    if (request.type == FGSR_MSG_STATS) {
        fgsr_stats_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_STATS_REPLY, sizeof(r), sequence);
        r.session_id = ref.session_id;
        r.status = it == c.sessions.end() ? FGSR_STATUS_INVALID_ARGUMENT : FGSR_STATUS_OK;
        if (it != c.sessions.end()) r.stats = it->second->stats();
        if (!send_reply(c, &r, sizeof(r))) {
            drop_client(c.id, nullptr);
            return false;
        }
        return true;
    }
    fgsr_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_DESTROY_SESSION_REPLY, sizeof(r), sequence);
    r.session_id = ref.session_id;
    r.status = it == c.sessions.end() ? FGSR_STATUS_INVALID_ARGUMENT : FGSR_STATUS_OK;
    if (it == c.sessions.end())
        copy_reason(r.reason, sizeof(r.reason), "no such session on this connection");
    else
        destroy_session(c, ref.session_id);
    if (!send_reply(c, &r, sizeof(r))) {
        drop_client(c.id, nullptr);
        return false;
    }
    return true;
}

int Server::run() {
    // Blocked before any thread starts (lanes and driver threads inherit the mask): otherwise the
    // kernel may deliver SIGTERM to a driver thread and kill the process without a clean shutdown.
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGTERM);
    sigaddset(&mask, SIGINT);
    pthread_sigmask(SIG_BLOCK, &mask, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
    lanes_event_.reset(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
    if (!lanes_event_) {
        log::error("eventfd: {}", std::strerror(errno));
        return 1;
    }
    auto interactive =
        Lane::start(Lane::Config{"interactive", opt_.device, 0, opt_.warm_up}, deliver(), true);
    if (!interactive) {
        log::error("cannot start the engine: {}", interactive.error().message);
        return 1;
    }
    lanes_[kInteractive].lane = std::move(*interactive);
    const Lane& engine = *lanes_[kInteractive].lane;
    caps_ = FGSR_CAP_SR | FGSR_CAP_INTERPOLATE | FGSR_CAP_EXTRAPOLATE;
    const size_t align = engine.host_import_alignment();
    if (opt_.zero_copy && align > 0 && FGSR_PLANE_ALIGNMENT % align == 0) caps_ |= FGSR_CAP_ZERO_COPY_INPUT;
    if (engine.calibrated_time()) caps_ |= FGSR_CAP_CALIBRATED_TIME;
    const uint64_t ram = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGESIZE));
    if (opt_.max_session_memory == 0) opt_.max_session_memory = ram / 2;
    if (opt_.max_total_memory == 0) opt_.max_total_memory = ram / 4 * 3;
    log::info("limits: {} pixels and {} MiB a session, {} MiB all sessions", opt_.max_session_pixels,
              opt_.max_session_memory >> 20, opt_.max_total_memory >> 20);
    std::random_device rd;
    epoch_ = (uint64_t(rd()) << 32) ^ rd() ^ (uint64_t(getpid()) << 16) ^ monotonic_ns();
    if (epoch_ == 0) epoch_ = 1;
    log::info("device {}; zero-copy input {}; calibrated timestamps {}", engine.device_name(),
              (caps_ & FGSR_CAP_ZERO_COPY_INPUT) ? "yes" : "no", engine.calibrated_time() ? "yes" : "no");

    signal_.reset(signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK));
    epoll_.reset(epoll_create1(EPOLL_CLOEXEC));
    if (!signal_ || !epoll_) {
        log::error("signalfd/epoll: {}", std::strerror(errno));
        return 1;
    }
    Listener listener = open_listener(opt_.socket_path, opt_.allow_any_user);
    if (!listener.fd) return 1;
    listen_ = std::move(listener.fd);
    created_socket_ = listener.created_path;
    if (!start_http(engine.device_name())) return 1;
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = tag(kListen, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, listen_.get(), &ev);
    ev.data.u64 = tag(kSignal, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, signal_.get(), &ev);
    ev.data.u64 = tag(kLanes, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, lanes_event_.get(), &ev);

    std::vector<epoll_event> events(64);
    bool spin = false; // the last round handled events: the next may follow soon
    const uint64_t spin_ns = uint64_t(opt_.spin_us) * 1000;
    while (!stop_) {
        bool startable = false, ring_wait = false;
        for (const auto& [sid, ref] : session_owner_) {
            const ServiceSession& s = *clients_.at(ref.client)->sessions.at(sid);
            startable |= s.ready() && !lanes_[size_t(ref.lane)].frame_in_flight;
            ring_wait |= s.waiting_on_completion_ring();
        }
        int timeout = startable ? 0 : ring_wait ? 2 : -1;
        const int deadline = expire_connections();
        if (deadline >= 0 && (timeout < 0 || deadline < timeout)) timeout = deadline;
        // Not while a lane runs a frame: its completion is a frame's time away, and on a CPU device
        // the spin would take a core from the frame's threads.
        bool lane_busy = false;
        for (const LaneState& l : lanes_) lane_busy |= l.frame_in_flight;
        int n = 0;
        if (spin && !lane_busy && timeout != 0 && spin_ns > 0) {
            // Bounded (fgsr/ipc/spin.hpp): at most spin_ns per round that handled an event.
            const auto arrived = [&] {
                n = epoll_wait(epoll_.get(), events.data(), int(events.size()), 0);
                return n != 0;
            };
            fgsr::ipc::spin_until(arrived, spin_ns);
        }
        if (n == 0) n = epoll_wait(epoll_.get(), events.data(), int(events.size()), timeout);
        spin = n > 0;
        if (n < 0 && errno != EINTR) {
            log::error("epoll_wait: {}", std::strerror(errno));
            return 1;
        }
        for (int i = 0; i < n; ++i) {
            const uint64_t t = events[size_t(i)].data.u64;
            const uint64_t id = t & ((1ull << 56) - 1);
            switch (Kind(t >> 56)) {
            case kListen:
                accept_clients();
                break;
            case kSignal: {
                signalfd_siginfo si{};
                while (read(signal_.get(), &si, sizeof(si)) == sizeof(si)) {
                    log::info("signal {}: shutting down", si.ssi_signo);
                    stop_ = true;
                }
                break;
            }
            case kClient:
                on_client(id, events[size_t(i)].events);
                break;
            case kSession: // polled by schedule() below
            case kLanes:   // continuations run below
                break;
            }
        }
        run_continuations();
        if (!stop_) schedule();
    }
    log::info("stopping: {} clients", clients_.size());
    if (hub_) hub_->stop();
    http_.reset();
    // A frame cannot be interrupted (one Vulkan submission; a 4096x4096 session's can take a
    // minute on a CPU device). The clients are disconnected at once; past the grace period the
    // process exits without waiting for the running frames (the kernel frees their memory).
    if (!drain(uint64_t(opt_.shutdown_grace_s * 1e9))) {
        log::warn("frames still running {:g} s after the signal; exiting without waiting for them",
                  opt_.shutdown_grace_s);
        if (!created_socket_.empty()) unlink(created_socket_.c_str());
        std::fflush(stderr);
        _exit(0);
    }
    return 0;
}

} // namespace detail

int run_server(const Options& options) {
    detail::Server s(options);
    return s.run();
}

} // namespace fgsrd
