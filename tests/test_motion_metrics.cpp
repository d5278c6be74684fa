// End-point error and its visibility mask (tools/capture metrics) on analytic fields with a known
// error, and the Middlebury .flo reader and writer (tools/capture flow_io) on files written here,
// including malformed ones.
#include <fgsr/capture/flow_io.hpp>
#include <fgsr/capture/metrics.hpp>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

using fgsr::Errc;
using namespace fgsr::capture;

namespace {

constexpr uint32_t kW = 40, kH = 30;

// A frame pair with a known geometry: the current frame is a background at depth 50 that moved
// (3, -2) px since the previous frame (vectors to previous: (-3, 2)), with a square at depth 5
// (x, y in [10, 20)) whose vectors are (4, 1). In the previous frame the square stood at the
// same place as now (depth 5 over [10, 20)^2), so the background pixels whose vectors land on it
// were hidden then, and so were those landing outside the frame.
struct Pair {
    std::vector<float> mv, depth, previous_depth;
};

bool in_square(double x, double y) {
    return x >= 10 && x < 20 && y >= 10 && y < 20;
}

Pair make_pair() {
    Pair p;
    p.mv.resize(2 * kW * kH);
    p.depth.resize(kW * kH);
    p.previous_depth.resize(kW * kH);
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + x;
            const bool sq = in_square(x, y);
            p.mv[2 * i] = sq ? 4.f : -3.f;
            p.mv[2 * i + 1] = sq ? 1.f : 2.f;
            p.depth[i] = sq ? 5.f : 50.f;
            p.previous_depth[i] = sq ? 5.f : 50.5f; // the background 1 % farther: the same surface
        }
    return p;
}

// The mask computed independently: landing pixel inside and the same kind of surface.
std::vector<uint8_t> expected_mask(const Pair& p) {
    std::vector<uint8_t> m(kW * kH, 0);
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + x;
            const double qx = x + 0.5 + p.mv[2 * i], qy = y + 0.5 + p.mv[2 * i + 1];
            if (qx < 0 || qy < 0 || qx >= kW || qy >= kH) continue;
            m[i] = in_square(x, y) == in_square(std::floor(qx), std::floor(qy));
        }
    return m;
}

TEST(MotionMetrics, VisibilityMaskOfAnalyticPair) {
    const Pair p = make_pair();
    auto mask = visible_in_both(p.mv, p.depth, p.previous_depth, kW, kH);
    ASSERT_TRUE(mask) << mask.error().message;
    const std::vector<uint8_t> expected = expected_mask(p);
    EXPECT_EQ(*mask, expected);
    size_t visible = 0, square_visible = 0;
    for (size_t i = 0; i < mask->size(); ++i) {
        visible += (*mask)[i];
        square_visible += (*mask)[i] && p.depth[i] == 5.f;
    }
    // Background landing outside: x < 3 (3 columns) or y >= 28 (2 rows); landing on the square:
    // the 10x10 block shifted by (3, -2). Square pixels landing outside the square: x >= 16 or
    // y >= 19, 100 - 6 * 9 = 46 of them.
    EXPECT_EQ(square_visible, 54u);
    EXPECT_GT(visible, 54u);
    EXPECT_LT(visible, size_t(kW) * kH - 100);
    // Pixel (0, 0): its vector lands at (-2.5, 2.5), outside. Pixel (30, 5) background: visible.
    EXPECT_EQ((*mask)[0], 0);
    EXPECT_EQ((*mask)[5 * kW + 30], 1);
    // Pixel (13, 8) background lands at (10.5, 10.5), on the square: hidden in the previous frame.
    EXPECT_EQ((*mask)[8 * kW + 13], 0);

    // A tolerance below the background's 1 % depth change hides the whole background.
    auto strict = visible_in_both(p.mv, p.depth, p.previous_depth, kW, kH, 0.005f);
    ASSERT_TRUE(strict);
    size_t strict_visible = 0;
    for (uint8_t v : *strict) strict_visible += v;
    EXPECT_EQ(strict_visible, square_visible);

    // Unknown reference vectors (known = 0, or NaN) are never visible.
    std::vector<uint8_t> known(kW * kH, 1);
    known[5 * kW + 30] = 0;
    Pair nan = p;
    nan.mv[2 * (5 * kW + 31)] = std::numeric_limits<float>::quiet_NaN();
    auto partial = visible_in_both(nan.mv, nan.depth, nan.previous_depth, kW, kH, 0.1f, known);
    ASSERT_TRUE(partial);
    EXPECT_EQ((*partial)[5 * kW + 30], 0);
    EXPECT_EQ((*partial)[5 * kW + 31], 0);
    EXPECT_EQ((*partial)[5 * kW + 32], 1);
}

