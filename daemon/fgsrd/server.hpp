// fgsrd's server: the listening socket, the clients and their sessions, one event loop.
#pragma once

#include <cstdint>
#include <string>

namespace fgsrd {

struct Options {
    std::string socket_path; // empty: $XDG_RUNTIME_DIR/fgsr/fgsrd.sock (directory created 0700)
    std::string device;      // fgsr::DeviceOptions::device
    uint32_t max_clients = 32;
    uint32_t max_sessions_per_client = 8;
    // Connections that have not said HELLO: closed after hello_timeout_s, and at most
    // max_pending of them (a new one beyond it closes the oldest), so that idle or hostile
    // connections cannot hold the daemon's fds.
    double hello_timeout_s = 5.0;
    uint32_t max_pending = 64;
    bool allow_any_user = false; // else only peers with the daemon's uid (SO_PEERCRED)
    bool zero_copy = true;       // import input pools into the device where it can
};

// Runs until SIGTERM or SIGINT. Returns the process exit status (0 after a clean shutdown).
int run_server(const Options& options);

} // namespace fgsrd
