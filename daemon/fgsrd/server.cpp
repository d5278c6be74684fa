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
// or completion-ring room is not ready and is skipped.
#include "server.hpp"

#include "lane.hpp"
#include "listen.hpp"
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
#include <mutex>
#include <pthread.h>
#include <random>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

namespace fgsrd {

namespace {

// epoll tags: kind in the top byte, an id below.
enum Kind : uint64_t { kListen = 1, kSignal = 2, kClient = 3, kSession = 4, kLanes = 5 };
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
    uint64_t active_ns = 0;    // last message, submit or release
    uint32_t creating = 0;     // CREATE_SESSION requests on a lane
    std::map<uint32_t, std::unique_ptr<ServiceSession>> sessions;
};

// Where a session lives and what the scheduler knows of it.
struct SessionRef {
    uint64_t client = 0;
    int lane = 0;          // index into Server::lanes_
    uint64_t vstart = 0;   // the lane's virtual clock when the session was created
    uint64_t memory = 0;   // estimated bytes (counted in Server::memory_)
    uint64_t activity = 0; // ServiceSession::ring_activity() at the last poll
};

struct LaneState {
    std::unique_ptr<Lane> lane;
    bool frame_in_flight = false;
    uint64_t vclock = 0;   // virtual time of the last frame started
    uint32_t rr_after = 0; // ties: round robin after this session id
};

constexpr int kInteractive = 0, kBulk = 1;

class Server {
  public:
    explicit Server(const Options& o) : opt_(o) {}
    ~Server();
    int run();

  private:
    void accept_clients();
    // Closes the connections without HELLO past their deadline and the idle ones; returns the
    // milliseconds until the next deadline (-1: none).
    int expire_connections();
    void on_client(uint64_t id, uint32_t events);
    void drop_client(uint64_t id, const char* why);
    // Sends FGSR_MSG_ERROR with a reason, then drops the client.
    void violation(Client& c, uint32_t sequence, const std::string& reason);
    // Handles one message; false when the client was dropped.
    bool handle_message(Client& c, const std::byte* data, size_t size);
    bool send_reply(Client& c, const void* msg, size_t size, const int* fds = nullptr, size_t nfds = 0);
    bool create_session(Client& c, const fgsr_msg_header& h, const std::byte* data, size_t size);
    void session_created(uint64_t client_id, uint32_t sequence, uint32_t session_id, int lane,
                         uint64_t memory, std::shared_ptr<std::unique_ptr<ServiceSession>> made,
                         int32_t status, const std::string& reason);
    void destroy_session(Client& c, uint32_t session_id);
    // Polls every session's rings, then starts a frame on each free lane.
    void schedule();
    void start_frame(int lane);
    void frame_done(int lane, uint32_t session_id, const std::shared_ptr<ServiceSession::FrameJob>& job);
    // Publishes a session's pushed completions; false when the client was dropped for blocking it.
    bool signal(Client& c, ServiceSession& s);
    Lane* lane(int index);
    // What a lane calls with a finished job's continuation (on the lane's thread).
    std::function<void(Lane::Continuation)> deliver() {
        return [this](Lane::Continuation c) {
            {
                std::lock_guard lock(done_mutex_);
                done_.push_back(std::move(c));
            }
            const uint64_t one = 1;
            (void)!write(lanes_event_.get(), &one, sizeof(one)); // private eventfd, non-blocking
        };
    }
    void run_continuations();
    bool lanes_idle() const;
    bool evict_idle_client();
    size_t served_clients(uid_t uid, bool any_uid) const {
        size_t n = 0;
        for (const auto& [id, c] : clients_) n += c->hello_done && (any_uid || c->uid == uid) ? 1 : 0;
        return n;
    }
    size_t sessions_of(uid_t uid) const {
        size_t n = 0;
        for (const auto& [id, c] : clients_)
            if (c->uid == uid) n += c->sessions.size() + c->creating;
        return n;
    }