TEST(MotionMetrics, EndPointErrorOfKnownError) {
    const Pair p = make_pair();
    auto mask = visible_in_both(p.mv, p.depth, p.previous_depth, kW, kH);
    ASSERT_TRUE(mask);
    // Exact vectors: 0.
    auto zero = end_point_error(p.mv, p.mv, *mask, kW, kH);
    ASSERT_TRUE(zero);
    EXPECT_EQ(*zero, 0.0);
    // Off by (0.3, 0.4) on the background, (1.2, -0.5) on the square: |e| = 0.5 and 1.3; the mean
    // weighs them by their visible pixels.
    std::vector<float> est = p.mv;
    size_t bg = 0, sq = 0;
    for (size_t i = 0; i < size_t(kW) * kH; ++i) {
        const bool square = p.depth[i] == 5.f;
        est[2 * i] += square ? 1.2f : 0.3f;
        est[2 * i + 1] += square ? -0.5f : 0.4f;
        if ((*mask)[i]) (square ? sq : bg) += 1;
    }
    auto e = end_point_error(est, p.mv, *mask, kW, kH);
    ASSERT_TRUE(e) << e.error().message;
    EXPECT_NEAR(*e, (0.5 * double(bg) + 1.3 * double(sq)) / double(bg + sq), 1e-5);
    // Hidden pixels do not count: a huge error there changes nothing.
    est[0] = 1000.f; // pixel (0, 0) is not visible
    auto same = end_point_error(est, p.mv, *mask, kW, kH);
    ASSERT_TRUE(same);
    EXPECT_NEAR(*same, *e, 1e-9);
    // A NaN estimate on a visible pixel scores +inf.
    est[2 * (5 * kW + 30)] = std::numeric_limits<float>::quiet_NaN();
    auto bad = end_point_error(est, p.mv, *mask, kW, kH);
    ASSERT_TRUE(bad);
    EXPECT_TRUE(std::isinf(*bad));
}

TEST(MotionMetrics, ErrorsAreValues) {
    const Pair p = make_pair();
    std::vector<uint8_t> none(kW * kH, 0);
    auto empty = end_point_error(p.mv, p.mv, none, kW, kH);
    ASSERT_FALSE(empty);
    EXPECT_EQ(empty.error().code, Errc::empty_input);
    std::vector<float> short_mv(p.mv.begin(), p.mv.end() - 2);
    auto sm = end_point_error(short_mv, p.mv, none, kW, kH);
    ASSERT_FALSE(sm);
    EXPECT_EQ(sm.error().code, Errc::size_mismatch);
    EXPECT_NE(sm.error().message.find("estimated"), std::string::npos) << sm.error().message;
    auto vm = visible_in_both(p.mv, short_mv, p.previous_depth, kW, kH);
    ASSERT_FALSE(vm);
    EXPECT_EQ(vm.error().code, Errc::size_mismatch);
    auto tol = visible_in_both(p.mv, p.depth, p.previous_depth, kW, kH, -1.f);
    ASSERT_FALSE(tol);
    EXPECT_EQ(tol.error().code, Errc::invalid_argument);
    EXPECT_EQ(visible_in_both({}, {}, {}, 0, 0).error().code, Errc::empty_input);
}

