// libfgsr_client, the connection: the socket, the handshake (fgsr_connect), one request/reply
// exchange at a time (fgsr_connection::request), and the helpers every part of the library uses.
// Sessions: session.cpp; frames and rings: frames.cpp; recording: record.cpp.
//
// Everything the daemon can write (control replies, ring entries, ring positions) is copied into
// private memory once and validated there; nothing validated is read again from shared memory.
// No exception leaves this library: every exported function catches at its boundary (guarded:
// std::bad_alloc becomes OUT_OF_MEMORY, anything else INTERNAL).
#include "client_internal.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/ipc/socket.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace fgsr::client {

int ms_left(uint64_t deadline_ns) {
    const uint64_t t = monotonic_ns();
    if (t >= deadline_ns) return 0;
    return int(std::min<uint64_t>((deadline_ns - t + 999999) / 1000000, 1u << 30));
}

uint64_t wait_spin_ns_from_env() {
    const char* v = std::getenv("FGSR_WAIT_SPIN_US");
    if (!v || !*v) return uint64_t(kDefaultWaitSpinUs) * 1000;
    char* end = nullptr;
    errno = 0;
    const unsigned long us = std::strtoul(v, &end, 10);
    if (errno != 0 || *end != '\0' || *v == '-' || us > 1000) {
        log_line("FGSR_WAIT_SPIN_US=%s: not a whole number of microseconds from 0 to 1000; using %lu", v,
                 kDefaultWaitSpinUs);
        return uint64_t(kDefaultWaitSpinUs) * 1000;
    }
    return uint64_t(us) * 1000;
}

void log_line(const char* fmt, const char* a, unsigned long b, unsigned long c) {
    if (std::getenv("FGSR_CLIENT_QUIET")) return;
    std::fprintf(stderr, "fgsr_client: ");
    std::fprintf(stderr, fmt, a, b, c);
    std::fputc('\n', stderr);
}

fgsr_status peer_status(int32_t s) {
    if (s <= FGSR_STATUS_OK || s >= FGSR_STATUS_COUNT_) return FGSR_STATUS_PROTOCOL_ERROR;
    return fgsr_status(s);
}

namespace {

bool is_disconnect_errno(int e) {
    return e == EPIPE || e == ECONNRESET || e == ENOTCONN || e == ECONNABORTED;
}

fgsr_status send_packet(int sock, const void* msg, size_t size) {
    const ssize_t n = fgsr::ipc::send_with_fds(sock, msg, size);
    if (n < 0) return is_disconnect_errno(errno) ? FGSR_STATUS_DISCONNECTED : FGSR_STATUS_INTERNAL;
    if (size_t(n) != size) return FGSR_STATUS_DISCONNECTED;
    return FGSR_STATUS_OK;
}
// Waits for the socket to become readable; OK, TIMEOUT or DISCONNECTED (hang-up without data is
// reported by the following recv as 0).
fgsr_status wait_readable(int sock, uint64_t deadline_ns) {
    for (;;) {
        pollfd p{sock, POLLIN, 0};
        const int r = ::poll(&p, 1, ms_left(deadline_ns));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return FGSR_STATUS_INTERNAL;
        if (r == 0) return FGSR_STATUS_TIMEOUT;
        return FGSR_STATUS_OK;
    }
}

void fill_header(void* msg, uint16_t type, uint32_t size, uint32_t sequence) {
    const fgsr_msg_header h = fgsr_msg_header_for(type, size, sequence);
    std::memcpy(msg, &h, sizeof(h));
}

std::string default_socket_path() {
    if (const char* s = std::getenv("FGSR_SOCKET"); s && *s) return s;
    if (const char* x = std::getenv("XDG_RUNTIME_DIR"); x && *x) return std::string(x) + "/fgsr/fgsrd.sock";
    return {};
}

std::string program_name() {
    char buf[256];
    const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof(buf) - 1);
    if (n <= 0) return "client";
    buf[n] = '\0';
    const char* slash = std::strrchr(buf, '/');
    return slash ? slash + 1 : buf;
}

} // namespace

} // namespace fgsr::client

using namespace fgsr::client;
using fgsr::monotonic_ns;

