// libfgsr_client against a fake daemon that speaks raw protocol.h from a thread of the test: missing
// daemon, other major version, hang-ups, malformed replies and fds (PROTOCOL_ERROR, every fd closed),
// ring semantics seen from the client (input slots, completions, output slots, releases, corrupted
// completions), and recording a session as an fgsr capture that loads back bit-identically.
#include "run_process.hpp"

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/fgsr_format.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/client.h>
#include <fgsr/client.hpp>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <poll.h>
#include <string>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <thread>
#include <unistd.h>
#include <vector>

#ifndef F_SEAL_FUTURE_WRITE
#define F_SEAL_FUTURE_WRITE 0x0010
#endif

namespace {

namespace fs = std::filesystem;

using fgsr::test::count_fds;

size_t color_bpp(uint32_t f) {
    return f == FGSR_COLOR_RGBA8_SRGB ? 4 : f == FGSR_COLOR_RGBA16F_LINEAR ? 8 : 16;
}

fgsr_session_desc small_desc(uint32_t w = 16, uint32_t h = 8) {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = w;
    d.height = h;
    d.color_format = FGSR_COLOR_RGBA16F_LINEAR;
    d.mv_format = FGSR_MV_RG32F;
    d.depth_kind = FGSR_DEPTH_LINEAR;
    d.scale = 1.f;
    d.modes = FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
    d.output_format = FGSR_COLOR_RGBA32F_LINEAR;
    return d;
}

// The layout a conforming daemon could compute (planes packed, each on FGSR_PLANE_ALIGNMENT).
fgsr_pool_layout layout_for(const fgsr_session_desc& in) {
    fgsr_session_desc d = in;
    if (!d.input_slots) d.input_slots = 3;
    if (!d.output_slots) d.output_slots = 4;
    if (!d.ring_capacity) d.ring_capacity = 64;
    auto A = [](uint64_t v) { return fgsr_align_up(v, FGSR_PLANE_ALIGNMENT); };
    const uint64_t w = d.width, h = d.height;
    fgsr_pool_layout l{};
    const uint32_t mb = d.mv_format == FGSR_MV_RG16F ? 4 : 8;
    l.color = {0, w * h * color_bpp(d.color_format), uint32_t(w * color_bpp(d.color_format)), d.color_format};
    l.depth = {A(l.color.size), w * h * 4, uint32_t(w * 4), 0};
    l.mv = {A(l.depth.offset + l.depth.size), w * h * mb, uint32_t(w * mb), d.mv_format};
    l.input_slot_stride = A(l.mv.offset + l.mv.size);
    l.input_slot_count = d.input_slots;
    l.input_pool_size = l.input_slot_stride * d.input_slots;
    l.output_width = uint32_t(std::lround(double(d.width) * double(d.scale)));
    l.output_height = uint32_t(std::lround(double(d.height) * double(d.scale)));
    const uint64_t ob = color_bpp(d.output_format);
    l.output = {0, uint64_t(l.output_width) * l.output_height * ob, uint32_t(l.output_width * ob),
                d.output_format};
    l.output_slot_stride = A(l.output.size);
    l.output_slot_count = d.output_slots;
    l.output_pool_size = l.output_slot_stride * d.output_slots;
    l.ring_capacity = d.ring_capacity;
    l.rings_size = fgsr_rings_layout_for(d.ring_capacity).total_size;
    return l;
}

int make_memfd(uint64_t size, unsigned seals) {
    const int fd = memfd_create("fake-fgsrd", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (fd < 0) return -1;
    if (ftruncate(fd, off_t(size)) != 0) return -1;
    if (seals && fcntl(fd, F_ADD_SEALS, int(seals)) != 0) return -1;
    return fd;
}

// A daemon in a thread of the test process: accepts one connection and answers it as the scenario
// says. After a successful create, the test thread plays the daemon's side of the rings through
// the mappings below.
class FakeDaemon {
  public:
    enum class Hello { ok, other_major, close, bad_magic, error_message };
    enum class Create {
        ok,
        four_fds,
        bad_output_size,
        small_memfd,
        unsealed_output,
        not_eventfd,
        refuse,
        close,
    };
    Hello hello = Hello::ok;
    Create create = Create::ok;
    std::function<void(fgsr_pool_layout&)> tamper; // edits the layout before it is sent

    FakeDaemon() {
        char tmpl[] = "/tmp/fgsr-fake-XXXXXX";
        dir_ = mkdtemp(tmpl);
        path = dir_ + "/fgsrd.sock";
        listen_ = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::snprintf(a.sun_path, sizeof(a.sun_path), "%s", path.c_str());
        bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof(a));
        listen(listen_, 4);
    }
    void start() {
        thread_ = std::thread([this] { serve(); });
    }
    ~FakeDaemon() {
        stop();
        if (rings && rings != MAP_FAILED) munmap(rings, layout.rings_size);
        if (output && output != MAP_FAILED) munmap(output, output_mapped_);
        for (int& fd : fds)
            if (fd >= 0) close(fd);
        close(listen_);
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    // Closes the connection from the daemon's side (as if it died) and waits for the thread.
    void stop() {
        if (conn_ >= 0) shutdown(conn_, SHUT_RDWR);
        if (thread_.joinable()) {
            shutdown(listen_, SHUT_RDWR);
            thread_.join();
        }
        if (conn_ >= 0) close(conn_);
        conn_ = -1;
    }

    // Daemon side of the rings (valid once `ready`).
    fgsr_ring_header* hdr(uint64_t off) {
        return reinterpret_cast<fgsr_ring_header*>(static_cast<char*>(rings) + off);
    }
    bool pop_submit(fgsr_submit_entry& e) {
        const fgsr_rings_layout rl = fgsr_rings_layout_for(layout.ring_capacity);
        fgsr_ring_header* h = hdr(rl.submit_header);
        if (fgsr_ring_load_head(h) == submit_tail_) return false;
        std::memcpy(&e,
                    static_cast<char*>(rings) + rl.submit_entries +
                        fgsr_ring_index(submit_tail_, layout.ring_capacity) * sizeof(e),
                    sizeof(e));
        fgsr_ring_consume(h, ++submit_tail_);
        return true;
    }
    void push_completion(const fgsr_completion_entry& e) {
        const fgsr_rings_layout rl = fgsr_rings_layout_for(layout.ring_capacity);
        std::memcpy(static_cast<char*>(rings) + rl.completion_entries +
                        fgsr_ring_index(completion_head_, layout.ring_capacity) * sizeof(e),
                    &e, sizeof(e));
        fgsr_ring_publish(hdr(rl.completion_header), ++completion_head_);
        const uint64_t one = 1;
        (void)!write(fds[FGSR_FD_COMPLETE_EVENT], &one, sizeof(one));
    }
    bool pop_release(uint32_t& slot) {
        const fgsr_rings_layout rl = fgsr_rings_layout_for(layout.ring_capacity);
        fgsr_ring_header* h = hdr(rl.release_header);
        if (fgsr_ring_load_head(h) == release_tail_) return false;
        fgsr_release_entry r;
        std::memcpy(&r,
                    static_cast<char*>(rings) + rl.release_entries +
                        fgsr_ring_index(release_tail_, layout.ring_capacity) * sizeof(r),
                    sizeof(r));
        fgsr_ring_consume(h, ++release_tail_);
        slot = r.output_slot;
        return true;
    }
    // Completes one submit without output (INPUT_RELEASED | LAST), as for a submit that asked none.
    bool complete_plain(int32_t status = FGSR_STATUS_OK) {
        fgsr_submit_entry s;
        if (!pop_submit(s)) return false;
        fgsr_completion_entry c{};
        c.sequence = s.sequence;
        c.status = status;
        c.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
        c.input_slot = s.input_slot;
        c.output_slot = FGSR_NO_SLOT;
        c.user_data = s.user_data;
        push_completion(c);
        return true;
    }

    std::string path;
    std::atomic<bool> ready{false};
    fgsr_pool_layout layout{};
    int fds[FGSR_FD_COUNT] = {-1, -1, -1, -1, -1};
    void* rings = nullptr;
    void* output = nullptr; // writable daemon mapping of the output pool
    std::atomic<int> destroys{0};

  private:
    // Serves the connection; hangs up (the client sees EOF) when the scenario ends it.
    void serve() {
        conn_ = accept4(listen_, nullptr, nullptr, SOCK_CLOEXEC);
        if (conn_ < 0) return;
        serve_connection();
        shutdown(conn_, SHUT_RDWR);
    }
    void serve_connection() {
        alignas(8) unsigned char buf[FGSR_MAX_MESSAGE_SIZE];
        for (;;) {
            const ssize_t n = recv(conn_, buf, sizeof(buf), 0);
            if (n <= 0) return;
            fgsr_msg_header h;
            std::memcpy(&h, buf, sizeof(h));
            if (h.type == FGSR_MSG_HELLO) {
                fgsr_hello_reply r{};
                r.header = {FGSR_PROTOCOL_MAGIC, FGSR_MSG_HELLO_REPLY, 0, sizeof(r), h.sequence};
                r.major = FGSR_PROTOCOL_MAJOR;
                r.epoch = 42;
                std::snprintf(r.device, sizeof(r.device), "fake device");
                if (hello == Hello::close) return;
                if (hello == Hello::other_major) {
                    r.major = FGSR_PROTOCOL_MAJOR + 1;
                    r.status = FGSR_STATUS_VERSION_MISMATCH;
                }
                if (hello == Hello::bad_magic) r.header.magic = 0x12345678;
                if (hello == Hello::error_message) {
                    fgsr_reply e{};
                    e.header = {FGSR_PROTOCOL_MAGIC, FGSR_MSG_ERROR, 0, sizeof(e), h.sequence};
                    e.status = FGSR_STATUS_PERMISSION_DENIED;
                    send(conn_, &e, sizeof(e), MSG_NOSIGNAL);
                    return;
                }
                send(conn_, &r, sizeof(r), MSG_NOSIGNAL);
            } else if (h.type == FGSR_MSG_CREATE_SESSION) {
                if (create == Create::close) return;
                fgsr_create_session req;
                std::memcpy(&req, buf, sizeof(req));
                send_create_reply(req, h.sequence);
            } else if (h.type == FGSR_MSG_DESTROY_SESSION || h.type == FGSR_MSG_STATS) {
                if (h.type == FGSR_MSG_DESTROY_SESSION) {
                    ++destroys;
                    fgsr_reply r{};
                    r.header = {FGSR_PROTOCOL_MAGIC, FGSR_MSG_DESTROY_SESSION_REPLY, 0, sizeof(r),
                                h.sequence};
                    send(conn_, &r, sizeof(r), MSG_NOSIGNAL);
                } else {
                    fgsr_stats_reply r{};
                    r.header = {FGSR_PROTOCOL_MAGIC, FGSR_MSG_STATS_REPLY, 0, sizeof(r), h.sequence};
                    r.session_id = 7;
                    r.stats.frames_submitted = 3;
                    send(conn_, &r, sizeof(r), MSG_NOSIGNAL);
                }
            }
        }
    }

    void send_create_reply(const fgsr_create_session& req, uint32_t seq) {
        fgsr_create_session_reply r{};
        r.header = {FGSR_PROTOCOL_MAGIC, FGSR_MSG_CREATE_SESSION_REPLY, 0, sizeof(r), seq};
        r.session_id = 7;
        r.epoch = 42;
        if (create == Create::refuse) {
            r.status = FGSR_STATUS_UNSUPPORTED;
            std::snprintf(r.reason, sizeof(r.reason), "fake: no");
            send(conn_, &r, sizeof(r), MSG_NOSIGNAL);
            return;
        }
        layout = layout_for(req.desc);
        if (create == Create::bad_output_size) layout.output_width += 1;
        if (tamper) tamper(layout);
        const unsigned pool_seals = F_SEAL_SHRINK | F_SEAL_GROW;
        fds[FGSR_FD_INPUT_POOL] = make_memfd(layout.input_pool_size, pool_seals);
        fds[FGSR_FD_OUTPUT_POOL] =
            make_memfd(layout.output_pool_size / (create == Create::small_memfd ? 2 : 1), 0);
        fds[FGSR_FD_RINGS] = make_memfd(layout.rings_size, F_SEAL_SHRINK | F_SEAL_GROW);
        fds[FGSR_FD_SUBMIT_EVENT] = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
        fds[FGSR_FD_COMPLETE_EVENT] = create == Create::not_eventfd ? memfd_create("x", MFD_CLOEXEC)
                                                                    : eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
        output_mapped_ = layout.output_pool_size / (create == Create::small_memfd ? 2 : 1);
        output =
            mmap(nullptr, output_mapped_, PROT_READ | PROT_WRITE, MAP_SHARED, fds[FGSR_FD_OUTPUT_POOL], 0);
        if (create != Create::unsealed_output)
            fcntl(fds[FGSR_FD_OUTPUT_POOL], F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_FUTURE_WRITE);
        rings = mmap(nullptr, layout.rings_size, PROT_READ | PROT_WRITE, MAP_SHARED, fds[FGSR_FD_RINGS], 0);
        r.layout = layout;
        const int nfds = create == Create::four_fds ? 4 : FGSR_FD_COUNT;
        alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int) * FGSR_FD_COUNT)] = {};
        iovec iov{&r, sizeof(r)};
        msghdr mh{};
        mh.msg_iov = &iov;
        mh.msg_iovlen = 1;
        mh.msg_control = control;
        mh.msg_controllen = CMSG_SPACE(sizeof(int) * size_t(nfds));
        cmsghdr* c = CMSG_FIRSTHDR(&mh);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SCM_RIGHTS;
        c->cmsg_len = CMSG_LEN(sizeof(int) * size_t(nfds));
        std::memcpy(CMSG_DATA(c), fds, sizeof(int) * size_t(nfds));
        ready.store(true, std::memory_order_release);
        sendmsg(conn_, &mh, MSG_NOSIGNAL);
    }

    std::string dir_;
    size_t output_mapped_ = 0;
    int listen_ = -1;
    // Written by the serving thread (accept), read by stop() on the test's thread to unblock it.
    std::atomic<int> conn_{-1};
    std::thread thread_;
    uint64_t submit_tail_ = 0, completion_head_ = 0, release_tail_ = 0;
};

