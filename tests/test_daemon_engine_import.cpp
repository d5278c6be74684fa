// Engine API for the daemon: zero-copy ingest from imported host memory
// (VK_EXT_external_memory_host) gives the same internal frames as the staging copy, and pass
// timings carry CLOCK_MONOTONIC begin/end times.
#include "engine_fixture.hpp"

#include <fgsr/core/clock.hpp>

#include <sys/mman.h>

namespace fgsr::test {
namespace {

// Page-aligned host memory holding the planes of a frame at 4096-aligned offsets.
struct Pool {
    size_t size = 0;
    std::byte* data = nullptr;
    explicit Pool(size_t bytes) : size((bytes + 4095) / 4096 * 4096) {
        data = static_cast<std::byte*>(
            mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    }
    ~Pool() { munmap(data, size); }
};

size_t align4k(size_t v) {
    return (v + 4095) / 4096 * 4096;
}

TEST(DaemonEngineImport, ZeroCopyIngestEqualsStagingCopy) {
    Engine& e = engine();
    if (e.host_import_alignment() == 0) GTEST_SKIP() << e.device_name() << " cannot import host memory";
    ASSERT_LE(e.host_import_alignment(), 4096u);
    const uint32_t w = 32, h = 24;
    const FrameFormat fmt = internal_format(w, h);
    auto staged = e.create_session(fmt);
    auto direct = e.create_session(fmt);
    ASSERT_TRUE(staged && direct);
    for (uint32_t k = 0; k < 2; ++k) {
        // Non-finite values too: ingest sanitises whatever bytes it reads in place.
        RawFrame f = random_frame(w, h, 10 + k, 3.f);
        const float nan = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(f.color.data(), &nan, 4);
        const size_t oc = 0, od = align4k(f.color.size()), om = od + align4k(f.depth.size());
        Pool pool(om + f.mv.size());
        std::memcpy(pool.data + oc, f.color.data(), f.color.size());
        std::memcpy(pool.data + od, f.depth.data(), f.depth.size());
        std::memcpy(pool.data + om, f.mv.data(), f.mv.size());
        auto mem = e.import_host_memory(pool.data, pool.size);
        ASSERT_TRUE(mem) << mem.error().message;
        FrameView v{{pool.data + oc, f.color.size()},
                    {pool.data + od, f.depth.size()},
                    {pool.data + om, f.mv.size()}};
        const uint64_t before = monotonic_ns();
        ASSERT_TRUE((*staged)->submit(f.view()));
        ASSERT_TRUE((*direct)->submit(v, **mem));
        const uint64_t after = monotonic_ns();
        for (int which = k == 0 ? 1 : 0; which < 2; ++which) { // frame 0 exists from the second submit on
            auto a = (*staged)->read_frame(which), b = (*direct)->read_frame(which);
            ASSERT_TRUE(a && b);
            EXPECT_EQ(0, std::memcmp(a->color.data(), b->color.data(), a->color.size() * 4));
            EXPECT_EQ(0, std::memcmp(a->depth.data(), b->depth.data(), a->depth.size() * 4));
            EXPECT_EQ(0, std::memcmp(a->mv.data(), b->mv.data(), a->mv.size() * 4));
            EXPECT_EQ(a->has_mv, b->has_mv);
            EXPECT_EQ(b->color[0], 0.f) << "NaN colour sanitised";
        }
        const PassTiming t = (*direct)->last_ingest_timing();
        EXPECT_EQ(t.name, "ingest");
        EXPECT_LE(t.begin_ns, t.end_ns);
        // Monotonic times within the submit call (generous: anchoring may be off by the queue's
        // start-up latency, calibration by its deviation).
        EXPECT_GT(t.begin_ns + 50'000'000ull, before);
        EXPECT_LT(t.end_ns, after + 50'000'000ull);
    }
    // A plane outside the imported memory is refused.
    RawFrame f = random_frame(w, h, 3, 1.f);
    Pool pool(4096);
    auto mem = e.import_host_memory(pool.data, pool.size);
    ASSERT_TRUE(mem);
    EXPECT_FALSE((*direct)->submit(f.view(), **mem));
    expect_no_validation_errors();
}

TEST(DaemonEngineImport, GeneratedFramePassesHaveMonotonicTimes) {
    Engine& e = engine();
    const uint32_t w = 32, h = 24;
    auto s = e.create_session(internal_format(w, h));
    ASSERT_TRUE(s);
    ASSERT_TRUE((*s)->submit(random_frame(w, h, 1, 2.f).view()));
    ASSERT_TRUE((*s)->submit(random_frame(w, h, 2, 2.f).view()));
    const uint64_t before = monotonic_ns();
    auto out = (*s)->interpolate(std::vector<float>{0.25f, 0.5f});
    const uint64_t after = monotonic_ns();
    ASSERT_TRUE(out);
    for (const GeneratedFrame& g : *out) {
        ASSERT_FALSE(g.passes.empty());
        uint64_t prev_end = 0;
        for (const PassTiming& p : g.passes) {
            EXPECT_LE(p.begin_ns, p.end_ns) << p.name;
            EXPECT_LE(prev_end, p.begin_ns) << p.name << " starts before the previous pass ended";
            prev_end = p.end_ns;
            EXPECT_GT(p.begin_ns + 50'000'000ull, before);
            EXPECT_LT(p.end_ns, after + 50'000'000ull);
        }
    }
    expect_no_validation_errors();
}

} // namespace
} // namespace fgsr::test
