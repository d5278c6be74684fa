// A raw protocol client for multi-process tests of fgsrd: it speaks protocol.h directly (not the
// client library), so tests can be hostile: malformed messages, corrupted ring entries, fd games.
#pragma once

#include <fgsr/testing/fgsrd_process.hpp>

#include <fgsr/core/clock.hpp>
#include <fgsr/protocol.h>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <poll.h>
#include <string>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>
#include <utility>
#include <vector>

namespace fgsr::test {

// AddressSanitizer builds of the tests (FGSR_TEST_ASAN), and ASan options for the daemons a test
// starts.
#if defined(__SANITIZE_ADDRESS__)
#define FGSR_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FGSR_TEST_ASAN 1
#endif
#endif

// ThreadSanitizer builds of the tests (FGSR_TEST_TSAN): the daemons they start run instrumented too.
#if defined(__SANITIZE_THREAD__)
#define FGSR_TEST_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define FGSR_TEST_TSAN 1
#endif
#endif

// Appends `option` to ASAN_OPTIONS for the processes started while it lives (ASan builds only).
class AsanOptionForChildren {
  public:
    explicit AsanOptionForChildren([[maybe_unused]] const char* option) {
#ifdef FGSR_TEST_ASAN
        const char* old = std::getenv("ASAN_OPTIONS");
        if (old) old_ = old;
        const std::string value = old_ ? *old_ + ":" + option : std::string(option);
        setenv("ASAN_OPTIONS", value.c_str(), 1);
#endif
    }
    ~AsanOptionForChildren() {
#ifdef FGSR_TEST_ASAN
        if (old_)
            setenv("ASAN_OPTIONS", old_->c_str(), 1);
        else
            unsetenv("ASAN_OPTIONS");
#endif
    }
    AsanOptionForChildren(const AsanOptionForChildren&) = delete;
    AsanOptionForChildren& operator=(const AsanOptionForChildren&) = delete;

  private:
    std::optional<std::string> old_;
};

constexpr uint32_t kW = 64, kH = 64;

// Owns an fd (test side).
struct Fd {
    int fd = -1;
    Fd() = default;
    explicit Fd(int f) : fd(f) {}
    Fd(Fd&& o) noexcept : fd(std::exchange(o.fd, -1)) {}
    Fd& operator=(Fd&& o) noexcept {
        if (this != &o) {
            if (fd >= 0) close(fd);
            fd = std::exchange(o.fd, -1);
        }
        return *this;
    }
    ~Fd() {
        if (fd >= 0) close(fd);
    }
};

inline fgsr_msg_header header(uint16_t type, uint32_t size, uint32_t seq = 1) {
    fgsr_msg_header h{};
    h.magic = FGSR_PROTOCOL_MAGIC;
    h.type = type;
    h.size = size;
    h.sequence = seq;
    return h;
}

// A HELLO of this protocol version; name up to 31 bytes.
inline fgsr_hello hello_message(const char* name) {
    fgsr_hello h{};
    h.header = header(FGSR_MSG_HELLO, sizeof(h));
    h.major = FGSR_PROTOCOL_MAJOR;
    h.minor = FGSR_PROTOCOL_MINOR;
    std::memcpy(h.name, name, std::min(std::strlen(name), sizeof(h.name) - 1)); // h is zeroed: terminated
    return h;
}

// A raw protocol client.
struct Raw {
    Fd sock;

