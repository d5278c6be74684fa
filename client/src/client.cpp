// libfgsr_client: the C API of fgsr/client.h over the contract of fgsr/protocol.h.
//
// Everything the daemon can write (control replies, ring entries, ring positions) is copied into
// private memory once and validated there; nothing validated is read again from shared memory.
// No exception leaves this file: every exported function catches at its boundary (std::bad_alloc
// becomes OUT_OF_MEMORY, anything else INTERNAL).
#include "client_internal.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/client.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fcntl.h>
#include <map>
#include <mutex>
#include <new>
#include <poll.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>
#include <vector>

#ifndef F_SEAL_FUTURE_WRITE
#define F_SEAL_FUTURE_WRITE 0x0010
#endif

namespace fgsr::client {

void Fd::reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void Mapping::reset() {
    if (p_) ::munmap(p_, n_);
    p_ = nullptr;
    n_ = 0;
}

size_t color_bytes(uint32_t format) {
    switch (format) {
    case FGSR_COLOR_RGBA8_SRGB:
        return 4;
    case FGSR_COLOR_RGBA16F_LINEAR:
        return 8;
    case FGSR_COLOR_RGBA32F_LINEAR:
        return 16;
    default:
        return 0;
    }
}

size_t mv_bytes(uint32_t format) {
    switch (format) {
    case FGSR_MV_RG16F:
        return 4;
    case FGSR_MV_RG32F:
        return 8;
    default:
        return 0;
    }
}

namespace {

constexpr uint32_t kDefaultTimeoutMs = 5000;
constexpr uint32_t kMaxRingCapacity = 4096;

// Milliseconds left until `deadline_ns` (0 when passed), for poll().
int ms_left(uint64_t deadline_ns) {
    const uint64_t t = monotonic_ns();
    if (t >= deadline_ns) return 0;
    return int(std::min<uint64_t>((deadline_ns - t + 999999) / 1000000, 1u << 30));
}

void log_line(const char* fmt, const char* a, unsigned long b = 0, unsigned long c = 0) {
    if (std::getenv("FGSR_CLIENT_QUIET")) return;
    std::fprintf(stderr, "fgsr_client: ");
    std::fprintf(stderr, fmt, a, b, c);
    std::fputc('\n', stderr);
}

bool is_disconnect_errno(int e) {
    return e == EPIPE || e == ECONNRESET || e == ENOTCONN || e == ECONNABORTED;
}

bool valid_color_format(uint32_t f) {
    return color_bytes(f) != 0;
}

bool finite_in(float v, float lo, float hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
}

} // namespace

} // namespace fgsr::client

using namespace fgsr::client;
using fgsr::monotonic_ns;

struct fgsr_connection {
    Fd sock;
    std::mutex mutex; // one request/reply exchange at a time (sessions may be on other threads)
    uint32_t next_request = 1;
    bool dead = false; // the daemon went away or violated the protocol; guarded by mutex
    fgsr_daemon_info info{};
    std::string name;

    // Sends `msg` (header filled here) and receives the reply of type `reply_type` into `reply`
    // (exactly reply_size bytes are kept; a longer reply from a newer minor version is cut).
    // fds received with it are appended to `fds` (nullptr: any fd is an error).
    fgsr_status request(void* msg, uint32_t size, uint16_t type, void* reply, uint32_t reply_size,
                        uint16_t reply_type, std::vector<Fd>* fds, uint32_t timeout_ms);
};

namespace {

// Receives one packet with its fds (MSG_CMSG_CLOEXEC); every received fd ends up owned by `fds`
// (closed by the caller on any error). Returns the packet length, 0 for an orderly close, or -1
// with errno (EMSGSIZE: truncated packet, EPROTO: truncated control data).
ssize_t recv_packet(int sock, void* buf, size_t cap, std::vector<Fd>& fds) {
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int) * (FGSR_FD_COUNT + 3))];
    iovec iov{buf, cap};
    msghdr mh{};
    mh.msg_iov = &iov;
    mh.msg_iovlen = 1;
    mh.msg_control = control;
    mh.msg_controllen = sizeof(control);
    ssize_t n;
    do {
        n = ::recvmsg(sock, &mh, MSG_CMSG_CLOEXEC);
    } while (n < 0 && errno == EINTR);
    if (n < 0) return -1;
    for (cmsghdr* c = CMSG_FIRSTHDR(&mh); c; c = CMSG_NXTHDR(&mh, c)) {
        if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_RIGHTS) continue;
        const size_t count = (c->cmsg_len - CMSG_LEN(0)) / sizeof(int);
        for (size_t i = 0; i < count; ++i) {
            int fd;
            std::memcpy(&fd, CMSG_DATA(c) + i * sizeof(int), sizeof(int));
            fds.emplace_back(fd);
        }
    }
    if (mh.msg_flags & MSG_TRUNC) {
        errno = EMSGSIZE;
        return -1;
    }
    if (mh.msg_flags & MSG_CTRUNC) {
        errno = EPROTO;
        return -1;
    }
    return n;
}

