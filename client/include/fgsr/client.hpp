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

namespace detail {

// Move-only owner of a C handle of type T, given back with Free (which accepts nullptr).
template <class T, void (*Free)(T*)> class Handle {
  public:
    Handle() = default;
    Handle(Handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
    Handle& operator=(Handle&& o) noexcept {
        if (this != &o) {
            reset();
            h_ = std::exchange(o.h_, nullptr);
        }
        return *this;
    }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    ~Handle() { reset(); }

    void reset() {
        Free(h_);
        h_ = nullptr;
    }
    T* get() const { return h_; }
    explicit operator bool() const { return h_ != nullptr; }

  protected:
    T* h_ = nullptr;
};

} // namespace detail

class Connection : public detail::Handle<fgsr_connection, fgsr_disconnect> {
  public:
    // Connects (socket_path nullptr: $FGSR_SOCKET, else $XDG_RUNTIME_DIR/fgsr/fgsrd.sock).
    fgsr_status connect(const char* socket_path = nullptr, const char* client_name = nullptr,
                        uint32_t timeout_ms = 0) {
        reset();
        fgsr_connect_info info{};
        info.struct_size = sizeof(info);
        info.timeout_ms = timeout_ms;
        info.socket_path = socket_path;
        info.client_name = client_name;
        return fgsr_connect(&info, &h_);
    }
    fgsr_status daemon_info(fgsr_daemon_info& out) const { return fgsr_daemon_info_get(h_, &out); }
    fgsr_status report_probe_samples(const fgsr_probe_sample* samples, uint32_t count) {
        return fgsr_report_probe_samples(h_, samples, count);
    }
};

class Session : public detail::Handle<fgsr_session, fgsr_session_destroy> {
  public:
    fgsr_status create(Connection& c, const fgsr_session_desc& desc) {
        reset();
        return fgsr_session_create(c.get(), &desc, &h_);
    }
    fgsr_status layout(fgsr_pool_layout& out) const { return fgsr_session_layout(h_, &out); }
    int event_fd() const { return fgsr_session_event_fd(h_); }
    fgsr_status acquire_input(uint32_t timeout_ms, fgsr_input_slot& out) {
        return fgsr_acquire_input(h_, timeout_ms, &out);
    }
    fgsr_status submit(const fgsr_submit_info& info, uint64_t* sequence = nullptr) {
        return fgsr_submit(h_, &info, sequence);
    }
    fgsr_status wait(uint32_t timeout_ms, fgsr_output& out) { return fgsr_wait(h_, timeout_ms, &out); }
    fgsr_status release_output(uint32_t slot) { return fgsr_release_output(h_, slot); }
    fgsr_status stats(fgsr_session_stats& out) { return fgsr_session_stats_get(h_, &out); }
    fgsr_status report_presents(const fgsr_present_report* reports, uint32_t count) {
        return fgsr_report_presents(h_, reports, count);
    }
    fgsr_status record(const char* dir) { return fgsr_session_record(h_, dir); }
};

} // namespace fgsr::client