    static std::optional<Raw> connect(const std::string& path) {
        const int fd = FgsrdProcess::connect_to(path);
        if (fd < 0) return std::nullopt;
        Raw r;
        r.sock = Fd(fd);
        return r;
    }
    bool send(const void* data, size_t size, int attach_fd = -1) const {
        iovec iov{const_cast<void*>(data), size};
        msghdr m{};
        m.msg_iov = &iov;
        m.msg_iovlen = 1;
        alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))]{};
        if (attach_fd >= 0) {
            m.msg_control = control;
            m.msg_controllen = sizeof(control);
            cmsghdr* cm = CMSG_FIRSTHDR(&m);
            cm->cmsg_level = SOL_SOCKET;
            cm->cmsg_type = SCM_RIGHTS;
            cm->cmsg_len = CMSG_LEN(sizeof(int));
            std::memcpy(CMSG_DATA(cm), &attach_fd, sizeof(int));
        }
        return sendmsg(sock.fd, &m, MSG_NOSIGNAL) == ssize_t(size);
    }
    // One message: its bytes (empty on EOF or timeout; eof tells which) and received fds.
    std::vector<std::byte> recv(std::vector<Fd>* fds = nullptr, bool* eof = nullptr,
                                int timeout_ms = 20000) const {
        if (eof) *eof = false;
        pollfd p{sock.fd, POLLIN, 0};
        if (poll(&p, 1, timeout_ms) <= 0) return {};
        std::vector<std::byte> buf(4096);
        iovec iov{buf.data(), buf.size()};
        alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int) * 8)];
        msghdr m{};
        m.msg_iov = &iov;
        m.msg_iovlen = 1;
        m.msg_control = control;
        m.msg_controllen = sizeof(control);
        const ssize_t n = recvmsg(sock.fd, &m, MSG_CMSG_CLOEXEC);
        if (n <= 0) {
            if (eof) *eof = true;
            return {};
        }
        for (cmsghdr* cm = CMSG_FIRSTHDR(&m); cm; cm = CMSG_NXTHDR(&m, cm))
            if (cm->cmsg_level == SOL_SOCKET && cm->cmsg_type == SCM_RIGHTS) {
                const size_t count = (cm->cmsg_len - CMSG_LEN(0)) / sizeof(int);
                for (size_t k = 0; k < count; ++k) {
                    int fd;
                    std::memcpy(&fd, CMSG_DATA(cm) + k * sizeof(int), sizeof(int));
                    if (fds)
                        fds->emplace_back(fd);
                    else
                        close(fd);
                }
            }
        buf.resize(size_t(n));
        return buf;
    }
    // True when the daemon closes the connection within the timeout (messages before are skipped).
    bool closed_by_daemon(int timeout_ms = 20000) const {
        for (int i = 0; i < 8; ++i) {
            bool eof = false;
            auto m = recv(nullptr, &eof, timeout_ms);
            if (eof) return true;
            if (m.empty()) return false;
        }
        return false;
    }
    fgsr_hello_reply hello(uint16_t major = FGSR_PROTOCOL_MAJOR) const {
        fgsr_hello h = hello_message("raw-test");
        h.major = major;
        fgsr_hello_reply r{};
        r.status = -1;
        if (!send(&h, sizeof(h))) return r;
        auto m = recv();
        if (m.size() == sizeof(r)) std::memcpy(&r, m.data(), sizeof(r));
        return r;
    }
};

template <class T> T as(const std::vector<std::byte>& m) {
    T t{};
    if (m.size() >= sizeof(T)) std::memcpy(&t, m.data(), sizeof(T));
    return t;
}

inline fgsr_session_desc default_desc() {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = kW;
    d.height = kH;
    d.color_format = FGSR_COLOR_RGBA32F_LINEAR;
    d.mv_format = FGSR_MV_RG32F;
    d.depth_kind = FGSR_DEPTH_LINEAR;
    d.scale = 2.f;
    d.modes = FGSR_MODE_SR | FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
    d.output_format = FGSR_COLOR_RGBA32F_LINEAR;
    d.input_slots = 3;
    d.output_slots = 4;
    return d;
}

// A session seen from the raw client: the reply, the fds and the client's mappings.
struct RawSession {
    fgsr_create_session_reply reply{};
    std::vector<Fd> fds;
    std::byte* input = nullptr;
    const std::byte* output = nullptr;
    std::byte* rings = nullptr;
    fgsr_rings_layout rl{};
    uint64_t submit_head = 0, completion_tail = 0, release_head = 0, sequence = 0;

