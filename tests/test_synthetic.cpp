// The analytic synthetic scene and the built-in "synthetic-toss" capture (tools/capture).
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

using fgsr::ImageRGBA;
using namespace fgsr::capture;

namespace {

// Bilinear sample of linear RGB at continuous pixel coordinates (centres at +0.5), clamped to edge.
glm::vec3 bilinear(const ImageRGBA& im, double px, double py) {
    const double u = px - 0.5, v = py - 0.5;
    const int x0 = int(std::floor(u)), y0 = int(std::floor(v));
    const double fx = u - x0, fy = v - y0;
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, int(im.width) - 1);
        y = std::clamp(y, 0, int(im.height) - 1);
        const float* p = &im.rgba[(size_t(y) * im.width + x) * 4];
        return glm::dvec3(p[0], p[1], p[2]);
    };
    const glm::dvec3 c = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
    return glm::vec3(c);
}

// True when every point of a (2r/step+1)^2 grid around (x, y) shows layer `l` at time t.
bool all_layer(const SyntheticScene& s, size_t l, double x, double y, double t, double r, double step) {
    for (double dy = -r; dy <= r + 1e-9; dy += step)
        for (double dx = -r; dx <= r + 1e-9; dx += step)
            if (s.visible_layer(x + dx, y + dy, t) != l) return false;
    return true;
}

struct WarpResult {
    double psnr_interior = 0, psnr_all = 0;
    size_t interior = 0, disoccluded = 0, pixels = 0;
    double max_texture_error = 0; // |layer colour at p, t - layer colour at p + mv, t_prev|
};

// Warps frame t-1 to frame t with the exact vectors of frame t and a bilinear sampler.
WarpResult warp_check(const SyntheticScene& s, double t) {
    const SyntheticScene::Sample cur = s.render(t, t - 1.0);
    const ImageRGBA prev = s.render_color(t - 1.0);
    const uint32_t w = s.options().width, h = s.options().height;
    ImageRGBA warped = cur.color;
    std::vector<uint8_t> mask(size_t(w) * h, 0);
    WarpResult r;
    r.pixels = mask.size();
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const double cx = x + 0.5, cy = y + 0.5;
            const double px = cx + cur.mv[i].x, py = cy + cur.mv[i].y;
            const glm::vec3 c = bilinear(prev, px, py);
            for (int k = 0; k < 3; ++k) warped.rgba[i * 4 + k] = c[k];
            const size_t l = cur.layer[i];
            if (s.visible_layer(px, py, t - 1.0) != l) {
                ++r.disoccluded; // the surface point was hidden (or is new) at t-1
                continue;
            }
            const glm::vec3 now = s.layer_color(l, cx, cy, t), then = s.layer_color(l, px, py, t - 1.0);
            r.max_texture_error = std::max<double>(r.max_texture_error, glm::length(now - then));
            // Interior: the pixel's footprint and the bilinear footprint at t-1 (with the box filter
            // of the neighbouring pixels) show only this layer, and lie inside the image.
            if (px < 1.5 || py < 1.5 || px > w - 1.5 || py > h - 1.5) continue;
            if (!all_layer(s, l, cx, cy, t, 0.75, 0.75)) continue;
            if (!all_layer(s, l, px, py, t - 1.0, 1.5, 0.75)) continue;
            mask[i] = 1;
            ++r.interior;
        }
    r.psnr_interior = *psnr_masked(warped, cur.color, mask);
    r.psnr_all = *psnr(warped, cur.color);
    return r;
}

} // namespace

TEST(Synthetic, ExactVectorsReproduceNextFrame) {
    const SyntheticScene s(SceneOptions{});
    size_t disoccluded = 0;
    for (double t : {1.0, 4.0, 8.0, 10.0}) {
        const WarpResult r = warp_check(s, t);
        // The vectors name the same surface point: the analytic texture agrees to float rounding.
        EXPECT_LT(r.max_texture_error, 1e-4) << "t=" << t;
        // Bilinear resampling of the antialiased frame is the only error left in the interior.
        EXPECT_GT(r.interior, r.pixels * 7 / 10) << "t=" << t;
        EXPECT_GT(r.psnr_interior, 44.0) << "t=" << t;
        // Edges and disocclusions are where warping alone fails.
        EXPECT_LT(r.psnr_all, r.psnr_interior) << "t=" << t;
        disoccluded += r.disoccluded;
        std::printf("t=%.0f interior %.2f dB (%zu px), all %.2f dB, disoccluded %zu, max tex err %.2g\n", t,
                    r.psnr_interior, r.interior, r.psnr_all, r.disoccluded, r.max_texture_error);
    }
    EXPECT_GT(disoccluded, 100u);
}