fgsr_status send_packet(int sock, const void* msg, size_t size) {
    ssize_t n;
    do {
        n = ::send(sock, msg, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
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
    fgsr_msg_header h{};
    h.magic = FGSR_PROTOCOL_MAGIC;
    h.type = type;
    h.size = size;
    h.sequence = sequence;
    std::memcpy(msg, &h, sizeof(h));
}

// A status the daemon sent, checked against the statuses the API may return for the request.
fgsr_status peer_status(int32_t s) {
    if (s <= FGSR_STATUS_OK || s >= FGSR_STATUS_COUNT_) return FGSR_STATUS_PROTOCOL_ERROR;
    return fgsr_status(s);
}

} // namespace

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
    const ssize_t n = recv_packet(sock.get(), buf, sizeof(buf), received);
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

namespace {

enum class InputState : uint8_t { free, acquired, submitted };

struct Outstanding {
    uint32_t input_slot;
    uint32_t outputs_seen;
};

} // namespace

struct fgsr_session {
    fgsr_connection* conn = nullptr;
    uint32_t id = 0;
    fgsr_session_desc desc{};
    fgsr_pool_layout layout{};
    Fd fds[FGSR_FD_COUNT];
    Mapping input, output, rings;
    fgsr_ring_header* submit_hdr = nullptr;
    fgsr_submit_entry* submit_ring = nullptr;
    fgsr_ring_header* completion_hdr = nullptr;
    const fgsr_completion_entry* completion_ring = nullptr;
    fgsr_ring_header* release_hdr = nullptr;
    fgsr_release_entry* release_ring = nullptr;
    // Private copies of the positions this side writes (never read back from shared memory).
    uint64_t submit_head = 0, completion_tail = 0, release_head = 0;
    uint64_t next_sequence = 1;
    InputState inputs[FGSR_MAX_SLOTS] = {};
    bool output_held[FGSR_MAX_SLOTS] = {};
    std::map<uint64_t, Outstanding> outstanding; // submitted sequences without their LAST completion
    std::deque<fgsr_completion_entry> ready;     // validated completions not yet returned by wait
    fgsr_status broken = FGSR_STATUS_OK;         // DISCONNECTED or PROTOCOL_ERROR once it happened
    std::unique_ptr<Recorder> recorder;
    std::string record_dir;

    fgsr_status pump();
    fgsr_status wait_event(uint64_t deadline_ns);
    fgsr_status fail(fgsr_status s) {
        if (broken == FGSR_STATUS_OK) broken = s;
        return s;
    }
    void stop_recording() {
        if (!recorder) return;
        if (recorder->finish() != FGSR_STATUS_OK) log_line("recording: %s", recorder->error().c_str());
        recorder.reset();
    }
};

// Copies every new completion out of the ring, validates it, applies input releases, queues it.
fgsr_status fgsr_session::pump() {
    if (broken != FGSR_STATUS_OK) return broken;
    // Clear the eventfd before reading the ring: a push after the drain signals again.
    pollfd p{fds[FGSR_FD_COMPLETE_EVENT].get(), POLLIN, 0};
    if (::poll(&p, 1, 0) == 1 && (p.revents & POLLIN)) {
        uint64_t v;
        if (::read(p.fd, &v, sizeof(v)) < 0 && errno != EAGAIN && errno != EINTR)
            return fail(FGSR_STATUS_INTERNAL);
    }
    const uint64_t head = fgsr_ring_load_head(completion_hdr);
    const uint64_t avail = head - completion_tail;
    if (avail > layout.ring_capacity) return fail(FGSR_STATUS_PROTOCOL_ERROR);
    for (uint64_t pos = completion_tail; pos != head; ++pos) {
        fgsr_completion_entry e;
        std::memcpy(&e, &completion_ring[fgsr_ring_index(pos, layout.ring_capacity)], sizeof(e));
        completion_tail = pos + 1;
        fgsr_ring_consume(completion_hdr, completion_tail);
        auto it = outstanding.find(e.sequence);
        if (it == outstanding.end()) return fail(FGSR_STATUS_PROTOCOL_ERROR);
        if (e.status < FGSR_STATUS_OK || e.status >= FGSR_STATUS_COUNT_)
            return fail(FGSR_STATUS_PROTOCOL_ERROR);
        if (e.output_slot != FGSR_NO_SLOT) {
            if (e.output_slot >= layout.output_slot_count || output_held[e.output_slot] ||
                e.status != FGSR_STATUS_OK)
                return fail(FGSR_STATUS_PROTOCOL_ERROR);
            output_held[e.output_slot] = true;
        }
        if (e.output_index >= 2 * FGSR_MAX_ALPHAS + 1 || e.telemetry.pass_count > FGSR_MAX_PASSES)
            return fail(FGSR_STATUS_PROTOCOL_ERROR);
        ++it->second.outputs_seen;
        if ((e.flags & FGSR_COMPLETION_INPUT_RELEASED) != 0) {
            if (e.input_slot != it->second.input_slot || !(e.flags & FGSR_COMPLETION_LAST))
                return fail(FGSR_STATUS_PROTOCOL_ERROR);
            inputs[e.input_slot] = InputState::free;
        }
        if ((e.flags & FGSR_COMPLETION_LAST) != 0) {
            if (!(e.flags & FGSR_COMPLETION_INPUT_RELEASED)) return fail(FGSR_STATUS_PROTOCOL_ERROR);
            outstanding.erase(it);
        }
        ready.push_back(e);
    }
    return FGSR_STATUS_OK;
}

// Waits until the complete eventfd is readable (OK), the deadline passes (TIMEOUT) or the
// daemon hangs up (DISCONNECTED).
fgsr_status fgsr_session::wait_event(uint64_t deadline_ns) {
    for (;;) {
        pollfd p[2] = {{fds[FGSR_FD_COMPLETE_EVENT].get(), POLLIN, 0}, {conn->sock.get(), 0, 0}};
        const int r = ::poll(p, 2, ms_left(deadline_ns));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return fail(FGSR_STATUS_INTERNAL);
        if (p[0].revents & POLLIN) return FGSR_STATUS_OK;
        if (p[1].revents & (POLLHUP | POLLERR | POLLNVAL)) {
            // Completions pushed before the daemon went away are still returned first.
            if (pump() == FGSR_STATUS_OK && !ready.empty()) return FGSR_STATUS_OK;
            std::lock_guard<std::mutex> lock(conn->mutex);
            conn->dead = true;
            return fail(FGSR_STATUS_DISCONNECTED);
        }
        if (r == 0) return FGSR_STATUS_TIMEOUT;
    }
}

namespace {

// Runs `f` and turns any exception into a status: nothing throws across the C API.
template <class F> fgsr_status guarded(F&& f) noexcept {
    try {
        return f();
    } catch (const std::bad_alloc&) {
        return FGSR_STATUS_OUT_OF_MEMORY;
    } catch (...) {
        return FGSR_STATUS_INTERNAL;
    }
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

bool is_eventfd(int fd) {
    char path[64], target[64];
    std::snprintf(path, sizeof(path), "/proc/self/fd/%d", fd);
    const ssize_t n = ::readlink(path, target, sizeof(target) - 1);
    if (n <= 0) return false;
    target[n] = '\0';
    return std::strcmp(target, "anon_inode:[eventfd]") == 0;
}

// The session description with defaults applied, or INVALID_ARGUMENT.
fgsr_status normalise_desc(const fgsr_session_desc& in, fgsr_session_desc& d) {
    if (in.struct_size < sizeof(fgsr_session_desc)) return FGSR_STATUS_INVALID_ARGUMENT;
    d = in;
    d.struct_size = sizeof(fgsr_session_desc);
    if (d.input_slots == 0) d.input_slots = 3;
    if (d.output_slots == 0) d.output_slots = 4;
    if (d.ring_capacity == 0) d.ring_capacity = 64;
    const bool ok = d.width >= 1 && d.width <= FGSR_MAX_FRAME_SIDE && d.height >= 1 && d.height <= FGSR_MAX_FRAME_SIDE &&
                    valid_color_format(d.color_format) && mv_bytes(d.mv_format) != 0 &&
                    d.depth_kind <= FGSR_DEPTH_DEVICE_REVERSED && d.mv_units <= FGSR_MV_UV &&
                    d.mv_direction <= FGSR_MV_FROM_PREVIOUS && finite_in(d.scale, 1.f, 4.f) && d.modes != 0 &&
                    (d.modes & ~(FGSR_MODE_SR | FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE)) == 0 &&
                    (!(d.modes & FGSR_MODE_SR) || d.scale > 1.f) && d.queue_policy <= FGSR_QUEUE_MAILBOX &&
                    d.input_slots <= FGSR_MAX_SLOTS && d.output_slots <= FGSR_MAX_SLOTS &&
                    valid_color_format(d.output_format) && (d.ring_capacity & (d.ring_capacity - 1)) == 0 &&
                    d.ring_capacity <= kMaxRingCapacity &&
                    d.ring_capacity >= std::max(d.input_slots, d.output_slots) &&
                    std::isfinite(d.near_plane) && !std::isnan(d.far_plane) && std::isfinite(d.t_depth) &&
                    std::isfinite(d.t_bright) && std::isfinite(d.sr_a) && std::isfinite(d.sr_b);
    return ok ? FGSR_STATUS_OK : FGSR_STATUS_INVALID_ARGUMENT;
}

bool plane_ok(const fgsr_plane& p, uint32_t w, uint32_t h, size_t bpp, uint32_t format,
              uint64_t slot_stride) {
    if (p.offset % FGSR_PLANE_ALIGNMENT != 0 || p.format != format || bpp == 0) return false;
    if (uint64_t(p.row_pitch) < uint64_t(w) * bpp) return false;
    if (p.size < uint64_t(p.row_pitch) * h) return false;
    return p.offset <= slot_stride && p.size <= slot_stride - p.offset;
}

bool disjoint(const fgsr_plane& a, const fgsr_plane& b) {
    return a.offset + a.size <= b.offset || b.offset + b.size <= a.offset;
}

bool mul_ok(uint64_t a, uint64_t b, uint64_t expect) {
    uint64_t r;
    return !__builtin_mul_overflow(a, b, &r) && r == expect;
}

// Checks the daemon's layout against the request (see fgsr_pool_layout in protocol.h).
bool layout_ok(const fgsr_pool_layout& l, const fgsr_session_desc& d) {
    const uint64_t ow = uint64_t(std::lround(double(d.width) * double(d.scale)));
    const uint64_t oh = uint64_t(std::lround(double(d.height) * double(d.scale)));
    if (l.input_slot_count != d.input_slots || l.output_slot_count != d.output_slots ||
        l.ring_capacity != d.ring_capacity || l.output_width != ow || l.output_height != oh)
        return false;
    if (l.input_slot_stride == 0 || l.input_slot_stride % FGSR_PLANE_ALIGNMENT != 0 ||
        l.output_slot_stride == 0 || l.output_slot_stride % FGSR_PLANE_ALIGNMENT != 0)
        return false;
    if (!mul_ok(l.input_slot_count, l.input_slot_stride, l.input_pool_size) ||
        !mul_ok(l.output_slot_count, l.output_slot_stride, l.output_pool_size))
        return false;
    if (l.input_pool_size > (uint64_t(1) << 40) || l.output_pool_size > (uint64_t(1) << 40)) return false;
    if (!plane_ok(l.color, d.width, d.height, color_bytes(d.color_format), d.color_format,
                  l.input_slot_stride) ||
        !plane_ok(l.depth, d.width, d.height, 4, 0, l.input_slot_stride) ||
        !plane_ok(l.mv, d.width, d.height, mv_bytes(d.mv_format), d.mv_format, l.input_slot_stride) ||
        !plane_ok(l.output, l.output_width, l.output_height, color_bytes(d.output_format), d.output_format,
                  l.output_slot_stride))
        return false;
    if (!disjoint(l.color, l.depth) || !disjoint(l.color, l.mv) || !disjoint(l.depth, l.mv)) return false;
    return l.rings_size == fgsr_rings_layout_for(l.ring_capacity).total_size;
}

// fstat and seals of a pool memfd: a regular file of at least `size` bytes with `seals`.
bool memfd_ok(int fd, uint64_t size, int seals_required, int seals_any_of) {
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) < size) return false;
    if (seals_required == 0 && seals_any_of == 0) return true;
    const int seals = ::fcntl(fd, F_GET_SEALS);
    if (seals < 0 || (seals & seals_required) != seals_required) return false;
    return seals_any_of == 0 || (seals & seals_any_of) != 0;
}

Mapping map_fd(int fd, uint64_t size, int prot) {
    void* p = ::mmap(nullptr, size, prot, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) return {};
    return Mapping(p, size);
}

} // namespace

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
            const ssize_t n = recv_packet(c->sock.get(), buf, sizeof(buf), fds);
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