    ~RawSession() {
        if (input) munmap(input, reply.layout.input_pool_size);
        if (output) munmap(const_cast<std::byte*>(output), reply.layout.output_pool_size);
        if (rings) munmap(rings, reply.layout.rings_size);
    }
    const fgsr_pool_layout& layout() const { return reply.layout; }
    fgsr_ring_header* hdr(uint64_t off) { return reinterpret_cast<fgsr_ring_header*>(rings + off); }
    std::byte* slot(uint32_t i) { return input + uint64_t(i) * layout().input_slot_stride; }
    const std::byte* out_slot(uint32_t i) const { return output + uint64_t(i) * layout().output_slot_stride; }

    // Fills input slot i with a 64x64 frame: colour a horizontal ramp shifted by `shift` pixels,
    // depth 10, vectors (-shift_step, 0) to the previous frame.
    void fill(uint32_t i, float shift, float step = 1.f) {
        std::byte* s = slot(i);
        auto* c = reinterpret_cast<float*>(s + layout().color.offset);
        auto* d = reinterpret_cast<float*>(s + layout().depth.offset);
        auto* m = reinterpret_cast<float*>(s + layout().mv.offset);
        for (uint32_t y = 0; y < kH; ++y)
            for (uint32_t x = 0; x < kW; ++x) {
                const size_t p = size_t(y) * kW + x;
                const float v = 0.5f + 0.5f * std::sin((float(x) - shift) * 0.3f + float(y) * 0.1f);
                c[4 * p] = v;
                c[4 * p + 1] = 1.f - v;
                c[4 * p + 2] = 0.25f;
                c[4 * p + 3] = 1.f;
                // Only the planes the session has (a colour-only session's are of size 0).
                if (layout().depth.size) d[p] = 10.f;
                if (layout().mv.size) {
                    m[2 * p] = -step;
                    m[2 * p + 1] = 0.f;
                }
            }
    }
    fgsr_submit_entry entry(uint32_t slot_index, uint32_t flags = FGSR_SUBMIT_HAS_MV) {
        fgsr_submit_entry e{};
        e.sequence = ++sequence;
        e.input_slot = slot_index;
        e.flags = flags;
        e.submit_time_ns = monotonic_ns();
        e.user_data = e.sequence * 100;
        return e;
    }
    // Pushes a submit entry as is (hostile tests write what they like) and signals.
    void push(const fgsr_submit_entry& e) {
        auto* se = reinterpret_cast<fgsr_submit_entry*>(rings + rl.submit_entries);
        std::memcpy(&se[fgsr_ring_index(submit_head, layout().ring_capacity)], &e, sizeof(e));
        fgsr_ring_publish(hdr(rl.submit_header), ++submit_head);
        signal();
    }
    // Pushes several entries and publishes them at once (the daemon sees them together).
    void push_many(const std::vector<fgsr_submit_entry>& es) {
        auto* se = reinterpret_cast<fgsr_submit_entry*>(rings + rl.submit_entries);
        uint64_t h = submit_head;
        for (const auto& e : es)
            std::memcpy(&se[fgsr_ring_index(h++, layout().ring_capacity)], &e, sizeof(e));
        submit_head = h;
        fgsr_ring_publish(hdr(rl.submit_header), submit_head);
        signal();
    }
    void release(uint32_t output_slot) {
        auto* re = reinterpret_cast<fgsr_release_entry*>(rings + rl.release_entries);
        re[fgsr_ring_index(release_head, layout().ring_capacity)] = fgsr_release_entry{output_slot, 0};
        fgsr_ring_publish(hdr(rl.release_header), ++release_head);
        signal();
    }
    void signal() const {
        const uint64_t one = 1;
        EXPECT_EQ(write(fds[FGSR_FD_SUBMIT_EVENT].fd, &one, 8), 8);
    }
    // The next completion, waiting up to timeout_ms.
    std::optional<fgsr_completion_entry> wait(int timeout_ms = 20000) {
        const uint64_t deadline = monotonic_ns() + uint64_t(timeout_ms) * 1000000ull;
        for (;;) {
            const uint64_t head = fgsr_ring_load_head(hdr(rl.completion_header));
            if (head != completion_tail) {
                fgsr_completion_entry c;
                auto* ce = reinterpret_cast<const fgsr_completion_entry*>(rings + rl.completion_entries);
                std::memcpy(&c, &ce[fgsr_ring_index(completion_tail, layout().ring_capacity)], sizeof(c));
                fgsr_ring_consume(hdr(rl.completion_header), ++completion_tail);
                return c;
            }
            const uint64_t now = monotonic_ns();
            if (now >= deadline) return std::nullopt;
            pollfd p{fds[FGSR_FD_COMPLETE_EVENT].fd, POLLIN, 0};
            poll(&p, 1, int(std::min<uint64_t>((deadline - now) / 1000000ull + 1, 50)));
            uint64_t v;
            (void)!read(fds[FGSR_FD_COMPLETE_EVENT].fd, &v, 8);
        }
    }
    // All completions of one submit (up to and including the LAST one).
    std::vector<fgsr_completion_entry> wait_submit(int timeout_ms = 20000) {
        std::vector<fgsr_completion_entry> v;
        while (auto c = wait(timeout_ms)) {
            v.push_back(*c);
            if (c->flags & FGSR_COMPLETION_LAST) break;
        }
        return v;
    }
};

