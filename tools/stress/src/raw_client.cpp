// The raw protocol client of `fgsr stress --service` (fgsr/stress/raw_client.hpp).
#include <fgsr/stress/raw_client.hpp>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <poll.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace fgsr::stress::raw {

uint64_t now_ns() {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    return uint64_t(t.tv_sec) * 1000000000ull + uint64_t(t.tv_nsec);
}

double ms_since(uint64_t t0_ns) {
    return double(now_ns() - t0_ns) * 1e-6;
}

Fd& Fd::operator=(Fd&& o) noexcept {
    if (this != &o) {
        if (fd_ >= 0) close(fd_);
        fd_ = std::exchange(o.fd_, -1);
    }
    return *this;
}

Fd::~Fd() {
    if (fd_ >= 0) close(fd_);
}

namespace {

void say(std::string* why, const std::string& what) {
    if (why) *why = what;
}

} // namespace

std::optional<Connection> Connection::connect(const std::string& socket_path, std::string* why) {
    Fd fd(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
    if (fd.get() < 0) {
        say(why, std::string("socket: ") + std::strerror(errno));
        return std::nullopt;
    }
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    if (socket_path.size() >= sizeof(a.sun_path)) {
        say(why, "socket path too long");
        return std::nullopt;
    }
    std::memcpy(a.sun_path, socket_path.c_str(), socket_path.size() + 1);
    if (::connect(fd.get(), reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
        say(why, "connect " + socket_path + ": " + std::strerror(errno));
        return std::nullopt;
    }
    Connection c;
    c.sock_ = std::move(fd);
    return c;
}

bool Connection::send(const void* data, size_t size, const std::vector<int>& fds) const {
    iovec iov{const_cast<void*>(data), size};
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    std::vector<char> control;
    if (!fds.empty()) {
        control.resize(CMSG_SPACE(sizeof(int) * fds.size()));
        m.msg_control = control.data();
        m.msg_controllen = control.size();
        cmsghdr* cm = CMSG_FIRSTHDR(&m);
        cm->cmsg_level = SOL_SOCKET;
        cm->cmsg_type = SCM_RIGHTS;
        cm->cmsg_len = CMSG_LEN(sizeof(int) * fds.size());
        std::memcpy(CMSG_DATA(cm), fds.data(), sizeof(int) * fds.size());
    }
    return sendmsg(sock_.get(), &m, MSG_NOSIGNAL) == ssize_t(size);
}

Message Connection::recv(int timeout_ms) const {
    Message msg;
    pollfd p{sock_.get(), POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return msg;
    std::vector<std::byte> buf(FGSR_MAX_MESSAGE_SIZE);
    iovec iov{buf.data(), buf.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int) * 8)];
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control;
    m.msg_controllen = sizeof(control);
    const ssize_t n = recvmsg(sock_.get(), &m, MSG_CMSG_CLOEXEC);
    if (n <= 0) {
        msg.eof = true;
        return msg;
    }
    for (cmsghdr* cm = CMSG_FIRSTHDR(&m); cm; cm = CMSG_NXTHDR(&m, cm))
        if (cm->cmsg_level == SOL_SOCKET && cm->cmsg_type == SCM_RIGHTS) {
            const size_t count = (cm->cmsg_len - CMSG_LEN(0)) / sizeof(int);
            for (size_t k = 0; k < count; ++k) {
                int fd;
                std::memcpy(&fd, CMSG_DATA(cm) + k * sizeof(int), sizeof(int));
                msg.fds.emplace_back(fd);
            }
        }
    buf.resize(size_t(n));
    msg.bytes = std::move(buf);
    return msg;
}

std::optional<fgsr_hello_reply> Connection::hello(int timeout_ms, uint32_t sequence) const {
    fgsr_hello h{};
    h.header = fgsr_msg_header_for(FGSR_MSG_HELLO, sizeof(h), sequence);
    h.major = FGSR_PROTOCOL_MAJOR;
    h.minor = FGSR_PROTOCOL_MINOR;
    h.pid = uint32_t(getpid());
    std::strcpy(h.name, "fgsr-stress-raw");
    if (!send(&h, sizeof(h))) return std::nullopt;
    const Message m = recv(timeout_ms);
    if (m.bytes.size() != sizeof(fgsr_hello_reply)) return std::nullopt;
    fgsr_hello_reply r;
    std::memcpy(&r, m.bytes.data(), sizeof(r));
    return r;
}

std::string Connection::next_event(int timeout_ms) const {
    const Message m = recv(timeout_ms);
    if (m.eof) return "closed";
    if (m.bytes.size() < sizeof(fgsr_msg_header)) return m.bytes.empty() ? "" : "short message";
    fgsr_msg_header h;
    std::memcpy(&h, m.bytes.data(), sizeof(h));
    if (h.type == FGSR_MSG_ERROR && m.bytes.size() == sizeof(fgsr_reply)) {
        fgsr_reply r;
        std::memcpy(&r, m.bytes.data(), sizeof(r));
        r.reason[sizeof(r.reason) - 1] = 0;
        return "error " + std::string(fgsr_status_string(r.status)) + ": " + r.reason;
    }
    return "reply type " + std::to_string(h.type);
}

bool Connection::closed_by_daemon(int timeout_ms) const {
    const uint64_t deadline = now_ns() + uint64_t(timeout_ms) * 1000000ull;
    for (;;) {
        const uint64_t now = now_ns();
        if (now >= deadline) return false;
        const Message m = recv(int((deadline - now) / 1000000ull) + 1);
        if (m.eof) return true;
        if (m.bytes.empty()) return false;
    }
}

Session::~Session() {
    if (input_) munmap(input_, layout().input_pool_size);
    if (output_) munmap(const_cast<std::byte*>(output_), layout().output_pool_size);
    if (rings_) munmap(rings_, layout().rings_size);
}

void Session::fill(uint32_t slot, float shift) {
    const fgsr_pool_layout& l = layout();
    std::byte* s = input_slot(slot);
    const uint32_t w = width_, h = height_;
    const int sh = int(shift);
    if (l.color.size) {
        std::byte* c = s + l.color.offset;
        for (uint32_t y = 0; y < h; ++y) {
            std::byte* row = c + uint64_t(y) * l.color.row_pitch;
            for (uint32_t x = 0; x < w; ++x) {
                const float v = float(uint32_t(int(x) + sh + int(y / 3)) % 37u) / 36.f;
                if (l.color.format == FGSR_COLOR_RGBA32F_LINEAR) {
                    const float px[4] = {v, 1.f - v, 0.25f, 1.f};
                    std::memcpy(row + uint64_t(x) * 16, px, 16);
                } else if (l.color.format == FGSR_COLOR_RGBA16F_LINEAR) {
                    // Halves of 0.5 and 1.0: a two-level pattern is enough to keep the engine busy.
                    const uint16_t a = v < 0.5f ? 0x3800 : 0x3c00, px[4] = {a, 0x3800, 0x3400, 0x3c00};
                    std::memcpy(row + uint64_t(x) * 8, px, 8);
                } else {
                    const uint8_t b = uint8_t(v * 255.f), px[4] = {b, uint8_t(255 - b), 64, 255};
                    std::memcpy(row + uint64_t(x) * 4, px, 4);
                }
            }
        }
    }
    if (l.depth.size)
        for (uint32_t y = 0; y < h; ++y) {
            auto* d = reinterpret_cast<float*>(s + l.depth.offset + uint64_t(y) * l.depth.row_pitch);
            for (uint32_t x = 0; x < w; ++x) d[x] = 10.f + float(x % 7);
        }
    if (l.mv.size)
        for (uint32_t y = 0; y < h; ++y) {
            std::byte* row = s + l.mv.offset + uint64_t(y) * l.mv.row_pitch;
            if (l.mv.format == FGSR_MV_RG32F)
                for (uint32_t x = 0; x < w; ++x) {
                    const float mv[2] = {-1.f, 0.f};
                    std::memcpy(row + uint64_t(x) * 8, mv, 8);
                }
            else
                std::memset(row, 0, size_t(w) * 4); // RG16F zero vectors
        }
}

fgsr_submit_entry Session::entry(uint32_t slot, uint32_t flags) {
    fgsr_submit_entry e{};
    e.sequence = ++sequence;
    e.input_slot = slot;
    e.flags = flags;
    e.submit_time_ns = now_ns();
    e.user_data = e.sequence;
    return e;
}

void Session::push(const std::vector<fgsr_submit_entry>& entries) {
    for (const auto& e : entries)
        std::memcpy(
            fgsr_ring_slot(rings_ + rl_.submit_entries, sizeof(e), submit_head++, layout().ring_capacity), &e,
            sizeof(e));
    fgsr_ring_publish(header_at(rl_.submit_header), submit_head);
    signal();
}

void Session::publish_submit_head(uint64_t head) {
    fgsr_ring_publish(header_at(rl_.submit_header), head);
    signal();
}

void Session::release(uint32_t output_slot) {
    const fgsr_release_entry r{output_slot, 0};
    std::memcpy(
        fgsr_ring_slot(rings_ + rl_.release_entries, sizeof(r), release_head++, layout().ring_capacity), &r,
        sizeof(r));
    fgsr_ring_publish(header_at(rl_.release_header), release_head);
    signal();
}

bool Session::signal() const {
    const uint64_t one = 1;
    return write(fd(FGSR_FD_SUBMIT_EVENT), &one, 8) == 8;
}

std::optional<fgsr_completion_entry> Session::wait(int timeout_ms) {
    const uint64_t deadline = now_ns() + uint64_t(timeout_ms) * 1000000ull;
    for (;;) {
        if (fgsr_ring_available(header_at(rl_.completion_header), completion_tail) > 0) {
            fgsr_completion_entry c;
            std::memcpy(&c,
                        fgsr_ring_slot(rings_ + rl_.completion_entries, sizeof(c), completion_tail,
                                       layout().ring_capacity),
                        sizeof(c));
            fgsr_ring_consume(header_at(rl_.completion_header), ++completion_tail);
            return c;
        }
        const uint64_t now = now_ns();
        if (now >= deadline) return std::nullopt;
        pollfd p{fd(FGSR_FD_COMPLETE_EVENT), POLLIN, 0};
        if (poll(&p, 1, int(std::min<uint64_t>((deadline - now) / 1000000ull + 1, 50))) > 0) {
            uint64_t v;
            (void)!read(fd(FGSR_FD_COMPLETE_EVENT), &v, 8);
        }
    }
}

std::vector<fgsr_completion_entry> Session::wait_submit(int timeout_ms) {
    std::vector<fgsr_completion_entry> v;
    const uint64_t deadline = now_ns() + uint64_t(timeout_ms) * 1000000ull;
    for (;;) {
        const uint64_t now = now_ns();
        if (now >= deadline) break;
        auto c = wait(int((deadline - now) / 1000000ull) + 1);
        if (!c) break;
        v.push_back(*c);
        if (c->flags & FGSR_COMPLETION_LAST) break;
    }
    return v;
}

std::unique_ptr<Session> create_session(const Connection& c, const fgsr_session_desc& desc,
                                        std::string* why) {
    fgsr_create_session m{};
    m.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION, sizeof(m), 2);
    m.desc = desc;
    if (!c.send(&m, sizeof(m))) {
        say(why, "send CREATE_SESSION failed");
        return nullptr;
    }
    Message msg = c.recv(60000);
    std::unique_ptr<Session> s(new Session());
    if (msg.bytes.size() != sizeof(fgsr_create_session_reply)) {
        say(why, msg.eof ? "the daemon closed the connection" : "no CREATE_SESSION reply");
        return nullptr;
    }
    std::memcpy(&s->reply_, msg.bytes.data(), sizeof(s->reply_));
    s->reply_.reason[sizeof(s->reply_.reason) - 1] = 0;
    if (s->reply_.status != FGSR_STATUS_OK || msg.fds.size() != FGSR_FD_COUNT) {
        say(why, std::string("session refused: ") + fgsr_status_string(s->reply_.status) + " (" +
                     s->reply_.reason + "), " + std::to_string(msg.fds.size()) + " fds");
        return nullptr;
    }
    s->fds_ = std::move(msg.fds);
    s->width_ = desc.width;
    s->height_ = desc.height;
    const fgsr_pool_layout& l = s->layout();
    s->rl_ = fgsr_rings_layout_for(l.ring_capacity);
    void* in =
        mmap(nullptr, l.input_pool_size, PROT_READ | PROT_WRITE, MAP_SHARED, s->fd(FGSR_FD_INPUT_POOL), 0);
    if (in != MAP_FAILED) s->input_ = static_cast<std::byte*>(in);
    void* out = mmap(nullptr, l.output_pool_size, PROT_READ, MAP_SHARED, s->fd(FGSR_FD_OUTPUT_POOL), 0);
    if (out != MAP_FAILED) s->output_ = static_cast<const std::byte*>(out);
    void* rings = mmap(nullptr, l.rings_size, PROT_READ | PROT_WRITE, MAP_SHARED, s->fd(FGSR_FD_RINGS), 0);
    if (rings != MAP_FAILED) s->rings_ = static_cast<std::byte*>(rings);
    if (!s->input_ || !s->output_ || !s->rings_) {
        say(why, std::string("mmap: ") + std::strerror(errno));
        return nullptr;
    }
    return s;
}