fgsr_status fgsr_session_create(fgsr_connection* connection, const fgsr_session_desc* desc,
                                fgsr_session** out) {
    if (!out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = nullptr;
    if (!connection || !desc) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        auto s = std::make_unique<fgsr_session>();
        s->conn = connection;
        fgsr_status st = normalise_desc(*desc, s->desc);
        if (st != FGSR_STATUS_OK) return st;
        fgsr_create_session msg{};
        msg.desc = s->desc;
        fgsr_create_session_reply reply{};
        std::vector<Fd> fds;
        {
            std::lock_guard<std::mutex> lock(connection->mutex);
            st = connection->request(&msg, sizeof(msg), FGSR_MSG_CREATE_SESSION, &reply, sizeof(reply),
                                     FGSR_MSG_CREATE_SESSION_REPLY, &fds, kDefaultTimeoutMs);
        }
        if (st != FGSR_STATUS_OK) return st;
        reply.reason[sizeof(reply.reason) - 1] = '\0';
        if (reply.status != FGSR_STATUS_OK) {
            if (reply.reason[0]) log_line("fgsrd refused the session: %s", reply.reason);
            const fgsr_status r = peer_status(reply.status);
            return r == FGSR_STATUS_INVALID_ARGUMENT || r == FGSR_STATUS_UNSUPPORTED ||
                           r == FGSR_STATUS_OUT_OF_MEMORY || r == FGSR_STATUS_BUSY
                       ? r
                       : FGSR_STATUS_PROTOCOL_ERROR;
        }
        // From here on any mismatch is the daemon's fault: every received fd is closed (fds owns
        // them) and the session is destroyed on the daemon's side when we tell it.
        auto refuse = [&](const char* why) {
            log_line("session reply rejected: %s", why);
            fgsr_session_ref ref{};
            ref.session_id = reply.session_id;
            fgsr_reply r{};
            std::lock_guard<std::mutex> lock(connection->mutex);
            (void)connection->request(&ref, sizeof(ref), FGSR_MSG_DESTROY_SESSION, &r, sizeof(r),
                                      FGSR_MSG_DESTROY_SESSION_REPLY, nullptr, kDefaultTimeoutMs);
            return FGSR_STATUS_PROTOCOL_ERROR;
        };
        if (fds.size() != FGSR_FD_COUNT) return refuse("wrong number of fds");
        if (reply.session_id == 0) return refuse("session id 0");
        const fgsr_pool_layout& l = reply.layout;
        if (!layout_ok(l, s->desc)) return refuse("layout does not match the request");
        if (!memfd_ok(fds[FGSR_FD_INPUT_POOL].get(), l.input_pool_size, F_SEAL_SHRINK | F_SEAL_GROW, 0) ||
            !memfd_ok(fds[FGSR_FD_OUTPUT_POOL].get(), l.output_pool_size, F_SEAL_SHRINK | F_SEAL_GROW,
                      F_SEAL_WRITE | F_SEAL_FUTURE_WRITE) ||
            !memfd_ok(fds[FGSR_FD_RINGS].get(), l.rings_size, 0, 0))
            return refuse("pool fds do not match the layout (size, type or seals)");
        if (!is_eventfd(fds[FGSR_FD_SUBMIT_EVENT].get()) || !is_eventfd(fds[FGSR_FD_COMPLETE_EVENT].get()))
            return refuse("event fds are not eventfds");
        s->input = map_fd(fds[FGSR_FD_INPUT_POOL].get(), l.input_pool_size, PROT_READ | PROT_WRITE);
        s->output = map_fd(fds[FGSR_FD_OUTPUT_POOL].get(), l.output_pool_size, PROT_READ);
        s->rings = map_fd(fds[FGSR_FD_RINGS].get(), l.rings_size, PROT_READ | PROT_WRITE);
        if (!s->input.data() || !s->output.data() || !s->rings.data()) return refuse("mmap failed");
        s->id = reply.session_id;
        s->layout = l;
        for (int i = 0; i < FGSR_FD_COUNT; ++i) s->fds[i] = std::move(fds[size_t(i)]);
        const fgsr_rings_layout rl = fgsr_rings_layout_for(l.ring_capacity);
        std::byte* base = s->rings.data();
        s->submit_hdr = reinterpret_cast<fgsr_ring_header*>(base + rl.submit_header);
        s->submit_ring = reinterpret_cast<fgsr_submit_entry*>(base + rl.submit_entries);
        s->completion_hdr = reinterpret_cast<fgsr_ring_header*>(base + rl.completion_header);
        s->completion_ring = reinterpret_cast<const fgsr_completion_entry*>(base + rl.completion_entries);
        s->release_hdr = reinterpret_cast<fgsr_ring_header*>(base + rl.release_header);
        s->release_ring = reinterpret_cast<fgsr_release_entry*>(base + rl.release_entries);
        // Positions start where the daemon left them (0 for a new session).
        s->submit_head = fgsr_ring_load_head(s->submit_hdr);
        s->completion_tail = fgsr_ring_load_tail(s->completion_hdr);
        s->release_head = fgsr_ring_load_head(s->release_hdr);
        if (s->submit_head != 0 || s->completion_tail != 0 || s->release_head != 0)
            return refuse("rings are not empty");
        if (const char* dir = std::getenv("FGSR_CAPTURE"); dir && *dir) {
            std::string reason;
            s->recorder = make_recorder(dir, connection->name, s->desc, reason);
            if (!s->recorder)
                log_line("FGSR_CAPTURE: %s", reason.c_str());
            else
                s->record_dir = dir;
        }
        *out = s.release();
        return FGSR_STATUS_OK;
    });
}