fgsr_status connect_to(const std::string& path, fgsr_connection** c) {
    fgsr_connect_info info{};
    info.struct_size = sizeof(info);
    info.socket_path = path.c_str();
    info.timeout_ms = 5000;
    info.client_name = "test";
    return fgsr_connect(&info, c);
}

// Connects to the fake daemon, creates a small session and submits one frame without requests.
void open_and_submit(FakeDaemon& d, fgsr::client::Connection& c, fgsr::client::Session& s) {
    ASSERT_EQ(c.connect(d.path.c_str()), FGSR_STATUS_OK);
    ASSERT_EQ(s.create(c, small_desc()), FGSR_STATUS_OK);
    fgsr_input_slot in{};
    ASSERT_EQ(s.acquire_input(0, in), FGSR_STATUS_OK);
    fgsr_submit_info info{};
    info.struct_size = sizeof(info);
    info.input_slot = in.index;
    ASSERT_EQ(s.submit(info), FGSR_STATUS_OK);
}

struct QuietClient {
    QuietClient() { setenv("FGSR_CLIENT_QUIET", "1", 1); }
    ~QuietClient() { unsetenv("FGSR_CLIENT_QUIET"); }
};

TEST(ClientFake, MissingDaemonIsUnavailable) {
    const int base = count_fds();
    fgsr_connection* c = reinterpret_cast<fgsr_connection*>(1);
    EXPECT_EQ(connect_to("/tmp/fgsr-no-such-dir/fgsrd.sock", &c), FGSR_STATUS_DAEMON_UNAVAILABLE);
    EXPECT_EQ(c, nullptr);
    // A socket file nobody listens on any more.
    {
        char tmpl[] = "/tmp/fgsr-stale-XXXXXX";
        const std::string dir = mkdtemp(tmpl);
        const std::string p = dir + "/fgsrd.sock";
        const int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::snprintf(a.sun_path, sizeof(a.sun_path), "%s", p.c_str());
        ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
        close(fd);
        EXPECT_EQ(connect_to(p, &c), FGSR_STATUS_DAEMON_UNAVAILABLE);
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    // Defaults: neither FGSR_SOCKET nor XDG_RUNTIME_DIR.
    const char* x = std::getenv("XDG_RUNTIME_DIR");
    const std::string saved = x ? x : "";
    unsetenv("XDG_RUNTIME_DIR");
    unsetenv("FGSR_SOCKET");
    EXPECT_EQ(fgsr_connect(nullptr, &c), FGSR_STATUS_DAEMON_UNAVAILABLE);
    setenv("FGSR_SOCKET", "/tmp/fgsr-no-such-dir/x.sock", 1);
    EXPECT_EQ(fgsr_connect(nullptr, &c), FGSR_STATUS_DAEMON_UNAVAILABLE);
    unsetenv("FGSR_SOCKET");
    if (x) setenv("XDG_RUNTIME_DIR", saved.c_str(), 1);
    EXPECT_EQ(fgsr_connect(nullptr, nullptr), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_EQ(count_fds(), base);
}

TEST(ClientFake, HandshakeOutcomes) {
    QuietClient quiet;
    const int base = count_fds();
    struct Case {
        FakeDaemon::Hello hello;
        fgsr_status expect;
    } cases[] = {{FakeDaemon::Hello::other_major, FGSR_STATUS_VERSION_MISMATCH},
                 {FakeDaemon::Hello::close, FGSR_STATUS_DISCONNECTED},
                 {FakeDaemon::Hello::bad_magic, FGSR_STATUS_PROTOCOL_ERROR},
                 {FakeDaemon::Hello::error_message, FGSR_STATUS_PERMISSION_DENIED}};
    for (const Case& k : cases) {
        FakeDaemon d;
        d.hello = k.hello;
        d.start();
        fgsr_connection* c = nullptr;
        EXPECT_EQ(connect_to(d.path, &c), k.expect) << int(k.hello);
        EXPECT_EQ(c, nullptr);
    }
    {
        FakeDaemon d;
        d.start();
        fgsr_connection* c = nullptr;
        ASSERT_EQ(connect_to(d.path, &c), FGSR_STATUS_OK);
        fgsr_daemon_info info{};
        ASSERT_EQ(fgsr_daemon_info_get(c, &info), FGSR_STATUS_OK);
        EXPECT_EQ(info.major, FGSR_PROTOCOL_MAJOR);
        EXPECT_EQ(info.epoch, 42u);
        EXPECT_STREQ(info.device, "fake device");
        fgsr_disconnect(c);
    }
    EXPECT_EQ(count_fds(), base);
}

TEST(ClientFake, MalformedSessionRepliesAreProtocolErrors) {
    QuietClient quiet;
    const int base = count_fds();
    using C = FakeDaemon::Create;
    struct Case {
        C create;
        fgsr_status expect;
        std::function<void(fgsr_pool_layout&)> tamper;
    } cases[] = {
        {C::four_fds, FGSR_STATUS_PROTOCOL_ERROR, nullptr},
        {C::bad_output_size, FGSR_STATUS_PROTOCOL_ERROR, nullptr},
        {C::small_memfd, FGSR_STATUS_PROTOCOL_ERROR, nullptr},
        {C::unsealed_output, FGSR_STATUS_PROTOCOL_ERROR, nullptr},
        {C::not_eventfd, FGSR_STATUS_PROTOCOL_ERROR, nullptr},
        {C::refuse, FGSR_STATUS_UNSUPPORTED, nullptr},
        {C::close, FGSR_STATUS_DISCONNECTED, nullptr},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.depth.offset = l.color.offset; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.mv.offset += 1; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.color.row_pitch -= 1; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.input_slot_count = 64; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.input_pool_size += 4096; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR,
         [](fgsr_pool_layout& l) { l.output.size = l.output_slot_stride + 1; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR, [](fgsr_pool_layout& l) { l.rings_size -= 4096; }},
        {C::ok, FGSR_STATUS_PROTOCOL_ERROR,
         [](fgsr_pool_layout& l) { l.output.format = FGSR_COLOR_RGBA8_SRGB; }},
    };
    for (size_t i = 0; i < std::size(cases); ++i) {
        FakeDaemon d;
        d.create = cases[i].create;
        d.tamper = cases[i].tamper;
        d.start();
        fgsr_connection* c = nullptr;
        ASSERT_EQ(connect_to(d.path, &c), FGSR_STATUS_OK);
        fgsr_session_desc desc = small_desc();
        fgsr_session* s = reinterpret_cast<fgsr_session*>(1);
        EXPECT_EQ(fgsr_session_create(c, &desc, &s), cases[i].expect) << "case " << i;
        EXPECT_EQ(s, nullptr);
        // The client told the daemon to drop a session it refused.
        if (cases[i].expect == FGSR_STATUS_PROTOCOL_ERROR && cases[i].create != C::close) {
            EXPECT_EQ(d.destroys.load(), 1) << "case " << i;
        }
        fgsr_disconnect(c);
    }
    EXPECT_EQ(count_fds(), base);
}

TEST(ClientFake, InvalidDescriptionsAreRefusedLocally) {
    FakeDaemon d;
    d.start();
    fgsr_connection* c = nullptr;
    ASSERT_EQ(connect_to(d.path, &c), FGSR_STATUS_OK);
    std::vector<std::function<void(fgsr_session_desc&)>> edits = {
        [](fgsr_session_desc& x) { x.struct_size = 4; },
        [](fgsr_session_desc& x) { x.width = 0; },
        [](fgsr_session_desc& x) { x.height = 20000; },
        [](fgsr_session_desc& x) { x.color_format = 9; },
        [](fgsr_session_desc& x) { x.scale = NAN; },
        [](fgsr_session_desc& x) { x.modes = 0; },
        [](fgsr_session_desc& x) { x.modes = FGSR_MODE_SR; }, // scale 1
        [](fgsr_session_desc& x) { x.input_slots = 65; },
        [](fgsr_session_desc& x) { x.ring_capacity = 48; },
        [](fgsr_session_desc& x) { x.ring_capacity = 2; }, // fewer than the 4 output slots
    };
    for (size_t i = 0; i < edits.size(); ++i) {
        fgsr_session_desc desc = small_desc();
        edits[i](desc);
        fgsr_session* s = nullptr;
        EXPECT_EQ(fgsr_session_create(c, &desc, &s), FGSR_STATUS_INVALID_ARGUMENT) << "edit " << i;
    }
    EXPECT_FALSE(d.ready.load());
    fgsr_disconnect(c);
}

// Fills an acquired slot with frame `f` of `cap` (tightly packed planes, as layout_for lays out).
void fill_slot(const fgsr_input_slot& in, const fgsr::capture::Frame& f) {
    std::memcpy(in.color, f.color.data(), f.color.size());
    std::memcpy(in.depth, f.depth.data(), f.depth.size());
    if (!f.mv.empty()) std::memcpy(in.mv, f.mv.data(), f.mv.size());
}

TEST(ClientFake, RingsSlotsAndCompletions) {
    QuietClient quiet;
    const int base = count_fds();
    {
        FakeDaemon d;
        d.start();
        fgsr::client::Connection c;
        ASSERT_EQ(c.connect(d.path.c_str(), "test"), FGSR_STATUS_OK);
        fgsr::client::Session s;
        fgsr_session_desc desc = small_desc();
        desc.input_slots = 2;
        desc.output_slots = 2;
        desc.ring_capacity = 4;
        ASSERT_EQ(s.create(c, desc), FGSR_STATUS_OK);
        ASSERT_TRUE(d.ready.load(std::memory_order_acquire));
        fgsr_pool_layout l{};
        ASSERT_EQ(s.layout(l), FGSR_STATUS_OK);
        EXPECT_EQ(l.input_slot_count, 2u);
        EXPECT_GE(s.event_fd(), 0);

        // Two slots, then none until the daemon hands one back.
        fgsr_input_slot a{}, b{}, x{};
        ASSERT_EQ(s.acquire_input(0, a), FGSR_STATUS_OK);
        ASSERT_EQ(s.acquire_input(0, b), FGSR_STATUS_OK);
        EXPECT_NE(a.index, b.index);
        EXPECT_EQ(s.acquire_input(20, x), FGSR_STATUS_NO_SLOT);

        fgsr_submit_info info{};
        info.struct_size = sizeof(info);
        info.input_slot = a.index;
        // Mode checks: SR not declared; alpha out of range; slot not acquired.
        info.flags = FGSR_SUBMIT_WANT_SR;
        EXPECT_EQ(s.submit(info), FGSR_STATUS_INVALID_ARGUMENT);
        info.flags = 0;
        const float bad_alpha[] = {1.f};
        info.interp_count = 1;
        info.interp_alphas = bad_alpha;
        EXPECT_EQ(s.submit(info), FGSR_STATUS_INVALID_ARGUMENT);
        const float half[] = {0.5f};
        info.interp_alphas = half;
        info.input_slot = 5;
        EXPECT_EQ(s.submit(info), FGSR_STATUS_INVALID_ARGUMENT);
        info.input_slot = a.index;
        info.user_data = 99;
        uint64_t seq = 0;
        ASSERT_EQ(s.submit(info, &seq), FGSR_STATUS_OK);
        EXPECT_EQ(seq, 1u);
        EXPECT_EQ(s.submit(info), FGSR_STATUS_INVALID_ARGUMENT); // a is the daemon's now

        // The daemon sees the entry as filled in, writes one output and releases the input.
        fgsr_submit_entry e{};
        ASSERT_TRUE(d.pop_submit(e));
        EXPECT_EQ(e.sequence, 1u);
        EXPECT_EQ(e.input_slot, a.index);
        EXPECT_EQ(e.interp_count, 1u);
        EXPECT_EQ(e.interp_alphas[0], 0.5f);
        EXPECT_EQ(e.user_data, 99u);
        EXPECT_GT(e.submit_time_ns, 0u);
        float* out0 = reinterpret_cast<float*>(static_cast<char*>(d.output) + 1 * l.output_slot_stride +
                                               l.output.offset);
        for (uint32_t i = 0; i < l.output_width * l.output_height * 4; ++i) out0[i] = float(i);
        fgsr_completion_entry ce{};
        ce.sequence = 1;
        ce.status = FGSR_STATUS_OK;
        ce.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
        ce.input_slot = a.index;
        ce.output_slot = 1;
        ce.user_data = 99;
        ce.telemetry.frame_type = FGSR_FRAME_INTERPOLATED;
        ce.telemetry.target_time = 0.5f;
        d.push_completion(ce);

        // acquire_input picks up the release and keeps the completion for wait.
        ASSERT_EQ(s.acquire_input(1000, x), FGSR_STATUS_OK);
        EXPECT_EQ(x.index, a.index);
        fgsr_output out{};
        ASSERT_EQ(s.wait(1000, out), FGSR_STATUS_OK);
        EXPECT_EQ(out.sequence, 1u);
        EXPECT_EQ(out.status, FGSR_STATUS_OK);
        EXPECT_EQ(out.output_slot, 1u);
        EXPECT_EQ(out.width, l.output_width);
        EXPECT_EQ(out.format, uint32_t(FGSR_COLOR_RGBA32F_LINEAR));
        EXPECT_EQ(out.telemetry.frame_type, uint32_t(FGSR_FRAME_INTERPOLATED));
        ASSERT_NE(out.pixels, nullptr);
        EXPECT_EQ(static_cast<const float*>(out.pixels)[37], 37.f);
        EXPECT_EQ(s.wait(0, out), FGSR_STATUS_TIMEOUT);

        ASSERT_EQ(s.release_output(1), FGSR_STATUS_OK);
        EXPECT_EQ(s.release_output(1), FGSR_STATUS_INVALID_ARGUMENT); // not held any more
        EXPECT_EQ(s.release_output(0), FGSR_STATUS_INVALID_ARGUMENT);
        uint32_t released = 9;
        ASSERT_TRUE(d.pop_release(released));
        EXPECT_EQ(released, 1u);

        fgsr_session_stats st{};
        ASSERT_EQ(s.stats(st), FGSR_STATUS_OK);
        EXPECT_EQ(st.frames_submitted, 3u);

        // A completion for a sequence never submitted: PROTOCOL_ERROR, and the session stays broken.
        ce.sequence = 77;
        d.push_completion(ce);
        EXPECT_EQ(s.wait(1000, out), FGSR_STATUS_PROTOCOL_ERROR);
        EXPECT_EQ(s.acquire_input(0, x), FGSR_STATUS_PROTOCOL_ERROR);
    }
    EXPECT_EQ(count_fds(), base);
}

TEST(ClientFake, CorruptedCompletionsAreRejected) {
    QuietClient quiet;
    std::vector<std::function<void(fgsr_completion_entry&)>> corruptions = {
        [](fgsr_completion_entry& c) { c.output_slot = 4; },              // out of range
        [](fgsr_completion_entry& c) { c.input_slot = 2; },               // not the submit's slot
        [](fgsr_completion_entry& c) { c.status = 1000; },                // unknown status
        [](fgsr_completion_entry& c) { c.telemetry.pass_count = 99; },    // too many passes
        [](fgsr_completion_entry& c) { c.flags = FGSR_COMPLETION_LAST; }, // LAST without release
    };
    for (size_t i = 0; i < corruptions.size(); ++i) {
        FakeDaemon d;
        d.start();
        fgsr::client::Connection c;
        fgsr::client::Session s;
        ASSERT_NO_FATAL_FAILURE(open_and_submit(d, c, s));
        fgsr_submit_entry e{};
        ASSERT_TRUE(d.pop_submit(e));
        fgsr_completion_entry ce{};
        ce.sequence = e.sequence;
        ce.flags = FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST;
        ce.input_slot = e.input_slot;
        ce.output_slot = 0;
        corruptions[i](ce);
        d.push_completion(ce);
        fgsr_output out{};
        EXPECT_EQ(s.wait(1000, out), FGSR_STATUS_PROTOCOL_ERROR) << "corruption " << i;
    }
}

TEST(ClientFake, DaemonGoneIsDisconnected) {
    QuietClient quiet;
    const int base = count_fds();
    {
        FakeDaemon d;
        d.start();
        fgsr::client::Connection c;
        fgsr::client::Session s;
        ASSERT_NO_FATAL_FAILURE(open_and_submit(d, c, s));
        ASSERT_TRUE(d.complete_plain());
        d.stop(); // the daemon dies after publishing one completion
        fgsr_output out{};
        ASSERT_EQ(s.wait(1000, out), FGSR_STATUS_OK); // what was published still arrives
        EXPECT_EQ(out.output_slot, FGSR_NO_SLOT);
        EXPECT_EQ(s.wait(5000, out), FGSR_STATUS_DISCONNECTED);
        fgsr_session_stats st{};
        EXPECT_EQ(s.stats(st), FGSR_STATUS_DISCONNECTED);
    }
    EXPECT_EQ(count_fds(), base);
}

// Recording: every submitted frame lands in an fgsr capture that loads back bit-identically.
void record_and_compare(bool through_env) {
    QuietClient quiet;
    fgsr::capture::SceneOptions so;
    so.width = 24;
    so.height = 16;
    so.supersample = 1;
    auto cap = fgsr::capture::make_synthetic_capture(so, 3);
    ASSERT_TRUE(cap) << cap.error().message;
    char tmpl[] = "/tmp/fgsr-rec-XXXXXX";
    const fs::path dir = fs::path(mkdtemp(tmpl)) / "rec";
    {
        FakeDaemon d;
        d.start();
        fgsr::client::Connection c;
        ASSERT_EQ(c.connect(d.path.c_str(), "recorder-test"), FGSR_STATUS_OK);
        fgsr_session_desc desc = small_desc(so.width, so.height);
        desc.color_format = uint32_t(cap->format.color_format);
        desc.mv_format = uint32_t(cap->format.mv_format);
        desc.depth_kind = uint32_t(cap->format.conventions.depth_kind);
        desc.mv_units = uint32_t(cap->format.conventions.mv_units);
        desc.mv_direction = uint32_t(cap->format.conventions.mv_direction);
        desc.near_plane = cap->format.conventions.near_plane;
        desc.far_plane = cap->format.conventions.far_plane;
        if (through_env) setenv("FGSR_CAPTURE", dir.c_str(), 1);
        fgsr::client::Session s;
        const fgsr_status created = s.create(c, desc);
        unsetenv("FGSR_CAPTURE");
        ASSERT_EQ(created, FGSR_STATUS_OK);
        if (!through_env) {
            ASSERT_EQ(s.record(dir.c_str()), FGSR_STATUS_OK);
        }
        for (size_t i = 0; i < cap->inputs.size(); ++i) {
            const auto& f = cap->inputs[i];
            fgsr_input_slot in{};
            ASSERT_EQ(s.acquire_input(1000, in), FGSR_STATUS_OK);
            fill_slot(in, f);
            fgsr_submit_info info{};
            info.struct_size = sizeof(info);
            info.input_slot = in.index;
            info.flags = (f.mv.empty() ? 0 : FGSR_SUBMIT_HAS_MV) | (i == 2 ? FGSR_SUBMIT_RESET : 0);
            info.jitter_x = 0.25f * float(i);
            info.jitter_y = -0.125f;
            ASSERT_EQ(s.submit(info), FGSR_STATUS_OK);
            ASSERT_TRUE(d.complete_plain());
            fgsr_output out{};
            ASSERT_EQ(s.wait(1000, out), FGSR_STATUS_OK);
        }
        if (!through_env) { // else at destroy
            ASSERT_EQ(s.record(nullptr), FGSR_STATUS_OK);
        }
    }
    auto back = fgsr::capture::load(dir);
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->inputs.size(), cap->inputs.size());
    EXPECT_EQ(back->name, "recorder-test");
    EXPECT_EQ(back->format.width, so.width);
    EXPECT_EQ(back->format.color_format, cap->format.color_format);
    EXPECT_EQ(back->format.mv_format, cap->format.mv_format);
    for (size_t i = 0; i < cap->inputs.size(); ++i) {
        EXPECT_EQ(back->inputs[i].color, cap->inputs[i].color) << i;
        EXPECT_EQ(back->inputs[i].depth, cap->inputs[i].depth) << i;
        EXPECT_EQ(back->inputs[i].mv, cap->inputs[i].mv) << i;
        EXPECT_EQ(back->inputs[i].jitter_x, 0.25f * float(i));
        EXPECT_EQ(back->inputs[i].jitter_y, -0.125f);
        EXPECT_EQ(back->inputs[i].reset, i == 2) << i;
    }
    std::error_code ec;
    fs::remove_all(dir.parent_path(), ec);
}

// fgsr_capture_format cannot link the engine (the client library links it), so it has its own
// bytes-per-pixel table: pinned equal to the engine's here.
// The plane sizes the protocol, the capture format and the engine share (types.hpp, header-only so
// the client's recorder uses the same function): pinned to the documented formats.
TEST(ClientFake, PlaneBytesPerPixelAreTheDocumentedOnes) {
    EXPECT_EQ(fgsr::bytes_per_pixel(fgsr::ColorFormat::rgba8_srgb), 4u);
    EXPECT_EQ(fgsr::bytes_per_pixel(fgsr::ColorFormat::rgba16f_linear), 8u);
    EXPECT_EQ(fgsr::bytes_per_pixel(fgsr::ColorFormat::rgba32f_linear), 16u);
    EXPECT_EQ(fgsr::bytes_per_pixel(fgsr::MvFormat::rg16f), 4u);
    EXPECT_EQ(fgsr::bytes_per_pixel(fgsr::MvFormat::rg32f), 8u);
    EXPECT_EQ(fgsr::bytes_per_pixel(static_cast<fgsr::ColorFormat>(7)), 0u);
    // The protocol's enum values are the engine's.
    EXPECT_EQ(uint32_t(fgsr::ColorFormat::rgba16f_linear), uint32_t(FGSR_COLOR_RGBA16F_LINEAR));
    EXPECT_EQ(uint32_t(fgsr::MvFormat::rg32f), uint32_t(FGSR_MV_RG32F));
}

TEST(ClientFake, RecordingThroughApiLoadsBackBitIdentical) {
    record_and_compare(false);
}

TEST(ClientFake, RecordingThroughEnvironmentLoadsBackBitIdentical) {
    record_and_compare(true);
}

} // namespace
