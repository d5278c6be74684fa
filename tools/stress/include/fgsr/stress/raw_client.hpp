// A raw protocol client of fgsrd for `fgsr stress --service` (fgsr/stress/service.hpp): it speaks
// fgsr/wire.h directly instead of going through libfgsr_client, so that it can misbehave
// (malformed messages, attached fds, hostile ring entries, flags on the eventfds). Errors are
// values: nothing throws; a failure returns nullopt / false / an empty message and, where a
// string pointer is given, says why.
#pragma once

#include <fgsr/protocol.h>
#include <fgsr/wire.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fgsr::stress::raw {

uint64_t now_ns(); // CLOCK_MONOTONIC
double ms_since(uint64_t t0_ns);

// Owns a file descriptor.
class Fd {
  public:
    Fd() = default;
    explicit Fd(int fd) : fd_(fd) {}
    Fd(Fd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
    Fd& operator=(Fd&& o) noexcept;
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd();
    int get() const { return fd_; }

  private:
    int fd_ = -1;
};

// One message received: its bytes and fds; eof when the daemon closed the connection, empty bytes
// and no eof when nothing came within the timeout.
struct Message {
    std::vector<std::byte> bytes;
    std::vector<Fd> fds;
    bool eof = false;
};

// A control connection (SOCK_SEQPACKET).
class Connection {
  public:
    static std::optional<Connection> connect(const std::string& socket_path, std::string* why = nullptr);
    int fd() const { return sock_.get(); }
    // Sends `size` bytes as one packet with `fds` attached (SCM_RIGHTS).
    bool send(const void* data, size_t size, const std::vector<int>& fds = {}) const;
    Message recv(int timeout_ms = 10000) const;
    // HELLO and its reply (nullopt: no well-formed reply within the timeout).
    std::optional<fgsr_hello_reply> hello(int timeout_ms = 10000, uint32_t sequence = 1) const;
    // What the daemon does next within timeout_ms: "error <status>: <reason>" for a
    // FGSR_MSG_ERROR (then it closes), "closed" on EOF, "reply type N" for another message, ""
    // for nothing.
    std::string next_event(int timeout_ms) const;
    // True when the daemon closes the connection within timeout_ms (messages before are skipped).
    bool closed_by_daemon(int timeout_ms) const;

  private:
    Fd sock_;
};

// A session made by the raw client: the reply, its five fds and the client's mappings.
class Session {
  public:
    ~Session();
    const fgsr_create_session_reply& reply() const { return reply_; }
    const fgsr_pool_layout& layout() const { return reply_.layout; }
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    int fd(int which) const { return fds_[size_t(which)].get(); }
    std::byte* input_slot(uint32_t i) const { return input_ + uint64_t(i) * layout().input_slot_stride; }
    std::byte* rings() const { return rings_; }
    const fgsr_rings_layout& rings_layout() const { return rl_; }

    // Fills input slot i with a moving pattern in the session's formats (shift in pixels).
    void fill(uint32_t slot, float shift);
    // A well-formed submit entry for `slot` (next sequence, now as submit time).
    fgsr_submit_entry entry(uint32_t slot, uint32_t flags = FGSR_SUBMIT_HAS_MV);
    // Writes entries at the submit head as they are, publishes and signals.
    void push(const std::vector<fgsr_submit_entry>& entries);
    void release(uint32_t output_slot);
    bool signal() const;
    // The next completion within timeout_ms.
    std::optional<fgsr_completion_entry> wait(int timeout_ms);
    // The completions of one submit up to its LAST (fewer when the time ran out).
    std::vector<fgsr_completion_entry> wait_submit(int timeout_ms);
    // Publishes an arbitrary submit head (hostile: out of range) and signals.
    void publish_submit_head(uint64_t head);

    uint64_t submit_head = 0, completion_tail = 0, release_head = 0, sequence = 0;

  private:
    friend std::unique_ptr<Session> create_session(const Connection&, const fgsr_session_desc&, std::string*);
    Session() = default;
    fgsr_ring_header* header_at(uint64_t offset) const {
        return reinterpret_cast<fgsr_ring_header*>(rings_ + offset);
    }
    fgsr_create_session_reply reply_{};
    uint32_t width_ = 0, height_ = 0;
    std::vector<Fd> fds_;
    std::byte* input_ = nullptr;
    const std::byte* output_ = nullptr;
    std::byte* rings_ = nullptr;
    fgsr_rings_layout rl_{};
};

// CREATE_SESSION on a connection that said HELLO; maps the pools and rings.
std::unique_ptr<Session> create_session(const Connection& c, const fgsr_session_desc& desc,
                                        std::string* why = nullptr);

// A connection with one session.
struct Client {
    Connection conn;
    std::unique_ptr<Session> session;
};
// Connects, says HELLO and creates a session.
std::optional<Client> open_client(const std::string& socket_path, const fgsr_session_desc& desc,
                                  std::string* why = nullptr);

// A w x h session, RGBA32F colour, RG32F vectors, scale 1, interpolation (and SR when sr).
fgsr_session_desc small_desc(uint32_t w, uint32_t h, bool sr = false);

// One frame: fills slot `slot`, submits it (one interpolated frame unless `interps` says
// otherwise; SR when the session has it) and waits for its completions, releasing every output.
// Returns the completions (empty when none came within timeout_ms).
std::vector<fgsr_completion_entry> roundtrip(Session& s, float shift, uint32_t slot = 0, uint32_t interps = 1,
                                             int timeout_ms = 30000);

// Milliseconds of a fresh connection's HELLO round trip; -1 when it is not answered in timeout.
double hello_ms(const std::string& socket_path, int timeout_ms = 5000);

} // namespace fgsr::stress::raw