// A scratch directory removed at the end of each test.
class FloFiles : public testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("fgsr-test-flo-" + std::to_string(::getpid()) + "-" +
                testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path path(const char* name) const { return dir_ / name; }
    // Raw bytes: magic, w, h, then `floats` floats.
    void write_raw(const std::filesystem::path& p, float magic, int32_t w, int32_t h, size_t floats) {
        std::ofstream f(p, std::ios::binary);
        f.write(reinterpret_cast<const char*>(&magic), 4);
        f.write(reinterpret_cast<const char*>(&w), 4);
        f.write(reinterpret_cast<const char*>(&h), 4);
        std::vector<float> v(floats, 0.25f);
        f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 4));
    }
    std::filesystem::path dir_;
};

TEST_F(FloFiles, WriteThenReadBack) {
    FlowField f;
    f.width = 7;
    f.height = 3;
    for (uint32_t i = 0; i < f.width * f.height; ++i) {
        f.xy.push_back(0.5f * float(i) - 3.f);
        f.xy.push_back(-0.125f * float(i));
    }
    ASSERT_TRUE(write_flo(path("a.flo"), f));
    EXPECT_EQ(std::filesystem::file_size(path("a.flo")), 12u + 7 * 3 * 8);
    auto r = read_flo(path("a.flo"));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->width, 7u);
    EXPECT_EQ(r->height, 3u);
    EXPECT_EQ(r->xy, f.xy);
    // The layout is the Middlebury one: magic bytes "PIEH", then width, height, row-major x, y.
    std::ifstream in(path("a.flo"), std::ios::binary);
    char head[4];
    in.read(head, 4);
    EXPECT_EQ(std::string(head, 4), "PIEH");
    int32_t wh[2];
    float first[4];
    in.read(reinterpret_cast<char*>(wh), 8);
    in.read(reinterpret_cast<char*>(first), 16);
    EXPECT_EQ(wh[0], 7);
    EXPECT_EQ(wh[1], 3);
    EXPECT_EQ(first[2], f.xy[2]); // pixel (1, 0) x
    EXPECT_EQ(first[3], f.xy[3]);
    // With the expected size: fine; with another: size_mismatch naming both.
    EXPECT_TRUE(read_flo(path("a.flo"), 7, 3));
    auto other = read_flo(path("a.flo"), 3, 7);
    ASSERT_FALSE(other);
    EXPECT_EQ(other.error().code, Errc::size_mismatch);
    EXPECT_NE(other.error().message.find("7x3"), std::string::npos) << other.error().message;
    EXPECT_NE(other.error().message.find("3x7"), std::string::npos) << other.error().message;
}

TEST_F(FloFiles, MalformedFilesAreRefusedWithReasons) {
    auto expect_io = [&](const std::filesystem::path& p, const char* reason) {
        auto r = read_flo(p);
        ASSERT_FALSE(r) << p;
        EXPECT_EQ(r.error().code, Errc::io) << p;
        EXPECT_NE(r.error().message.find(reason), std::string::npos) << r.error().message;
        EXPECT_NE(r.error().message.find(p.filename().string()), std::string::npos) << r.error().message;
    };
    write_raw(path("magic.flo"), 1.5f, 2, 2, 8);
    expect_io(path("magic.flo"), "magic");
    write_raw(path("truncated.flo"), kFloMagic, 4, 3, 4 * 3 * 2 - 1);
    expect_io(path("truncated.flo"), "truncated");
    write_raw(path("trailing.flo"), kFloMagic, 4, 3, 4 * 3 * 2 + 1);
    expect_io(path("trailing.flo"), "trailing");
    write_raw(path("zero.flo"), kFloMagic, 0, 3, 0);
    expect_io(path("zero.flo"), "0x3");
    write_raw(path("negative.flo"), kFloMagic, 4, -3, 24);
    expect_io(path("negative.flo"), "4x-3");
    write_raw(path("huge.flo"), kFloMagic, 1 << 20, 1 << 20, 0);
    expect_io(path("huge.flo"), "1048576x1048576");
    {
        std::ofstream f(path("header.flo"), std::ios::binary);
        f.write("PIEH\x02", 5);
    }
    expect_io(path("header.flo"), "header");
    expect_io(path("missing.flo"), "missing.flo");

    FlowField bad;
    bad.width = 2;
    bad.height = 2;
    bad.xy.resize(7);
    auto w = write_flo(path("bad.flo"), bad);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error().code, Errc::invalid_argument);
}

} // namespace