    Options opt_;
    std::array<LaneState, 2> lanes_;
    std::mutex done_mutex_; // guards done_ (lanes push, the server's thread pops)
    std::deque<Lane::Continuation> done_;
    UniqueFd epoll_, listen_, signal_, lanes_event_;
    std::string created_socket_; // unlinked at shutdown when this process created it
    std::map<uint64_t, std::unique_ptr<Client>> clients_;
    std::map<uint32_t, SessionRef> session_owner_;
    uint64_t memory_ = 0; // estimated bytes of every session, made or being made
    uint64_t next_client_ = 1;
    uint32_t next_session_ = 1;
    uint64_t epoch_ = 0;
    uint32_t caps_ = 0;
    bool stop_ = false;
};

Server::~Server() {
    // Every session is destroyed on its lane, before the lane's engine: drop the clients, then
    // run continuations (a creation that finishes for a dropped client posts its destruction)
    // until the lanes are idle; then the lanes stop.
    while (!clients_.empty()) drop_client(clients_.begin()->first, nullptr);
    while (!lanes_idle() || !done_.empty()) {
        run_continuations();
        if (!lanes_idle()) usleep(1000);
    }
    for (LaneState& l : lanes_) l.lane.reset();
    if (!created_socket_.empty()) unlink(created_socket_.c_str());
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
    const SessionRef ref = session_owner_.at(session_id);
    memory_ -= ref.memory;
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
        // Kept escaped: it reaches logs and telemetry, and must not forge lines there.
        c.name = log::printable(hello.name) + " (pid " + std::to_string(c.pid) + ")";
        fgsr_hello_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_HELLO_REPLY, sizeof(r), h.sequence);
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
    case FGSR_MSG_CREATE_SESSION:
        return create_session(c, h, data, size);
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

// The memory a session will hold, before anything is allocated: its shared pools, the engine's
// buffers (per input and per output pixel) and the host images of the outputs of one submit.
// The per-pixel figures are fitted to the RSS of fgsrd on lavapipe after running 512x512, 1024x1024
// and 2048x2048 sessions with eight outputs per submit (docs/RELIABILITY.md, "Limits"), and err
// on the high side (2048x2048: 2.05 GiB estimated, 1.57 GiB measured).
uint64_t session_memory_estimate(const fgsr_session_desc& d, const fgsr_pool_layout& l) {
    const uint64_t in_px = uint64_t(d.width) * d.height;
    const uint64_t out_px =
        uint64_t(std::ceil(double(d.width) * d.scale)) * uint64_t(std::ceil(double(d.height) * d.scale));
    constexpr uint64_t kEngineBytesPerInputPixel = 128, kEngineBytesPerOutputPixel = 32,
                       kBytesPerOutputImagePixel = 16;
    return l.input_pool_size + l.output_pool_size + l.rings_size + in_px * kEngineBytesPerInputPixel +
           out_px * (kEngineBytesPerOutputPixel + uint64_t(d.output_slots) * kBytesPerOutputImagePixel);
}

bool Server::create_session(Client& c, const fgsr_msg_header& h, const std::byte* data, size_t size) {
    if (size < sizeof(fgsr_create_session)) {
        violation(c, h.sequence,
                  "message type " + std::to_string(h.type) + " truncated to " + std::to_string(size) +
                      " bytes (needs " + std::to_string(sizeof(fgsr_create_session)) + ")");
        return false;
    }
    fgsr_session_desc desc;
    std::memcpy(&desc, data + sizeof(fgsr_msg_header), sizeof(desc));
    if (desc.struct_size < sizeof(fgsr_session_desc) || desc.struct_size > size - sizeof(fgsr_msg_header)) {
        violation(c, h.sequence,
                  "session description struct_size " + std::to_string(desc.struct_size) +
                      " does not match the message");
        return false;
    }
    const uint32_t sequence = h.sequence;
    auto refuse = [&](int32_t status, const std::string& reason) {
        log::info("client {} ({}): session refused: {}: {}", c.id, c.name, fgsr_status_string(status),
                  reason);
        fgsr_create_session_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), sequence);
        r.epoch = epoch_;
        r.status = status;
        copy_reason(r.reason, sizeof(r.reason), reason);
        if (send_reply(c, &r, sizeof(r))) return true;
        drop_client(c.id, nullptr);
        return false;
    };
    fgsr_session_desc d;
    char why[128];
    if (fgsr_session_desc_normalize(&desc, &d, why, sizeof(why)) != FGSR_STATUS_OK)
        return refuse(FGSR_STATUS_INVALID_ARGUMENT, why);
    const fgsr_pool_layout layout = fgsr_pool_layout_for(&d);
    const uint64_t in_px = uint64_t(d.width) * d.height;
    const uint64_t out_px =
        uint64_t(std::ceil(double(d.width) * d.scale)) * uint64_t(std::ceil(double(d.height) * d.scale));
    const uint64_t pixels = std::max(in_px, out_px);
    const uint64_t memory = session_memory_estimate(d, layout);
    const auto mib = [](uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
    if (c.sessions.size() + c.creating >= opt_.max_sessions_per_client)
        return refuse(FGSR_STATUS_BUSY, "too many sessions on this connection");
    if (sessions_of(c.uid) >= opt_.max_sessions_per_uid)
        return refuse(FGSR_STATUS_BUSY, "too many sessions for uid " + std::to_string(c.uid));
    if (pixels > opt_.max_session_pixels)
        return refuse(FGSR_STATUS_UNSUPPORTED, "--max-session-pixels " +
                                                   std::to_string(opt_.max_session_pixels) + ": frames of " +
                                                   std::to_string(pixels) + " pixels");
    if (memory > opt_.max_session_memory)
        return refuse(FGSR_STATUS_UNSUPPORTED, "--max-session-memory " + mib(opt_.max_session_memory) +
                                                   ": needs about " + mib(memory));
    if (memory_ + memory > opt_.max_total_memory)
        return refuse(FGSR_STATUS_BUSY, "--max-total-memory " + mib(opt_.max_total_memory) + ": " +
                                            mib(memory_) + " held, needs " + mib(memory));
    const int lane_index = pixels > opt_.interactive_pixels ? kBulk : kInteractive;
    Lane* l = lane(lane_index);
    const uint32_t id = next_session_++;
    if (next_session_ == 0) next_session_ = 1;
    memory_ += memory;
    ++c.creating;
    const uint64_t client_id = c.id;
    const bool zero_copy = opt_.zero_copy;
    l->post([this, l, client_id, sequence, id, lane_index, memory, desc, zero_copy](fgsr::Engine* engine) {
        auto made = std::make_shared<std::unique_ptr<ServiceSession>>();
        int32_t status = FGSR_STATUS_UNSUPPORTED;
        std::string reason;
        if (engine)
            *made = ServiceSession::create(*engine, id, desc, zero_copy, status, reason);
        else
            reason = "no engine for large sessions: " + l->engine_error();
        return Lane::Continuation([this, client_id, sequence, id, lane_index, memory, made, status, reason] {
            session_created(client_id, sequence, id, lane_index, memory, made, status, reason);
        });
    });
    return true;
}