void fgsr_session_destroy(fgsr_session* session) {
    if (!session) return;
    (void)guarded([&]() -> fgsr_status {
        session->stop_recording();
        fgsr_session_ref ref{};
        ref.session_id = session->id;
        fgsr_reply r{};
        std::lock_guard<std::mutex> lock(session->conn->mutex);
        return session->conn->request(&ref, sizeof(ref), FGSR_MSG_DESTROY_SESSION, &r, sizeof(r),
                                      FGSR_MSG_DESTROY_SESSION_REPLY, nullptr, kDefaultTimeoutMs);
    });
    delete session;
}

fgsr_status fgsr_session_layout(const fgsr_session* session, fgsr_pool_layout* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    *out = session->layout;
    return FGSR_STATUS_OK;
}

int fgsr_session_event_fd(const fgsr_session* session) {
    return session ? session->fds[FGSR_FD_COMPLETE_EVENT].get() : -1;
}

fgsr_status fgsr_acquire_input(fgsr_session* session, uint32_t timeout_ms, fgsr_input_slot* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
        for (;;) {
            fgsr_status st = session->pump();
            if (st != FGSR_STATUS_OK) return st;
            for (uint32_t i = 0; i < session->layout.input_slot_count; ++i) {
                if (session->inputs[i] != InputState::free) continue;
                session->inputs[i] = InputState::acquired;
                std::byte* slot = session->input.data() + uint64_t(i) * session->layout.input_slot_stride;
                *out = fgsr_input_slot{};
                out->index = i;
                out->color = slot + session->layout.color.offset;
                out->depth = slot + session->layout.depth.offset;
                out->mv = slot + session->layout.mv.offset;
                return FGSR_STATUS_OK;
            }
            if (ms_left(deadline) == 0) return FGSR_STATUS_NO_SLOT;
            st = session->wait_event(deadline);
            if (st == FGSR_STATUS_TIMEOUT) return FGSR_STATUS_NO_SLOT;
            if (st != FGSR_STATUS_OK) return st;
        }
    });
}