TEST(Synthetic, NearestLayerWinsAtOverlaps) {
    const SyntheticScene s(SceneOptions{});
    const uint32_t w = s.options().width, h = s.options().height;
    size_t overlaps = 0;
    for (double t = 0.0; t <= 10.0; t += 0.5) {
        const std::vector<uint8_t> map = s.layer_map(t);
        for (uint32_t y = 0; y < h; y += 2)
            for (uint32_t x = 0; x < w; x += 2) {
                size_t best = 0, covering = 0;
                for (size_t i = 1; i < s.layer_count(); ++i) {
                    if (!s.layer_covers(i, x + 0.5, y + 0.5, t)) continue;
                    ++covering;
                    if (best == 0 || s.layer_depth(i) < s.layer_depth(best)) best = i;
                }
                if (covering >= 2) ++overlaps;
                ASSERT_EQ(map[size_t(y) * w + x], best) << "t=" << t << " x=" << x << " y=" << y;
            }
    }
    EXPECT_GT(overlaps, 1000u); // layers do overlap (the ball crosses the panel and the disc, ...)

    // render() reports the visible layer's depth and motion.
    const SyntheticScene::Sample smp = s.render(8.0, 7.0);
    for (size_t i = 0; i < smp.layer.size(); ++i) {
        const size_t l = smp.layer[i];
        ASSERT_EQ(smp.depth[i], s.layer_depth(l));
        const glm::dvec2 mv = s.layer_position(l, 7.0) - s.layer_position(l, 8.0);
        ASSERT_NEAR(smp.mv[i].x, mv.x, 1e-4);
        ASSERT_NEAR(smp.mv[i].y, mv.y, 1e-4);
    }
}

TEST(Synthetic, SceneHasThinBarsExitsAndEntries) {
    const SyntheticScene s(SceneOptions{});
    std::vector<size_t> count0(s.layer_count()), count10(s.layer_count());
    for (uint8_t l : s.layer_map(0.0)) ++count0[l];
    for (uint8_t l : s.layer_map(10.0)) ++count10[l];
    bool thin = false, enters = false, leaves = false;
    std::vector<float> depths;
    for (size_t i = 0; i < s.layer_count(); ++i) {
        depths.push_back(s.layer_depth(i));
        const glm::dvec2 half = s.layer_half_size(i);
        if (s.layer_shape(i) == LayerShape::rect && std::min(half.x, half.y) * 2 >= 1.0 &&
            std::min(half.x, half.y) * 2 <= 2.0)
            thin = true;
        if (count0[i] == 0 && count10[i] > 100) enters = true;
        if (count0[i] > 100 && count10[i] == 0) leaves = true;
    }
    EXPECT_TRUE(thin);
    EXPECT_TRUE(enters);
    EXPECT_TRUE(leaves);
    std::sort(depths.begin(), depths.end());
    EXPECT_TRUE(std::adjacent_find(depths.begin(), depths.end()) == depths.end())
        << "depths must be distinct";
    EXPECT_EQ(s.layer_shape(0), LayerShape::plane);
    EXPECT_EQ(depths.back(), s.layer_depth(0)); // the background is the farthest
}

TEST(Synthetic, UniformVelocityWhenNotAccelerated) {
    SceneOptions o;
    o.accelerated = false;
    const SyntheticScene s(o);
    for (size_t i = 0; i < s.layer_count(); ++i) {
        for (double t : {0.0, 3.0, 9.0}) {
            const glm::dvec2 mid = 0.5 * (s.layer_position(i, t) + s.layer_position(i, t + 1.0));
            EXPECT_NEAR(s.layer_position(i, t + 0.5).x, mid.x, 1e-9);
            EXPECT_NEAR(s.layer_position(i, t + 0.5).y, mid.y, 1e-9);
        }
        EXPECT_EQ(s.layer_acceleration(i), glm::dvec2(0.0));
    }
    // Accelerated: the tossed ball's halfway position is well off the midpoint (a/8 per frame^2).
    const SyntheticScene acc(SceneOptions{});
    double max_dev = 0;
    for (size_t i = 0; i < acc.layer_count(); ++i) {
        const glm::dvec2 mid = 0.5 * (acc.layer_position(i, 0.0) + acc.layer_position(i, 1.0));
        max_dev = std::max(max_dev, glm::length(acc.layer_position(i, 0.5) - mid));
    }
    EXPECT_GT(max_dev, 1.0);
}

TEST(Synthetic, SpeedScalesMotion) {
    SceneOptions o;
    o.speed = 2.0f;
    const SyntheticScene fast(o), base(SceneOptions{});
    for (size_t i = 0; i < base.layer_count(); ++i) {
        const glm::dvec2 d1 = base.layer_position(i, 3.0) - base.layer_position(i, 0.0);
        const glm::dvec2 d2 = fast.layer_position(i, 3.0) - fast.layer_position(i, 0.0);
        EXPECT_NEAR(d2.x, 2.0 * d1.x, 1e-9);
        EXPECT_NEAR(d2.y, 2.0 * d1.y, 1e-9);
    }
}