void Server::session_created(uint64_t client_id, uint32_t sequence, uint32_t id, int lane_index,
                             uint64_t memory, std::shared_ptr<std::unique_ptr<ServiceSession>> made,
                             int32_t status, const std::string& reason) {
    auto cit = clients_.find(client_id);
    if (cit != clients_.end()) --cit->second->creating;
    if (cit == clients_.end() || !*made) {
        memory_ -= memory;
        if (*made) // the client went away meanwhile: destroy it where it was made
            lane(lane_index)->post([made](fgsr::Engine*) {
                made->reset();
                return Lane::Continuation{};
            });
        if (cit == clients_.end()) return;
        Client& c = *cit->second;
        log::info("client {} ({}): session refused: {}: {}", c.id, c.name, fgsr_status_string(status),
                  reason);
        fgsr_create_session_reply r{};
        r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), sequence);
        r.epoch = epoch_;
        r.status = status;
        copy_reason(r.reason, sizeof(r.reason), reason);
        if (!send_reply(c, &r, sizeof(r))) drop_client(c.id, nullptr);
        return;
    }
    Client& c = *cit->second;
    ServiceSession& s = **made;
    const fgsr_session_desc& d = s.desc();
    // Registered before the reply, so that a failed reply tears it down like any other session.
    session_owner_[id] = SessionRef{client_id, lane_index, lanes_[size_t(lane_index)].vclock, memory, 0};
    c.sessions[id] = std::move(*made);
    fgsr_create_session_reply r{};
    r.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION_REPLY, sizeof(r), sequence);
    r.epoch = epoch_;
    r.status = FGSR_STATUS_OK;
    r.session_id = id;
    r.layout = s.layout();
    const auto fds = s.fds();
    if (!send_reply(c, &r, sizeof(r), fds.data(), fds.size())) {
        drop_client(c.id, nullptr);
        return;
    }
    s.close_shared_fds();
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLET; // a wake-up per client write; the counter is never read
    ev.data.u64 = tag(kSession, id);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, s.submit_event_fd(), &ev);
    log::info("client {} ({}): session {} {}x{} x{} on the {} lane ({})", c.id, c.name, id, d.width, d.height,
              d.scale, lane_index == kBulk ? "bulk" : "interactive",
              s.zero_copy() ? "zero-copy input" : "staging copies");
}