fgsr_status fgsr_submit(fgsr_session* session, const fgsr_submit_info* info, uint64_t* out_sequence) {
    if (!session || !info || info->struct_size < sizeof(fgsr_submit_info))
        return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        if (session->broken != FGSR_STATUS_OK) return session->broken;
        const fgsr_session_desc& d = session->desc;
        if (info->input_slot >= session->layout.input_slot_count ||
            session->inputs[info->input_slot] != InputState::acquired)
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (info->flags & ~(FGSR_SUBMIT_RESET | FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR))
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (info->interp_count > FGSR_MAX_ALPHAS || info->extrap_count > FGSR_MAX_ALPHAS)
            return FGSR_STATUS_INVALID_ARGUMENT;
        if ((info->interp_count && (!(d.modes & FGSR_MODE_INTERPOLATE) || !info->interp_alphas)) ||
            (info->extrap_count && (!(d.modes & FGSR_MODE_EXTRAPOLATE) || !info->extrap_alphas)) ||
            ((info->flags & FGSR_SUBMIT_WANT_SR) && !(d.modes & FGSR_MODE_SR)))
            return FGSR_STATUS_INVALID_ARGUMENT;
        if (!std::isfinite(info->jitter_x) || !std::isfinite(info->jitter_y))
            return FGSR_STATUS_INVALID_ARGUMENT;
        fgsr_submit_entry e{};
        for (uint32_t i = 0; i < info->interp_count; ++i) {
            const float a = info->interp_alphas[i];
            if (!std::isfinite(a) || a <= 0.f || a >= 1.f) return FGSR_STATUS_INVALID_ARGUMENT;
            e.interp_alphas[i] = a;
        }
        for (uint32_t i = 0; i < info->extrap_count; ++i) {
            const float a = info->extrap_alphas[i];
            if (!std::isfinite(a) || a <= 0.f || a > 1.f) return FGSR_STATUS_INVALID_ARGUMENT;
            e.extrap_alphas[i] = a;
        }
        // The daemon consumes submits in order; the ring holds at most one entry per input slot,
        // so a full ring means the daemon misbehaves or lags far behind.
        const uint64_t tail = fgsr_ring_load_tail(session->submit_hdr);
        const uint64_t used = session->submit_head - tail;
        if (used > session->layout.ring_capacity) return session->fail(FGSR_STATUS_PROTOCOL_ERROR);
        if (used == session->layout.ring_capacity) return FGSR_STATUS_NO_SLOT;

        e.sequence = session->next_sequence;
        e.input_slot = info->input_slot;
        e.flags = info->flags;
        e.jitter_x = info->jitter_x;
        e.jitter_y = info->jitter_y;
        e.interp_count = info->interp_count;
        e.extrap_count = info->extrap_count;
        e.present_time_ns = info->present_time_ns;
        e.user_data = info->user_data;
        if (session->recorder) {
            const std::byte* slot =
                session->input.data() + uint64_t(info->input_slot) * session->layout.input_slot_stride;
            if (session->recorder->add(session->layout, slot, e) != FGSR_STATUS_OK) {
                log_line("recording stopped: %s", session->recorder->error().c_str());
                session->recorder.reset();
            }
        }
        e.submit_time_ns = monotonic_ns();
        std::memcpy(
            &session->submit_ring[fgsr_ring_index(session->submit_head, session->layout.ring_capacity)], &e,
            sizeof(e));
        ++session->submit_head;
        fgsr_ring_publish(session->submit_hdr, session->submit_head);
        session->inputs[info->input_slot] = InputState::submitted;
        session->outstanding[e.sequence] = Outstanding{info->input_slot, 0};
        ++session->next_sequence;
        const uint64_t one = 1;
        if (::write(session->fds[FGSR_FD_SUBMIT_EVENT].get(), &one, sizeof(one)) < 0 && errno != EAGAIN)
            return session->fail(FGSR_STATUS_DISCONNECTED);
        if (out_sequence) *out_sequence = e.sequence;
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_wait(fgsr_session* session, uint32_t timeout_ms, fgsr_output* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
        for (;;) {
            if (session->ready.empty()) {
                const fgsr_status st = session->pump();
                if (st != FGSR_STATUS_OK) return st;
            }
            if (!session->ready.empty()) {
                const fgsr_completion_entry e = session->ready.front();
                session->ready.pop_front();
                const fgsr_pool_layout& l = session->layout;
                *out = fgsr_output{};
                out->sequence = e.sequence;
                out->status = e.status;
                out->output_slot = e.output_slot;
                out->output_index = e.output_index;
                out->user_data = e.user_data;
                out->telemetry = e.telemetry;
                out->flags = e.flags;
                if (e.output_slot != FGSR_NO_SLOT) {
                    out->width = l.output_width;
                    out->height = l.output_height;
                    out->row_pitch = l.output.row_pitch;
                    out->format = l.output.format;
                    out->pixels = session->output.data() + uint64_t(e.output_slot) * l.output_slot_stride +
                                  l.output.offset;
                }
                return FGSR_STATUS_OK;
            }
            if (ms_left(deadline) == 0) return FGSR_STATUS_TIMEOUT;
            const fgsr_status st = session->wait_event(deadline);
            if (st != FGSR_STATUS_OK) return st;
        }
    });
}

