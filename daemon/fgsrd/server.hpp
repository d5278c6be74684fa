// fgsrd's server: the listening socket, the clients and their sessions, one event loop, and the
// lanes that run the engine (lane.hpp).
#pragma once

#include <cstdint>
#include <string>

namespace fgsrd {

struct Options {
    std::string socket_path; // empty: $XDG_RUNTIME_DIR/fgsr/fgsrd.sock (directory created 0700)
    std::string device;      // fgsr::DeviceOptions::device
    uint32_t max_clients = 32;
    uint32_t max_sessions_per_client = 8;
    // Per uid (SO_PEERCRED): served connections and sessions, so that with --allow-any-user no
    // user can take every place.
    uint32_t max_clients_per_uid = 16;
    uint32_t max_sessions_per_uid = 32;
    // Connections that have not said HELLO: closed after hello_timeout_s, and at most
    // max_pending of them (a new one beyond it closes the oldest), so that idle or hostile
    // connections cannot hold the daemon's fds.
    double hello_timeout_s = 5.0;
    uint32_t max_pending = 64;
    // A served connection that sends no message and no frame for idle_timeout_s is closed; and
    // when the daemon is full, a HELLO evicts the connection without sessions idle the longest
    // (idle at least one second).
    double idle_timeout_s = 120.0;
    // Per-session limits: the larger of the input and the output frame, in pixels, and the
    // session's memory (shared pools and the engine's buffers, estimated before anything is
    // allocated); and the memory of all sessions together (beyond it: BUSY). 0: from the
    // machine's memory at start (a session half of it, all sessions three quarters).
    uint64_t max_session_pixels = 4096ull * 4096ull;
    uint64_t max_session_memory = 0;
    uint64_t max_total_memory = 0;
    // Sessions whose larger frame has more pixels than this run on the bulk lane, at lower CPU
    // priority, so that they cannot hold up the frames of small sessions.
    uint64_t interactive_pixels = 1920ull * 1080ull;
    int bulk_nice = 10;
    // After SIGTERM/SIGINT: clients are disconnected at once; frames still running after this
    // long are not waited for (the process exits).
    double shutdown_grace_s = 2.0;
    // After a round of the event loop that handled events, while no lane runs a frame, the I/O
    // thread polls for the next event (epoll without waiting) for up to this many microseconds
    // before it sleeps: a client's submit or release that comes within it needs no wake-up. Bounded
    // per round; an idle daemon does not spin. Off by default: the wake-ups it saves cost 5-15 us
    // each on the 2-core VM, and a spin shorter than a frame saves none of them (docs/SERVICE.md,
    // "Spinning").
    uint32_t spin_us = 0;
    bool allow_any_user = false; // else only peers with the daemon's uid (SO_PEERCRED)
    // Before listening, run the engine's warm-up (fgsr::Engine::warm_up): drivers that compile a
    // pipeline at its first dispatch (llvmpipe: seconds per pipeline on a cold shader cache) do
    // it then, not during the first sessions' frames.
    bool warm_up = false;
    bool zero_copy = true;       // import input pools into the device where it can
    // The telemetry dashboard (http_server.hpp): off unless http_address is set ("HOST:PORT",
    // loopback only unless http_allow_remote). The chosen URL is printed on stdout.
    std::string http_address;
    bool http_allow_remote = false;
    double telemetry_window_s = 60; // frames the page and /trace.json can show
    double trace_seconds = 10;      // /trace.json's default span
};

// Runs until SIGTERM or SIGINT. Returns the process exit status (0 after a clean shutdown).
int run_server(const Options& options);

} // namespace fgsrd
