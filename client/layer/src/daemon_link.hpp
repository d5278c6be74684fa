// One swapchain's link to fgsrd through libfgsr_client: a connection and a colour-only session of
// the swapchain's size and format, (re)made on demand. When fgsrd is absent or goes away the link
// logs one line, drops the session and tries again at most every kRetryNs; meanwhile ready() is
// false and the layer presents the application's frames alone.
//
// Colour-only: with FGSR_SESSION_NO_MVS / FGSR_SESSION_NO_DEPTH (protocol minor 2) the session has
// no depth or vector planes and the daemon estimates motion from colour; with an older protocol
// header the depth plane is zero-filled and no vectors are flagged (the daemon then blends).
//
// Thread safety: used by one thread (the swapchain's present thread).
#pragma once

#include "config.hpp"

#include <fgsr/client.h>

#include <cstdint>
#include <string>
#include <vector>

namespace fgsr::layer {

struct SessionShape {
    uint32_t width = 0, height = 0;
    fgsr_color_format format = FGSR_COLOR_RGBA8_SRGB;
    Mode mode = Mode::interpolate;
    uint32_t multiplier = 2;
    std::string socket_path;
    Motion motion = Motion::full;
    bool operator==(const SessionShape&) const = default;
};

class DaemonLink {
  public:
    static constexpr uint64_t kRetryNs = 2'000'000'000;

    DaemonLink() = default;
    ~DaemonLink();
    DaemonLink(const DaemonLink&) = delete;
    DaemonLink& operator=(const DaemonLink&) = delete;

    // Makes sure a session of `shape` exists (connecting, or re-creating it when the shape changed);
    // true when one does. Tries at most every kRetryNs after a failure.
    bool ensure(const SessionShape& shape, uint64_t now_ns);
    // Tears the session and the connection down after `status` (DISCONNECTED, ...), logging once.
    void fail(fgsr_status status, const char* what, uint64_t now_ns);

    fgsr_session* session() const { return session_; }
    const fgsr_pool_layout& layout() const { return layout_; }
    const SessionShape& shape() const { return shape_; }
    // Input slots whose depth plane was zero-filled since the session began (older protocol only).
    std::vector<bool>& depth_cleared() { return depth_cleared_; }

  private:
    void close();

    fgsr_connection* connection_ = nullptr;
    fgsr_session* session_ = nullptr;
    fgsr_pool_layout layout_{};
    SessionShape shape_;
    std::string connected_socket_;
    uint64_t retry_at_ns_ = 0;
    bool unavailable_logged_ = false;
    bool old_daemon_logged_ = false; // motion = "fast" asked of a daemon that predates it
    std::vector<bool> depth_cleared_;
};

} // namespace fgsr::layer