// Connects, shakes hands and creates a session; nullopt (with a test failure) when anything fails.
struct Conn {
    Raw raw;
    std::unique_ptr<RawSession> s;
};

inline std::optional<Conn> open_session(const std::string& path,
                                        const fgsr_session_desc& desc = default_desc()) {
    auto raw = Raw::connect(path);
    if (!raw) {
        ADD_FAILURE() << "connect " << path;
        return std::nullopt;
    }
    if (raw->hello().status != FGSR_STATUS_OK) {
        ADD_FAILURE() << "hello refused";
        return std::nullopt;
    }
    fgsr_create_session m{};
    m.header = header(FGSR_MSG_CREATE_SESSION, sizeof(m), 2);
    m.desc = desc;
    if (!raw->send(&m, sizeof(m))) return std::nullopt;
    auto s = std::make_unique<RawSession>();
    // A 2048x2048 session's buffers take seconds to create in an ASan build on a loaded machine
    // (a clean-clone CI run beside other work took more than the default 20 s): a minute before the
    // reply counts as missing.
    auto msg = raw->recv(&s->fds, nullptr, 60000);
    s->reply = as<fgsr_create_session_reply>(msg);
    if (msg.size() != sizeof(fgsr_create_session_reply) || s->reply.status != FGSR_STATUS_OK ||
        s->fds.size() != FGSR_FD_COUNT) {
        ADD_FAILURE() << "create session: status " << s->reply.status << " (" << s->reply.reason << "), "
                      << s->fds.size() << " fds";
        return std::nullopt;
    }
    const fgsr_pool_layout& l = s->layout();
    s->rl = fgsr_rings_layout_for(l.ring_capacity);
    void* in = mmap(nullptr, l.input_pool_size, PROT_READ | PROT_WRITE, MAP_SHARED,
                    s->fds[FGSR_FD_INPUT_POOL].fd, 0);
    void* out = mmap(nullptr, l.output_pool_size, PROT_READ, MAP_SHARED, s->fds[FGSR_FD_OUTPUT_POOL].fd, 0);
    void* rings =
        mmap(nullptr, l.rings_size, PROT_READ | PROT_WRITE, MAP_SHARED, s->fds[FGSR_FD_RINGS].fd, 0);
    if (in == MAP_FAILED || out == MAP_FAILED || rings == MAP_FAILED) {
        ADD_FAILURE() << "mmap: " << std::strerror(errno);
        return std::nullopt;
    }
    s->input = static_cast<std::byte*>(in);
    s->output = static_cast<const std::byte*>(out);
    s->rings = static_cast<std::byte*>(rings);
    return Conn{std::move(*raw), std::move(s)};
}

// Submits one frame wanting SR and returns its completions.
inline std::vector<fgsr_completion_entry> roundtrip(RawSession& s, float shift, bool release = true) {
    s.fill(0, shift);
    s.push(s.entry(0, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    auto v = s.wait_submit();
    if (release)
        for (const auto& c : v)
            if (c.output_slot != FGSR_NO_SLOT) s.release(c.output_slot);
    return v;
}

} // namespace fgsr::test