TEST(Synthetic, DeterministicPerSeed) {
    const SyntheticScene a(SceneOptions{}), b(SceneOptions{});
    const ImageRGBA ia = a.render_color(3.25), ib = b.render_color(3.25);
    ASSERT_EQ(ia.rgba.size(), ib.rgba.size());
    EXPECT_EQ(std::memcmp(ia.rgba.data(), ib.rgba.data(), ia.rgba.size() * sizeof(float)), 0);
    SceneOptions o;
    o.seed = 2;
    const ImageRGBA ic = SyntheticScene(o).render_color(3.25);
    EXPECT_NE(std::memcmp(ia.rgba.data(), ic.rgba.data(), ia.rgba.size() * sizeof(float)), 0);
}

TEST(Synthetic, RenderMatchesPointTexture) {
    // With one sample per pixel the colour is the visible layer's texture at the pixel centre.
    SceneOptions o;
    o.supersample = 1;
    o.width = 160;
    o.height = 90;
    const SyntheticScene s(o);
    const SyntheticScene::Sample smp = s.render(5.5, 4.5);
    double max_err = 0;
    for (uint32_t y = 0; y < o.height; ++y)
        for (uint32_t x = 0; x < o.width; ++x) {
            const size_t i = size_t(y) * o.width + x;
            const glm::vec3 c = s.layer_color(smp.layer[i], x + 0.5, y + 0.5, 5.5);
            for (int k = 0; k < 3; ++k)
                max_err = std::max<double>(max_err, std::abs(c[k] - smp.color.rgba[i * 4 + k]));
            ASSERT_EQ(smp.color.rgba[i * 4 + 3], 1.0f);
        }
    EXPECT_LT(max_err, 1e-5);
}

TEST(Synthetic, CaptureLayout) {
    const SceneOptions o; // the CLI's default capture
    auto r = make_synthetic_capture(o, 11);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const fgsr::capture::Capture& c = *r;
    EXPECT_EQ(c.name, "synthetic-toss");
    EXPECT_EQ(c.source, "synthetic");
    EXPECT_EQ(c.format.width, o.width);
    EXPECT_EQ(c.format.height, o.height);
    EXPECT_EQ(c.format.color_format, fgsr::ColorFormat::rgba32f_linear);
    EXPECT_EQ(c.format.mv_format, fgsr::MvFormat::rg32f);
    EXPECT_EQ(c.format.conventions.depth_kind, fgsr::DepthKind::linear);
    EXPECT_EQ(c.format.conventions.mv_units, fgsr::MvUnits::pixels);
    EXPECT_EQ(c.format.conventions.mv_direction, fgsr::MvDirection::to_previous);
    EXPECT_FALSE(c.format.conventions.mv_y_up);
    EXPECT_EQ(c.ground_truth_kind, fgsr::capture::GroundTruth::halfway);
    ASSERT_EQ(c.inputs.size(), 11u);
    ASSERT_EQ(c.ground_truth.size(), 10u);
    const size_t n = size_t(o.width) * o.height;
    const SyntheticScene s(o);
    for (size_t k = 0; k < c.inputs.size(); ++k) {
        const auto& f = c.inputs[k];
        ASSERT_EQ(f.color.size(), n * 16);
        ASSERT_EQ(f.depth.size(), n * 4);
        ASSERT_EQ(f.mv.size(), k == 0 ? 0 : n * 8);
        EXPECT_EQ(f.jitter_x, 0.f);
        EXPECT_EQ(f.jitter_y, 0.f);
    }
    // Spot checks against the scene: frame 6 colour/depth/vectors, ground truth 6 at t = 6.5.
    const SyntheticScene::Sample smp = s.render(6.0, 5.0);
    EXPECT_EQ(std::memcmp(c.inputs[6].color.data(), smp.color.rgba.data(), n * 16), 0);
    EXPECT_EQ(std::memcmp(c.inputs[6].depth.data(), smp.depth.data(), n * 4), 0);
    EXPECT_EQ(std::memcmp(c.inputs[6].mv.data(), smp.mv.data(), n * 8), 0);
    const ImageRGBA gt = s.render_color(6.5);
    EXPECT_EQ(c.ground_truth[6].rgba, gt.rgba);
    // The halfway frame is neither neighbour.
    EXPECT_LT(*psnr(c.ground_truth[6], s.render_color(6.0)), 30.0);
    EXPECT_LT(*psnr(c.ground_truth[6], s.render_color(7.0)), 30.0);
}

TEST(Synthetic, InvalidOptionsAreErrors) {
    SceneOptions o;
    EXPECT_EQ(make_synthetic_capture(o, 1).error().code, fgsr::Errc::invalid_argument);
    o.width = 0;
    EXPECT_EQ(make_synthetic_capture(o, 3).error().code, fgsr::Errc::invalid_argument);
    o = SceneOptions{};
    o.supersample = 0;
    EXPECT_FALSE(validate(o).ok());
    o = SceneOptions{};
    o.speed = -1.0f;
    EXPECT_FALSE(validate(o).ok());
    EXPECT_TRUE(validate(SceneOptions{}).ok());
}
