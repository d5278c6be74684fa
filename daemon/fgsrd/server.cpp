// Scheduling: one thread runs everything (epoll over the listening socket, the signalfd, every
// client socket and every session's submit eventfd; then one submit per ready session, round
// robin). Why one thread: the engine's Vulkan queue is not externally synchronised and every
// engine call waits for its own fence, so GPU work is serial whatever the thread count; one thread
// makes the daemon lock-free, makes round robin exactly fair (one frame per ready session per
// round), and a stalled client cannot block others because a session that waits for output slots
// or completion-ring room is simply not ready and is skipped. Control messages and disconnects are
// handled between rounds, so a client that dies is torn down after at most one round of frames.
#include "server.hpp"

#include "log.hpp"
#include "session.hpp"

#include <fgsr/engine/engine.hpp>
#include <fgsr/ipc/socket.hpp>
#include <fgsr/wire.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <map>
#include <memory>
#include <pthread.h>
#include <random>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

namespace fgsrd {

namespace {

// epoll tags: kind in the top byte, an id below.
enum Kind : uint64_t { kListen = 1, kSignal = 2, kClient = 3, kSession = 4 };
uint64_t tag(Kind k, uint64_t id) {
    return (uint64_t(k) << 56) | id;
}

struct Client {
    uint64_t id = 0;
    UniqueFd fd;
    uid_t uid = 0;
    pid_t pid = 0;
    std::string name; // "pid N" until HELLO names it
    bool hello_done = false;
    uint64_t connected_ns = 0; // CLOCK_MONOTONIC at accept (the HELLO deadline counts from it)
    std::map<uint32_t, std::unique_ptr<ServiceSession>> sessions;
};

class Server {
  public:
    explicit Server(const Options& o) : opt_(o) {}
    ~Server();
    int run();

  private:
    bool setup_socket();
    void accept_clients();
    // Closes the connections without HELLO past their deadline; returns the milliseconds until
    // the next deadline (-1: none).
    int expire_pending();
    void on_client(uint64_t id, uint32_t events);
    void drop_client(uint64_t id, const char* why);
    // Sends FGSR_MSG_ERROR with a reason, then drops the client.
    void violation(Client& c, uint32_t sequence, const std::string& reason);
    // Handles one message; false when the client was dropped.
    bool handle_message(Client& c, const std::byte* data, size_t size);
    bool send_reply(Client& c, const void* msg, size_t size, const int* fds = nullptr, size_t nfds = 0);
    void destroy_session(Client& c, uint32_t session_id);
    void schedule();
    size_t served_clients() const {
        size_t n = 0;
        for (const auto& [id, c] : clients_) n += c->hello_done ? 1 : 0;
        return n;
    }