fgsr_status fgsr_release_output(fgsr_session* session, uint32_t output_slot) {
    if (!session) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        if (output_slot >= session->layout.output_slot_count || !session->output_held[output_slot])
            return FGSR_STATUS_INVALID_ARGUMENT;
        session->output_held[output_slot] = false;
        if (session->broken != FGSR_STATUS_OK) return session->broken;
        const uint64_t tail = fgsr_ring_load_tail(session->release_hdr);
        if (session->release_head - tail >= session->layout.ring_capacity)
            return session->fail(FGSR_STATUS_PROTOCOL_ERROR); // cannot fill up: see ring_capacity
        fgsr_release_entry r{};
        r.output_slot = output_slot;
        std::memcpy(
            &session->release_ring[fgsr_ring_index(session->release_head, session->layout.ring_capacity)], &r,
            sizeof(r));
        ++session->release_head;
        fgsr_ring_publish(session->release_hdr, session->release_head);
        const uint64_t one = 1;
        if (::write(session->fds[FGSR_FD_SUBMIT_EVENT].get(), &one, sizeof(one)) < 0 && errno != EAGAIN)
            return session->fail(FGSR_STATUS_DISCONNECTED);
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_session_stats_get(fgsr_session* session, fgsr_session_stats* out) {
    if (!session || !out) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        fgsr_session_ref ref{};
        ref.session_id = session->id;
        fgsr_stats_reply r{};
        fgsr_status st;
        {
            std::lock_guard<std::mutex> lock(session->conn->mutex);
            st = session->conn->request(&ref, sizeof(ref), FGSR_MSG_STATS, &r, sizeof(r),
                                        FGSR_MSG_STATS_REPLY, nullptr, kDefaultTimeoutMs);
        }
        if (st != FGSR_STATUS_OK) return st;
        if (r.status != FGSR_STATUS_OK) return peer_status(r.status);
        if (r.session_id != session->id) return FGSR_STATUS_PROTOCOL_ERROR;
        *out = r.stats;
        return FGSR_STATUS_OK;
    });
}

fgsr_status fgsr_session_record(fgsr_session* session, const char* dir) {
    if (!session) return FGSR_STATUS_INVALID_ARGUMENT;
    return guarded([&]() -> fgsr_status {
        session->stop_recording();
        if (!dir) return FGSR_STATUS_OK;
        if (!*dir) return FGSR_STATUS_INVALID_ARGUMENT;
        std::string reason;
        session->recorder = make_recorder(dir, session->conn->name, session->desc, reason);
        if (!session->recorder) {
            log_line("recording: %s", reason.c_str());
            return FGSR_STATUS_UNSUPPORTED;
        }
        session->record_dir = dir;
        return FGSR_STATUS_OK;
    });
}

} // extern "C"