std::optional<Client> open_client(const std::string& socket_path, const fgsr_session_desc& desc,
                                  std::string* why) {
    auto conn = Connection::connect(socket_path, why);
    if (!conn) return std::nullopt;
    auto h = conn->hello();
    if (!h || h->status != FGSR_STATUS_OK) {
        say(why, h ? std::string("HELLO refused: ") + fgsr_status_string(h->status) : "no HELLO reply");
        return std::nullopt;
    }
    auto s = create_session(*conn, desc, why);
    if (!s) return std::nullopt;
    return Client{std::move(*conn), std::move(s)};
}

fgsr_session_desc small_desc(uint32_t w, uint32_t h, bool sr) {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = w;
    d.height = h;
    d.color_format = FGSR_COLOR_RGBA32F_LINEAR;
    d.mv_format = FGSR_MV_RG32F;
    d.depth_kind = FGSR_DEPTH_LINEAR;
    d.scale = sr ? 2.f : 1.f;
    d.modes = FGSR_MODE_INTERPOLATE | (sr ? FGSR_MODE_SR : 0u);
    d.output_format = FGSR_COLOR_RGBA32F_LINEAR;
    d.input_slots = 3;
    d.output_slots = 4;
    return d;
}

std::vector<fgsr_completion_entry> roundtrip(Session& s, float shift, uint32_t slot, uint32_t interps,
                                             int timeout_ms) {
    s.fill(slot, shift);
    fgsr_submit_entry e = s.entry(slot);
    e.interp_count = s.sequence == 1 ? 0 : interps; // the first frame has nothing to interpolate from
    for (uint32_t k = 0; k < e.interp_count; ++k)
        e.interp_alphas[k] = float(k + 1) / float(e.interp_count + 1);
    s.push({e});
    auto v = s.wait_submit(timeout_ms);
    for (const auto& c : v)
        if (c.output_slot != FGSR_NO_SLOT && c.output_slot < s.layout().output_slot_count)
            s.release(c.output_slot);
    return v;
}

double hello_ms(const std::string& socket_path, int timeout_ms) {
    const uint64_t t0 = now_ns();
    auto c = Connection::connect(socket_path);
    if (!c) return -1;
    auto r = c->hello(timeout_ms);
    if (!r || r->status != FGSR_STATUS_OK) return -1;
    return ms_since(t0);
}

} // namespace fgsr::stress::raw