fgsr_status fgsr_connection::request(void* msg, uint32_t size, uint16_t type, void* reply,
                                     uint32_t reply_size, uint16_t reply_type, std::vector<Fd>* fds,
                                     uint32_t timeout_ms) {
    if (dead) return FGSR_STATUS_DISCONNECTED;
    const uint32_t seq = next_request++;
    fill_header(msg, type, size, seq);
    fgsr_status st = send_packet(sock.get(), msg, size);
    if (st != FGSR_STATUS_OK) {
        dead = st == FGSR_STATUS_DISCONNECTED || dead;
        return st;
    }
    const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
    alignas(8) unsigned char buf[FGSR_MAX_MESSAGE_SIZE];
    std::vector<Fd> received;
    st = wait_readable(sock.get(), deadline);
    if (st != FGSR_STATUS_OK) {
        // A reply that is late would desynchronise every later exchange: give the connection up.
        if (st == FGSR_STATUS_TIMEOUT) dead = true;
        return st;
    }
    const ssize_t n = fgsr::ipc::recv_with_fds(sock.get(), buf, sizeof(buf), received);
    if (n == 0 || (n < 0 && is_disconnect_errno(errno))) {
        dead = true;
        return FGSR_STATUS_DISCONNECTED;
    }
    if (n < 0 || size_t(n) < sizeof(fgsr_msg_header)) {
        dead = true;
        return FGSR_STATUS_PROTOCOL_ERROR;
    }
    fgsr_msg_header h;
    std::memcpy(&h, buf, sizeof(h));
    if (h.magic != FGSR_PROTOCOL_MAGIC || h.size != uint32_t(n)) {
        dead = true;
        return FGSR_STATUS_PROTOCOL_ERROR;
    }
    if (h.type == FGSR_MSG_ERROR) {
        // The daemon refuses this client (and may close): its status says why.
        fgsr_reply r{};
        std::memcpy(&r, buf, std::min(sizeof(r), size_t(n)));
        r.reason[sizeof(r.reason) - 1] = '\0';
        log_line("fgsrd: %s", r.reason);
        dead = true;
        return size_t(n) >= offsetof(fgsr_reply, session_id) ? peer_status(r.status)
                                                             : FGSR_STATUS_PROTOCOL_ERROR;
    }
    if (h.type != reply_type || h.sequence != seq || size_t(n) < reply_size || (!fds && !received.empty())) {
        dead = true;
        return FGSR_STATUS_PROTOCOL_ERROR;
    }
    std::memcpy(reply, buf, reply_size);
    if (fds)
        for (Fd& f : received) fds->push_back(std::move(f));
    return FGSR_STATUS_OK;
}

fgsr_status fgsr_connection::destroy_session(uint32_t session_id) {
    fgsr_session_ref ref{};
    ref.session_id = session_id;
    fgsr_reply r{};
    std::lock_guard<std::mutex> lock(mutex);
    return request(&ref, sizeof(ref), FGSR_MSG_DESTROY_SESSION, &r, sizeof(r), FGSR_MSG_DESTROY_SESSION_REPLY,
                   nullptr, kDefaultTimeoutMs);
}