bool Server::signal(Client& c, ServiceSession& s) {
    if (!s.signal_pending() || s.signal_complete()) return true;
    violation(c, 0,
              "session " + std::to_string(s.id()) +
                  ": its complete eventfd blocked the daemon's write (O_NONBLOCK cleared and counter full)");
    return false;
}

void Server::schedule() {
    // Poll every session (rings copied and validated, activity noted), in id order.
    std::vector<uint32_t> ids;
    ids.reserve(session_owner_.size());
    for (const auto& [sid, ref] : session_owner_) ids.push_back(sid);
    const uint64_t now = monotonic_ns();
    for (uint32_t sid : ids) {
        auto ref = session_owner_.find(sid);
        if (ref == session_owner_.end()) continue; // its client was dropped meanwhile
        Client& c = *clients_.at(ref->second.client);
        ServiceSession& s = *c.sessions.at(sid);
        if (auto why = s.poll()) {
            violation(c, 0, "session " + std::to_string(sid) + ": " + *why);
            continue;
        }
        if (s.ring_activity() != ref->second.activity) {
            ref->second.activity = s.ring_activity();
            c.active_ns = now;
        }
    }
    for (int l = 0; l < int(lanes_.size()); ++l) start_frame(l);
}

void Server::start_frame(int lane_index) {
    LaneState& ls = lanes_[size_t(lane_index)];
    while (ls.lane && !ls.frame_in_flight) {
        // The ready session of this lane with the least virtual time (engine time used since it
        // was created, from the lane's clock then); one that was idle restarts at the lane's clock.
        // Ties: round robin after the last one served.
        uint32_t best = 0;
        uint64_t best_key = UINT64_MAX;
        bool best_after = false;
        for (const auto& [sid, ref] : session_owner_) {
            if (ref.lane != lane_index) continue;
            const ServiceSession& s = *clients_.at(ref.client)->sessions.at(sid);
            if (!s.ready()) continue;
            const uint64_t key = std::max(ref.vstart + s.engine_ns(), ls.vclock);
            const bool after = sid > ls.rr_after;
            if (key < best_key || (key == best_key && after && !best_after)) {
                best = sid;
                best_key = key;
                best_after = after;
            }
        }
        if (best_key == UINT64_MAX) return;
        SessionRef& ref = session_owner_.at(best);
        Client& c = *clients_.at(ref.client);
        ServiceSession& s = *c.sessions.at(best);
        // Catch an idle session up: its virtual start moves so that its key is the clock.
        if (ref.vstart + s.engine_ns() < ls.vclock) ref.vstart = ls.vclock - s.engine_ns();
        ls.vclock = best_key;
        ls.rr_after = best;
        auto begun = s.begin();
        if (begun.violation) {
            violation(c, 0, "session " + std::to_string(best) + ": " + *begun.violation);
            continue;
        }
        if (!signal(c, s)) continue; // drops and rejections published by begin()
        if (!begun.job) continue;    // nothing for the engine: pick again
        ls.frame_in_flight = true;
        auto job = begun.job;
        ServiceSession* target = &s; // outlives the job: its destruction is posted after it
        const uint32_t sid = best;
        ls.lane->post([this, lane_index, sid, job, target](fgsr::Engine*) {
            target->execute(*job);
            return Lane::Continuation([this, lane_index, sid, job] { frame_done(lane_index, sid, job); });
        });
    }
}

void Server::frame_done(int lane_index, uint32_t session_id,
                        const std::shared_ptr<ServiceSession::FrameJob>& job) {
    lanes_[size_t(lane_index)].frame_in_flight = false;
    auto ref = session_owner_.find(session_id);
    if (ref != session_owner_.end()) { // else destroyed while the frame ran: nothing to publish
        Client& c = *clients_.at(ref->second.client);
        ServiceSession& s = *c.sessions.at(session_id);
        if (auto why = s.finish(*job))
            violation(c, 0, "session " + std::to_string(session_id) + ": " + *why);
        else
            signal(c, s);
    }
    start_frame(lane_index);
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
    auto interactive = Lane::start(Lane::Config{"interactive", opt_.device, 0}, deliver(), true);
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
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = tag(kListen, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, listen_.get(), &ev);
    ev.data.u64 = tag(kSignal, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, signal_.get(), &ev);
    ev.data.u64 = tag(kLanes, 0);
    epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, lanes_event_.get(), &ev);

    std::vector<epoll_event> events(64);
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
            case kLanes:   // continuations run below
                break;
            }
        }
        run_continuations();
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
