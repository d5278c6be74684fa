// The server's private declarations, shared by server.cpp (connections, control messages, the
// event loop) and server_sessions.cpp (session creation, limits and frame scheduling).
#pragma once

#include "http_server.hpp"
#include "lane.hpp"
#include "messages.hpp"
#include "reaper.hpp"
#include "server.hpp"
#include "session.hpp"

#include <fgsr/ipc/unique_fd.hpp>
#include <fgsr/wire.h>

#include <array>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <sys/types.h>

namespace fgsrd::detail {

// epoll tags: kind in the top byte, an id below.
enum Kind : uint64_t { kListen = 1, kSignal = 2, kClient = 3, kSession = 4, kLanes = 5 };
inline uint64_t tag(Kind k, uint64_t id) {
    return (uint64_t(k) << 56) | id;
}

struct Client {
    uint64_t id = 0;
    UniqueFd fd;
    uid_t uid = 0;
    pid_t pid = 0;
    std::string name; // "pid N" until HELLO names it
    std::string application; // /proc/<pid>/comm at accept (telemetry), escaped
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
    bool create_session(Client& c, const CreateRequest& request);
    // Sends a CREATE_SESSION refusal (and logs it); false when the client was dropped.
    bool refuse_session(Client& c, uint32_t sequence, int32_t status, const std::string& reason);
    bool session_request(Client& c, const SessionRequest& request);
    // Present reports go to the telemetry hub (when --http); reports of sessions the connection
    // does not own are ignored.
    void report(Client& c, const ReportRequest& request);
    // --http: the hub and the dashboard's server; false when it cannot listen.
    bool start_http(const std::string& device);
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
    // Drops every client and waits until the lanes are idle; false after timeout_ns.
    bool drain(uint64_t timeout_ns);
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
    Reaper reaper_; // before lanes_: their jobs hand it memory until they are gone
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
    // Declared last: the HTTP server stops (its threads read the hub) before the hub goes.
    std::unique_ptr<TelemetryHub> hub_;
    std::unique_ptr<HttpServer> http_;
};

// Copies s into a fixed-size, NUL-terminated reason field.
void copy_reason(char* dst, size_t cap, const std::string& s);

} // namespace fgsrd::detail
