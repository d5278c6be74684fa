// fgsrd's control-message parser and its ring protocol, in process and without a device: the
// parser is a pure function of the packet; a session made without an engine runs poll, begin,
// execute (which completes with DEVICE_ERROR) and finish over real shared memory.
#include "messages.hpp"
#include "session.hpp"

#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <cstring>
#include <sys/mman.h>
#include <vector>

namespace fgsrd {
namespace {

std::vector<std::byte> packet(uint16_t type, size_t size, uint32_t seq = 7) {
    std::vector<std::byte> p(size);
    fgsr_msg_header h = fgsr_msg_header_for(type, uint32_t(size), seq);
    std::memcpy(p.data(), &h, std::min(size, sizeof(h)));
    return p;
}

std::string violation(const Request& r) {
    const auto* v = std::get_if<Violation>(&r);
    return v ? v->reason : std::string("(no violation)");
}

TEST(DaemonMessages, EveryWireCheckIsAViolationWithItsReason) {
    auto hello = packet(FGSR_MSG_HELLO, sizeof(fgsr_hello));
    EXPECT_NE(violation(parse_request(hello.data(), 8, false)).find("shorter than a header"),
              std::string::npos);
    auto bad = hello;
    bad[0] = std::byte{0};
    EXPECT_EQ(violation(parse_request(bad.data(), bad.size(), false)), "bad magic");
    EXPECT_NE(violation(parse_request(hello.data(), hello.size() - 1, false)).find("but the packet has"),
              std::string::npos);
    auto stats = packet(FGSR_MSG_STATS, sizeof(fgsr_session_ref));
    EXPECT_EQ(violation(parse_request(stats.data(), stats.size(), false)), "the first message must be HELLO");
    EXPECT_EQ(violation(parse_request(hello.data(), hello.size(), true)), "second HELLO");
    auto short_hello = packet(FGSR_MSG_HELLO, sizeof(fgsr_msg_header) + 4);
    EXPECT_NE(violation(parse_request(short_hello.data(), short_hello.size(), false)).find("truncated"),
              std::string::npos);
    auto unknown = packet(999, sizeof(fgsr_msg_header));
    EXPECT_EQ(violation(parse_request(unknown.data(), unknown.size(), true)), "unknown message type 999");
    auto create = packet(FGSR_MSG_CREATE_SESSION, sizeof(fgsr_create_session));
    fgsr_session_desc d{};
    d.struct_size = sizeof(d) + 64; // beyond the packet
    std::memcpy(create.data() + sizeof(fgsr_msg_header), &d, sizeof(d));
    EXPECT_NE(violation(parse_request(create.data(), create.size(), true)).find("struct_size"),
              std::string::npos);
    d.struct_size = 16; // below the struct
    std::memcpy(create.data() + sizeof(fgsr_msg_header), &d, sizeof(d));
    EXPECT_NE(violation(parse_request(create.data(), create.size(), true)).find("struct_size"),
              std::string::npos);
}

TEST(DaemonMessages, ValidRequestsAreParsedAndTheNameIsTerminated) {
    auto hello = packet(FGSR_MSG_HELLO, sizeof(fgsr_hello) + 16); // longer packets are accepted
    fgsr_hello h{};
    std::memcpy(&h, hello.data(), sizeof(fgsr_msg_header));
    h.major = FGSR_PROTOCOL_MAJOR;
    std::memset(h.name, 'x', sizeof(h.name)); // not terminated by the sender
    std::memcpy(hello.data(), &h, sizeof(h));
    const Request r = parse_request(hello.data(), hello.size(), false);
    ASSERT_TRUE(std::holds_alternative<HelloRequest>(r)) << violation(r);
    EXPECT_EQ(std::strlen(std::get<HelloRequest>(r).hello.name), sizeof(h.name) - 1);
    auto create = packet(FGSR_MSG_CREATE_SESSION, sizeof(fgsr_create_session), 42);
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = 123;
    std::memcpy(create.data() + sizeof(fgsr_msg_header), &d, sizeof(d));
    const Request c = parse_request(create.data(), create.size(), true);
    ASSERT_TRUE(std::holds_alternative<CreateRequest>(c)) << violation(c);
    EXPECT_EQ(std::get<CreateRequest>(c).sequence, 42u);
    EXPECT_EQ(std::get<CreateRequest>(c).desc.width, 123u);
    auto destroy = packet(FGSR_MSG_DESTROY_SESSION, sizeof(fgsr_session_ref));
    const Request s = parse_request(destroy.data(), destroy.size(), true);
    ASSERT_TRUE(std::holds_alternative<SessionRequest>(s));
    EXPECT_EQ(std::get<SessionRequest>(s).type, FGSR_MSG_DESTROY_SESSION);
}

fgsr_session_desc small_desc() {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = d.height = 16;
    d.color_format = d.output_format = FGSR_COLOR_RGBA8_SRGB;
    d.scale = 1.f;
    d.modes = FGSR_MODE_INTERPOLATE;
    d.input_slots = 2;
    d.output_slots = 2;
    return d;
}

struct Rings {
    std::byte* base = nullptr;
    size_t size = 0;
    fgsr_rings_layout rl{};
    uint32_t capacity = 0;
    ~Rings() {
        if (base) munmap(base, size);
    }
    // Maps the session's rings memfd as a client would.
    bool map(const ServiceSession& s) {
        size = s.layout().rings_size;
        capacity = s.layout().ring_capacity;
        rl = fgsr_rings_layout_for(capacity);
        void* m = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, s.fds()[FGSR_FD_RINGS], 0);
        if (m == MAP_FAILED) return false;
        base = static_cast<std::byte*>(m);
        return true;
    }
    fgsr_ring_header* hdr(uint64_t off) { return reinterpret_cast<fgsr_ring_header*>(base + off); }
    void submit(uint64_t position, const fgsr_submit_entry& e) {
        auto* entries = reinterpret_cast<fgsr_submit_entry*>(base + rl.submit_entries);
        entries[fgsr_ring_index(position, capacity)] = e;
        fgsr_ring_publish(hdr(rl.submit_header), position + 1);
    }
};

TEST(DaemonMessages, ASessionWithoutAnEngineRunsTheRingProtocol) {
    int32_t status = -1;
    std::string reason;
    auto s = ServiceSession::create(nullptr, 1, small_desc(), false, status, reason);
    ASSERT_TRUE(s) << reason;
    Rings r;
    ASSERT_TRUE(r.map(*s));

    fgsr_submit_entry e{};
    e.sequence = 1;
    e.input_slot = 0;
    e.interp_count = 1;
    e.interp_alphas[0] = 0.5f;
    r.submit(0, e);
    ASSERT_EQ(s->poll(), std::nullopt);
    ASSERT_TRUE(s->ready());
    auto begun = s->begin();
    ASSERT_FALSE(begun.violation);
    ASSERT_TRUE(begun.job);
    EXPECT_TRUE(s->in_flight());
    EXPECT_FALSE(s->ready());
    s->execute(*begun.job);
    ASSERT_EQ(s->finish(*begun.job), std::nullopt);
    EXPECT_TRUE(s->signal_pending());
    auto* ce = reinterpret_cast<const fgsr_completion_entry*>(r.base + r.rl.completion_entries);
    ASSERT_EQ(fgsr_ring_load_head(r.hdr(r.rl.completion_header)), 1u);
    EXPECT_EQ(ce[0].status, FGSR_STATUS_DEVICE_ERROR);
    EXPECT_EQ(ce[0].sequence, 1u);
    EXPECT_NE(ce[0].flags & FGSR_COMPLETION_INPUT_RELEASED, 0u);
    EXPECT_EQ(ce[0].output_slot, FGSR_NO_SLOT);
    EXPECT_EQ(s->stats().frames_rejected, 1u);

    // The slot came back: reusing it is fine; a slot out of range and a non-increasing sequence
    // are violations.
    e.sequence = 2;
    r.submit(1, e);
    EXPECT_EQ(s->poll(), std::nullopt);
    e.sequence = 2;
    e.input_slot = 1;
    r.submit(2, e);
    auto why = s->poll();
    ASSERT_TRUE(why);
    EXPECT_NE(why->find("does not increase"), std::string::npos) << *why;
}

TEST(DaemonMessages, ARingHeadBeyondCapacityIsAViolation) {
    int32_t status = -1;
    std::string reason;
    auto s = ServiceSession::create(nullptr, 1, small_desc(), false, status, reason);
    ASSERT_TRUE(s) << reason;
    Rings r;
    ASSERT_TRUE(r.map(*s));
    fgsr_ring_publish(r.hdr(r.rl.submit_header), uint64_t(r.capacity) + 5);
    auto why = s->poll();
    ASSERT_TRUE(why);
    EXPECT_NE(why->find("beyond tail"), std::string::npos) << *why;
}

} // namespace
} // namespace fgsrd