extern "C" {

fgsr_status fgsr_connect(const fgsr_connect_info* info, fgsr_connection** out) {
    if (!out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = nullptr;
    return guarded([&]() -> fgsr_status {
        if (info && info->struct_size < sizeof(fgsr_connect_info)) return FGSR_STATUS_INVALID_ARGUMENT;
        const std::string path =
            info && info->socket_path ? std::string(info->socket_path) : default_socket_path();
        const uint32_t timeout = info && info->timeout_ms ? info->timeout_ms : kDefaultTimeoutMs;
        if (path.empty()) return FGSR_STATUS_DAEMON_UNAVAILABLE; // neither variable set
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        if (path.size() >= sizeof(addr.sun_path)) return FGSR_STATUS_INVALID_ARGUMENT;
        std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);

        auto c = std::make_unique<fgsr_connection>();
        c->sock = Fd(::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
        if (!c->sock.valid())
            return errno == ENOMEM || errno == ENFILE || errno == EMFILE ? FGSR_STATUS_OUT_OF_MEMORY
                                                                         : FGSR_STATUS_INTERNAL;
        int r;
        do {
            r = ::connect(c->sock.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
        } while (r < 0 && errno == EINTR);
        if (r < 0) {
            if (errno == EACCES || errno == EPERM) return FGSR_STATUS_PERMISSION_DENIED;
            if (errno == EAGAIN) return FGSR_STATUS_BUSY; // listen backlog full
            return FGSR_STATUS_DAEMON_UNAVAILABLE;        // ENOENT, ECONNREFUSED, ENOTDIR, EPROTOTYPE...
        }
        c->name = info && info->client_name ? info->client_name : program_name();

        fgsr_hello hello{};
        hello.major = FGSR_PROTOCOL_MAJOR;
        hello.minor = FGSR_PROTOCOL_MINOR;
        hello.capabilities = FGSR_CAP_SR | FGSR_CAP_INTERPOLATE | FGSR_CAP_EXTRAPOLATE |
                             FGSR_CAP_ZERO_COPY_INPUT | FGSR_CAP_CALIBRATED_TIME;
        hello.pid = uint32_t(::getpid());
        std::snprintf(hello.name, sizeof(hello.name), "%s", c->name.c_str());
        // The reply is read in two steps: its version fields sit at the same offsets in every
        // major version, the rest is interpreted only for ours.
        fgsr_hello_reply reply{};
        fgsr_status st;
        {
            std::lock_guard<std::mutex> lock(c->mutex);
            const uint32_t seq = c->next_request++;
            fill_header(&hello, FGSR_MSG_HELLO, sizeof(hello), seq);
            st = send_packet(c->sock.get(), &hello, sizeof(hello));
            if (st != FGSR_STATUS_OK) return st;
            st = wait_readable(c->sock.get(), monotonic_ns() + uint64_t(timeout) * 1000000ull);
            if (st != FGSR_STATUS_OK) return st;
            alignas(8) unsigned char buf[FGSR_MAX_MESSAGE_SIZE];
            std::vector<Fd> fds;
            const ssize_t n = fgsr::ipc::recv_with_fds(c->sock.get(), buf, sizeof(buf), fds);
            if (n == 0 || (n < 0 && is_disconnect_errno(errno))) return FGSR_STATUS_DISCONNECTED;
            if (n < 0 || size_t(n) < offsetof(fgsr_hello_reply, capabilities) || !fds.empty())
                return FGSR_STATUS_PROTOCOL_ERROR;
            std::memcpy(&reply, buf, std::min(size_t(n), sizeof(reply)));
            if (reply.header.magic != FGSR_PROTOCOL_MAGIC || reply.header.size != uint32_t(n))
                return FGSR_STATUS_PROTOCOL_ERROR;
            if (reply.header.type == FGSR_MSG_ERROR) {
                fgsr_reply e{};
                std::memcpy(&e, buf, std::min(size_t(n), sizeof(e)));
                return peer_status(e.status);
            }
            if (reply.header.type != FGSR_MSG_HELLO_REPLY || reply.header.sequence != seq)
                return FGSR_STATUS_PROTOCOL_ERROR;
            if (reply.major != FGSR_PROTOCOL_MAJOR) {
                log_line("fgsrd at %s speaks protocol %lu.%lu", path.c_str(), reply.major, reply.minor);
                return FGSR_STATUS_VERSION_MISMATCH;
            }
            if (size_t(n) < sizeof(fgsr_hello_reply)) return FGSR_STATUS_PROTOCOL_ERROR;
        }
        if (reply.status != FGSR_STATUS_OK) {
            const fgsr_status s = peer_status(reply.status);
            return s == FGSR_STATUS_VERSION_MISMATCH || s == FGSR_STATUS_PERMISSION_DENIED ||
                           s == FGSR_STATUS_BUSY
                       ? s
                       : FGSR_STATUS_PROTOCOL_ERROR;
        }
        c->info.major = reply.major;
        c->info.minor = reply.minor;
        c->info.capabilities = reply.capabilities;
        c->info.epoch = reply.epoch;
        std::memcpy(c->info.device, reply.device, sizeof(c->info.device));
        c->info.device[sizeof(c->info.device) - 1] = '\0';
        *out = c.release();
        return FGSR_STATUS_OK;
    });
}

void fgsr_disconnect(fgsr_connection* connection) {
    delete connection; // closes the socket; the daemon frees what is left of its sessions
}

fgsr_status fgsr_daemon_info_get(const fgsr_connection* connection, fgsr_daemon_info* out) {
    if (!connection || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = connection->info;
    return FGSR_STATUS_OK;
}

} // extern "C"
