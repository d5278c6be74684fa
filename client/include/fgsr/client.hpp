// Thin header-only C++ wrapper of fgsr/client.h: RAII owners of a connection and a session.
// Errors are the C API's statuses (no exceptions); thread-safety as in client.h.
//
//   fgsr::client::Connection c;
//   if (fgsr_status s = c.connect(); s != FGSR_STATUS_OK) { ... fgsr_status_string(s) ... }
//   fgsr::client::Session s;
//   s.create(c, desc);
//   fgsr_input_slot in; s.acquire_input(1000, in); ... s.submit(info); s.wait(1000, out); ...
//
// Lifetime: a Session must be destroyed (or reset) before the Connection it was created on.
#pragma once

#include <fgsr/client.h>

#include <utility>

namespace fgsr::client {

class Connection {
  public:
    Connection() = default;
    Connection(Connection&& o) noexcept : c_(std::exchange(o.c_, nullptr)) {}
    Connection& operator=(Connection&& o) noexcept {
        if (this != &o) {
            reset();
            c_ = std::exchange(o.c_, nullptr);
        }
        return *this;
    }
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;
    ~Connection() { reset(); }

    // Connects (socket_path nullptr: $FGSR_SOCKET, else $XDG_RUNTIME_DIR/fgsr/fgsrd.sock).
    fgsr_status connect(const char* socket_path = nullptr, const char* client_name = nullptr,
                        uint32_t timeout_ms = 0) {
        reset();
        fgsr_connect_info info{};
        info.struct_size = sizeof(info);
        info.timeout_ms = timeout_ms;
        info.socket_path = socket_path;
        info.client_name = client_name;
        return fgsr_connect(&info, &c_);
    }
    fgsr_status daemon_info(fgsr_daemon_info& out) const { return fgsr_daemon_info_get(c_, &out); }
    void reset() {
        fgsr_disconnect(c_);
        c_ = nullptr;
    }
    fgsr_connection* get() const { return c_; }
    explicit operator bool() const { return c_ != nullptr; }

  private:
    fgsr_connection* c_ = nullptr;
};

class Session {
  public:
    Session() = default;
    Session(Session&& o) noexcept : s_(std::exchange(o.s_, nullptr)) {}
    Session& operator=(Session&& o) noexcept {
        if (this != &o) {
            reset();
            s_ = std::exchange(o.s_, nullptr);
        }
        return *this;
    }
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;
    ~Session() { reset(); }

    fgsr_status create(Connection& c, const fgsr_session_desc& desc) {
        reset();
        return fgsr_session_create(c.get(), &desc, &s_);
    }
    fgsr_status layout(fgsr_pool_layout& out) const { return fgsr_session_layout(s_, &out); }
    int event_fd() const { return fgsr_session_event_fd(s_); }
    fgsr_status acquire_input(uint32_t timeout_ms, fgsr_input_slot& out) {
        return fgsr_acquire_input(s_, timeout_ms, &out);
    }
    fgsr_status submit(const fgsr_submit_info& info, uint64_t* sequence = nullptr) {
        return fgsr_submit(s_, &info, sequence);
    }
    fgsr_status wait(uint32_t timeout_ms, fgsr_output& out) { return fgsr_wait(s_, timeout_ms, &out); }
    fgsr_status release_output(uint32_t slot) { return fgsr_release_output(s_, slot); }
    fgsr_status stats(fgsr_session_stats& out) { return fgsr_session_stats_get(s_, &out); }
    fgsr_status record(const char* dir) { return fgsr_session_record(s_, dir); }
    void reset() {
        fgsr_session_destroy(s_);
        s_ = nullptr;
    }
    fgsr_session* get() const { return s_; }
    explicit operator bool() const { return s_ != nullptr; }

  private:
    fgsr_session* s_ = nullptr;
};

} // namespace fgsr::client