    Options opt_;
    std::unique_ptr<fgsr::Engine> engine_;
    UniqueFd epoll_, listen_, signal_;
    std::string created_socket_; // unlinked at shutdown when this process created it
    std::map<uint64_t, std::unique_ptr<Client>> clients_;
    std::map<uint32_t, uint64_t> session_owner_; // session id -> client id
    uint64_t next_client_ = 1;
    uint32_t next_session_ = 1;
    uint32_t rr_after_ = 0; // round robin: start after this session id
    uint64_t epoch_ = 0;
    uint32_t caps_ = 0;
    bool stop_ = false;
};

Server::~Server() {
    // Sessions before the engine.
    clients_.clear();
    engine_.reset();
    if (!created_socket_.empty()) unlink(created_socket_.c_str());
}

// Socket activation (sd_listen_fds, by hand): LISTEN_PID is this process and LISTEN_FDS >= 1;
// the first passed fd (3) must be a listening SOCK_SEQPACKET Unix socket.
int activated_socket() {
    const char* pid = std::getenv("LISTEN_PID");
    const char* fds = std::getenv("LISTEN_FDS");
    if (!pid || !fds) return -1;
    const bool mine = std::strtol(pid, nullptr, 10) == long(getpid());
    const long n = std::strtol(fds, nullptr, 10);
    unsetenv("LISTEN_PID");
    unsetenv("LISTEN_FDS");
    unsetenv("LISTEN_FDNAMES");
    if (!mine || n < 1) return -1;
    if (n > 1) log::warn("socket activation passed {} fds; using the first", n);
    int type = 0;
    socklen_t len = sizeof(type);
    if (getsockopt(3, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_SEQPACKET) {
        log::error("socket activation: fd 3 is not a SOCK_SEQPACKET socket (use ListenSequentialPacket=)");
        return -2;
    }
    fcntl(3, F_SETFD, FD_CLOEXEC);
    fcntl(3, F_SETFL, fcntl(3, F_GETFL) | O_NONBLOCK);
    return 3;
}

bool Server::setup_socket() {
    const int act = activated_socket();
    if (act == -2) return false;
    if (act >= 0) {
        listen_.reset(act);
        log::info("listening on the socket systemd passed (fd 3)");
        return true;
    }
    std::string path = opt_.socket_path;
    if (path.empty()) {
        const char* xdg = std::getenv("XDG_RUNTIME_DIR");
        if (!xdg || !*xdg) {
            log::error("XDG_RUNTIME_DIR is not set; pass --socket PATH");
            return false;
        }
        const std::string dir = std::string(xdg) + "/fgsr";
        if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
            log::error("cannot create {}: {}", dir, std::strerror(errno));
            return false;
        }
        path = dir + "/fgsrd.sock";
    }
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof(addr.sun_path)) {
        log::error("socket path {} is longer than {} bytes", path, sizeof(addr.sun_path) - 1);
        return false;
    }
    std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
    listen_.reset(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
    if (!listen_) {
        log::error("socket: {}", std::strerror(errno));
        return false;
    }
    const int bound = bind(listen_.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
    if (bound != 0 && errno == EADDRINUSE) {
        // A stale socket file, unless a daemon answers on it.
        UniqueFd probe(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
        if (connect(probe.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
            log::error("another fgsrd is already listening on {}", path);
            return false;
        }
        unlink(path.c_str());
        if (bind(listen_.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
            log::error("bind {}: {}", path, std::strerror(errno));
            return false;
        }
    } else if (bound != 0) {
        log::error("bind {}: {}", path, std::strerror(errno));
        return false;
    }
    created_socket_ = path;
    // Connecting needs write permission on the socket file: only this user, or everyone.
    chmod(path.c_str(), opt_.allow_any_user ? 0666 : 0600);
    if (listen(listen_.get(), 64) != 0) {
        log::error("listen {}: {}", path, std::strerror(errno));
        return false;
    }
    log::info("listening on {}", path);
    return true;
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

void copy_reason(char* dst, size_t cap, const std::string& s) {
    const size_t n = std::min(cap - 1, s.size());
    std::memcpy(dst, s.data(), n);
    dst[n] = 0;
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
    c.sessions.erase(it);
    session_owner_.erase(session_id);
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

int Server::expire_pending() {
    const uint64_t now = monotonic_ns();
    const uint64_t limit = uint64_t(opt_.hello_timeout_s * 1e9);
    std::vector<uint64_t> late;
    uint64_t next = UINT64_MAX;
    for (const auto& [cid, c] : clients_) {
        if (c->hello_done) continue;
        const uint64_t deadline = c->connected_ns + limit;
        if (deadline <= now)
            late.push_back(cid);
        else
            next = std::min(next, deadline);
    }
    for (uint64_t cid : late) drop_client(cid, "no HELLO in time");
    return next == UINT64_MAX ? -1 : int(std::min<uint64_t>((next - now) / 1000000 + 1, 60000));
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
        if (n < 0 && (errno == EMSGSIZE || errno == EPROTO)) {
            violation(c, 0, "message larger than " + std::to_string(FGSR_MAX_MESSAGE_SIZE) + " bytes");
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
        if (!handle_message(c, buf, size_t(n))) return;
    }
    if (events & (EPOLLHUP | EPOLLRDHUP | EPOLLERR)) drop_client(id, "hung up");
}

bool Server::handle_message(Client& c, const std::byte* data, size_t size) {
    fgsr_msg_header h{};
    if (size < sizeof(h)) {
        violation(c, 0, "message of " + std::to_string(size) + " bytes is shorter than a header");
        return false;
    }
    std::memcpy(&h, data, sizeof(h));
    if (h.magic != FGSR_PROTOCOL_MAGIC) {
        violation(c, h.sequence, "bad magic");
        return false;
    }
    if (h.size != size) {
        violation(c, h.sequence,
                  "header size " + std::to_string(h.size) + " but the packet has " + std::to_string(size) +
                      " bytes");
        return false;
    }
    auto need = [&](size_t n) {
        if (size >= n) return true;
        violation(c, h.sequence,
                  "message type " + std::to_string(h.type) + " truncated to " + std::to_string(size) +
                      " bytes (needs " + std::to_string(n) + ")");
        return false;
    };
    if (!c.hello_done && h.type != FGSR_MSG_HELLO) {
        violation(c, h.sequence, "the first message must be HELLO");
        return false;
    }
    switch (h.type) {
    case FGSR_MSG_HELLO: {
        if (c.hello_done) {
            violation(c, h.sequence, "second HELLO");
            return false;
        }
        if (!need(sizeof(fgsr_hello))) return false;
        fgsr_hello hello;
        std::memcpy(&hello, data, sizeof(hello));
        hello.name[sizeof(hello.name) - 1] = 0;
        c.name = std::string(hello.name) + " (pid " + std::to_string(c.pid) + ")";
        fgsr_hello_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_HELLO_REPLY, sizeof(r), h.sequence);
        r.major = FGSR_PROTOCOL_MAJOR;
        r.minor = FGSR_PROTOCOL_MINOR;
        r.capabilities = caps_;
        r.epoch = epoch_;
        copy_reason(r.device, sizeof(r.device), engine_->device_name());
        r.status = FGSR_STATUS_OK;
        if (hello.major != FGSR_PROTOCOL_MAJOR)
            r.status = FGSR_STATUS_VERSION_MISMATCH;
        else if (!opt_.allow_any_user && c.uid != getuid())
            r.status = FGSR_STATUS_PERMISSION_DENIED;
        else if (served_clients() >= opt_.max_clients)
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
    case FGSR_MSG_CREATE_SESSION: {
        if (!need(sizeof(fgsr_create_session))) return false;
        fgsr_session_desc desc;
        std::memcpy(&desc, data + sizeof(fgsr_msg_header), sizeof(desc));
        if (desc.struct_size < sizeof(fgsr_session_desc) ||
            desc.struct_size > size - sizeof(fgsr_msg_header)) {
            violation(c, h.sequence,
                      "session description struct_size " + std::to_string(desc.struct_size) +
                          " does not match the message");
            return false;
        }
        fgsr_create_session_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), h.sequence);
        r.epoch = epoch_;
        std::string reason;
        std::unique_ptr<ServiceSession> s;
        if (c.sessions.size() >= opt_.max_sessions_per_client) {
            r.status = FGSR_STATUS_BUSY;
            reason = "too many sessions on this connection";
        } else {
            s = ServiceSession::create(*engine_, next_session_, desc, opt_.zero_copy, r.status, reason);
        }
        if (!s) {
            log::info("client {} ({}): session refused: {}: {}", c.id, c.name, fgsr_status_string(r.status),
                      reason);
            copy_reason(r.reason, sizeof(r.reason), reason);
            if (!send_reply(c, &r, sizeof(r))) drop_client(c.id, nullptr);
            return clients_.count(c.id) != 0;
        }
        r.session_id = s->id();
        r.layout = s->layout();
        const auto fds = s->fds();
        if (!send_reply(c, &r, sizeof(r), fds.data(), fds.size())) {
            drop_client(c.id, nullptr);
            return false;
        }
        s->close_shared_fds();
        epoll_event ev{};
        ev.events = EPOLLIN;
        ev.data.u64 = tag(kSession, s->id());
        epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, s->submit_event_fd(), &ev);
        log::info("client {} ({}): session {} {}x{} x{} ({})", c.id, c.name, s->id(), desc.width, desc.height,
                  desc.scale, s->zero_copy() ? "zero-copy input" : "staging copies");
        session_owner_[s->id()] = c.id;
        c.sessions[s->id()] = std::move(s);
        ++next_session_;
        if (next_session_ == 0) next_session_ = 1;
        return true;
    }
    case FGSR_MSG_DESTROY_SESSION:
    case FGSR_MSG_STATS: {
        if (!need(sizeof(fgsr_session_ref))) return false;
        fgsr_session_ref ref;
        std::memcpy(&ref, data, sizeof(ref));
        auto it = c.sessions.find(ref.session_id);
        if (h.type == FGSR_MSG_STATS) {
            fgsr_stats_reply r{};
            r.header = fgsr_msg_header_for(FGSR_MSG_STATS_REPLY, sizeof(r), h.sequence);
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
        r.header = fgsr_msg_header_for(FGSR_MSG_DESTROY_SESSION_REPLY, sizeof(r), h.sequence);
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
    default:
        violation(c, h.sequence, "unknown message type " + std::to_string(h.type));
        return false;
    }
}

void Server::schedule() {
    // One round: every session with work gets one submit, starting after the last one served.
    std::vector<uint32_t> order;
    for (auto it = session_owner_.upper_bound(rr_after_); it != session_owner_.end(); ++it)
        order.push_back(it->first);
    for (auto it = session_owner_.begin(); it != session_owner_.end() && it->first <= rr_after_; ++it)
        order.push_back(it->first);
    for (uint32_t sid : order) {
        auto owner = session_owner_.find(sid);
        if (owner == session_owner_.end()) continue;
        Client& c = *clients_.at(owner->second);
        ServiceSession& s = *c.sessions.at(sid);
        if (auto why = s.poll()) {
            violation(c, 0, "session " + std::to_string(sid) + ": " + *why);
            continue;
        }
        if (!s.ready()) continue;
        if (auto why = s.process_one()) {
            violation(c, 0, "session " + std::to_string(sid) + ": " + *why);
            continue;
        }
        rr_after_ = sid;
    }
}

int Server::run() {
    // Blocked before the engine starts driver threads (which inherit the mask): otherwise the
    // kernel may deliver SIGTERM to a driver thread and kill the process without a clean shutdown.
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGTERM);
    sigaddset(&mask, SIGINT);
    pthread_sigmask(SIG_BLOCK, &mask, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
    auto engine = fgsr::Engine::create(fgsr::DeviceOptions{opt_.device});
    if (!engine) {
        log::error("cannot start the engine: {}", engine.error().message);
        return 1;
    }
    engine_ = std::move(*engine);
    caps_ = FGSR_CAP_SR | FGSR_CAP_INTERPOLATE | FGSR_CAP_EXTRAPOLATE;
    const size_t align = engine_->host_import_alignment();
    if (opt_.zero_copy && align > 0 && FGSR_PLANE_ALIGNMENT % align == 0) caps_ |= FGSR_CAP_ZERO_COPY_INPUT;
    if (engine_->calibrated_time()) caps_ |= FGSR_CAP_CALIBRATED_TIME;
    std::random_device rd;
    epoch_ = (uint64_t(rd()) << 32) ^ rd() ^ (uint64_t(getpid()) << 16) ^ monotonic_ns();
    if (epoch_ == 0) epoch_ = 1;
    log::info("device {}; zero-copy input {}; calibrated timestamps {}", engine_->device_name(),
              (caps_ & FGSR_CAP_ZERO_COPY_INPUT) ? "yes" : "no", engine_->calibrated_time() ? "yes" : "no");

    signal_.reset(signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK));
    epoll_.reset(epoll_create1(EPOLL_CLOEXEC));
    if (!signal_ || !epoll_) {
        log::error("signalfd/epoll: {}", std::strerror(errno));
        return 1;
    }
    if (!setup_socket()) return 1;
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = tag(kListen, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, listen_.get(), &ev);
    ev.data.u64 = tag(kSignal, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, signal_.get(), &ev);

    std::vector<epoll_event> events(64);
    while (!stop_) {
        bool ready = false, ring_wait = false;
        for (auto& [cid, c] : clients_)
            for (auto& [sid, s] : c->sessions) {
                ready |= s->ready();
                ring_wait |= s->waiting_on_completion_ring();
            }
        int timeout = ready ? 0 : ring_wait ? 2 : -1;
        const int hello_wait = expire_pending();
        if (hello_wait >= 0 && (timeout < 0 || hello_wait < timeout)) timeout = hello_wait;
        const int n = epoll_wait(epoll_.get(), events.data(), int(events.size()), timeout);
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
                break;
            }
        }
        if (!stop_) schedule();
    }
    log::info("stopping: {} clients", clients_.size());
    return 0;
}

} // namespace

int run_server(const Options& options) {
    Server s(options);
    return s.run();
}

} // namespace fgsrd
