// fgsrd: the fgsr service. See server.hpp and README.md ("fgsrd").
#include "log.hpp"
#include "server.hpp"

#include <CLI/CLI.hpp>

#include <malloc.h>

int main(int argc, char** argv) {
    // Frames, images and staging copies (hundreds of KiB to hundreds of MiB) are allocated and
    // freed for every frame, on several threads. glibc's dynamic mmap threshold moves such blocks
    // onto the heaps after the first free, where they fragment them: a soak of back-to-back replays
    // grew the idle daemon's RSS by about 400 kB/min that way, and not at all with the threshold
    // fixed (docs/RELIABILITY.md, "Soak"). Fixed thresholds keep every block from 128 KiB up in its
    // own mapping, returned at free, and the heaps trimmed.
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
    fgsrd::Options opt;
    std::string level = "info";
    bool no_zero_copy = false;
    CLI::App app{"fgsrd: the fgsr frame-generation and super-resolution service.\n"
                 "Clients connect over a SOCK_SEQPACKET Unix socket (fgsr/protocol.h) and exchange frames "
                 "through shared memory. Supports systemd socket activation (LISTEN_FDS)."};
    app.add_option("--socket", opt.socket_path, "Socket path (default $XDG_RUNTIME_DIR/fgsr/fgsrd.sock)");
    app.add_option("--device", opt.device,
                   "Vulkan device: index or name substring (default $FGSR_DEVICE, else the first GPU)");
    app.add_option("--log-level", level, "debug, info, warn, error or off")
        ->check(CLI::IsMember({"debug", "info", "warn", "error", "off"}));
    app.add_option("--max-clients", opt.max_clients, "Connections served at once (more get BUSY)")
        ->check(CLI::Range(1u, 4096u));
    app.add_option("--hello-timeout", opt.hello_timeout_s,
                   "Seconds a connection may take to say HELLO before it is closed")
        ->check(CLI::Range(0.01, 3600.0))
        ->capture_default_str();
    app.add_option("--max-pending", opt.max_pending,
                   "Connections waiting for their HELLO at once (a new one closes the oldest)")
        ->check(CLI::Range(1u, 4096u))
        ->capture_default_str();
    app.add_option("--idle-timeout", opt.idle_timeout_s,
                   "Seconds a served connection may send no message and no frame before it is closed")
        ->check(CLI::Range(0.01, 86400.0))
        ->capture_default_str();
    app.add_option("--max-clients-per-uid", opt.max_clients_per_uid, "Connections served at once per user")
        ->check(CLI::Range(1u, 4096u))
        ->capture_default_str();
    app.add_option("--max-sessions-per-uid", opt.max_sessions_per_uid, "Sessions at once per user")
        ->check(CLI::Range(1u, 65536u))
        ->capture_default_str();
    app.add_option("--max-session-pixels", opt.max_session_pixels,
                   "Largest frame of a session (input or output), in pixels (more: UNSUPPORTED)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 32))
        ->capture_default_str();
    uint64_t session_mib = 0, total_mib = 0;
    app.add_option(
           "--max-session-memory", session_mib,
           "Estimated memory of one session, MiB (more: UNSUPPORTED; default half the machine's memory)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 30));
    app.add_option("--max-total-memory", total_mib,
                   "Estimated memory of all sessions, MiB (more: BUSY; default three quarters of the "
                   "machine's memory)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 30));
    app.add_option("--interactive-pixels", opt.interactive_pixels,
                   "Sessions with larger frames run on the bulk lane, at lower CPU priority")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 32))
        ->capture_default_str();
    app.add_option("--bulk-nice", opt.bulk_nice, "Nice increment of the bulk lane's threads")
        ->check(CLI::Range(0, 19))
        ->capture_default_str();
    app.add_option("--shutdown-grace", opt.shutdown_grace_s,
                   "Seconds to wait at shutdown for frames still running before exiting without them")
        ->check(CLI::Range(0.0, 3600.0))
        ->capture_default_str();
    app.add_option("--spin-us", opt.spin_us,
                   "Microseconds the I/O thread polls for the next event after handling one, before it "
                   "sleeps (lower latency for some CPU time; 0: never)")
        ->check(CLI::Range(0u, 1000u))
        ->capture_default_str();
    app.add_flag("--allow-any-user", opt.allow_any_user,
                 "Serve clients of any uid (default: only this user, checked with SO_PEERCRED)");
    app.add_flag("--no-zero-copy", no_zero_copy, "Always copy inputs through a staging buffer");
    app.add_flag("--warm-up", opt.warm_up,
                 "Before listening, create every pipeline and run small sessions through the engine so "
                 "that the driver compiles its pipelines then, not during the first clients' frames "
                 "(lavapipe on 2 cores: about 30 s on a cold shader cache, about 4 s on a warm one)");
    app.add_option("--http", opt.http_address,
                   "Serve the telemetry dashboard, /metrics and /trace.json on HOST:PORT (read-only; port 0 "
                   "picks one; the URL is printed on stdout). Off by default");
    app.add_flag("--http-allow-remote", opt.http_allow_remote,
                 "Let --http listen on an address other machines can reach (default: loopback only)");
    app.add_option("--telemetry-window", opt.telemetry_window_s,
                   "Seconds of frames the dashboard and /trace.json keep")
        ->check(CLI::Range(1.0, 3600.0))
        ->capture_default_str();
    app.add_option("--trace-seconds", opt.trace_seconds, "Default span of /trace.json, seconds")
        ->check(CLI::Range(0.1, 3600.0))
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    opt.zero_copy = !no_zero_copy;
    opt.max_session_memory = session_mib << 20;
    opt.max_total_memory = total_mib << 20;
    fgsrd::log::parse_level(level, fgsrd::log::threshold());
    return fgsrd::run_server(opt);
}
