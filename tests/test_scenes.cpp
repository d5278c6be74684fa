// Frame generation on analytic scenes (tools/capture synthetic.hpp): the exact colour at any
// instant is the ground truth, and the scene's layers say which surface is visible where, so the
// tests can score occlusion handling region by region. Thresholds were set from measured values
// with margin (measured figures in comments, lavapipe, default 480x270 scene).
#include "engine_fixture.hpp"

#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

namespace fgsr::test {
namespace {

using capture::SceneOptions;
using capture::SyntheticScene;

// Runs interpolation (alpha) or extrapolation (1 + alpha) for inputs t = 0..count-1 of a scene and
// returns the generated frames for pairs (k, k+1), k >= 1 (so that frame 0 has vectors).
struct Generated {
    std::vector<ImageRGBA> frames;
    std::vector<double> times; // scene time of each generated frame
};

// cut_at: input t = cut_at gets every vector moved 600 px to the right, as the first input after
// a camera cut has (they point to where each surface was in the other shot).
Generated generate(const SyntheticScene& scene, MotionModel motion, bool extrapolate, float alpha,
                   int count, int cut_at = -1, bool vector_cuts = true) {
    const SceneOptions& o = scene.options();
    Params p = given_field();
    p.motion = motion;
    p.vector_cuts = vector_cuts;
    auto s = engine().create_session(internal_format(o.width, o.height), p);
    EXPECT_TRUE(s);
    Generated g;
    for (int t = 0; t < count; ++t) {
        auto smp = scene.render(t, t - 1);
        if (t == cut_at)
            for (size_t i = 0; i < smp.mv.size(); ++i) smp.mv[i].x += 600.0f;
        RawFrame raw =
            make_raw(std::vector<glm::vec4>(reinterpret_cast<const glm::vec4*>(smp.color.rgba.data()),
                                            reinterpret_cast<const glm::vec4*>(smp.color.rgba.data()) +
                                                smp.color.rgba.size() / 4),
                     smp.depth, t == 0 ? std::vector<glm::vec2>{} : smp.mv);
        EXPECT_TRUE((*s)->submit(raw.view()));
        if (t < 2) continue;
        const float a[] = {alpha};
        auto out = extrapolate ? (*s)->extrapolate(a) : (*s)->interpolate(a);
        EXPECT_TRUE(out) << out.error().message;
        g.frames.push_back(std::move((*out)[0].color));
        g.times.push_back(extrapolate ? t + alpha : t - 1 + alpha);
    }
    return g;
}

double mean_psnr(const SyntheticScene& scene, const Generated& g) {
    double sum = 0;
    for (size_t i = 0; i < g.frames.size(); ++i)
        sum += *capture::psnr(g.frames[i], scene.render_color(g.times[i]));
    return sum / double(g.frames.size());
}

TEST(Scenes, InterpolationAndExtrapolationReachStatedPsnr) {
    SyntheticScene scene(SceneOptions{});
    const double interp = mean_psnr(scene, generate(scene, MotionModel::quadratic, false, 0.5f, 7));
    const double extrap = mean_psnr(scene, generate(scene, MotionModel::quadratic, true, 0.5f, 7));
    std::printf("[ measured ] interpolation %.2f dB, extrapolation %.2f dB\n", interp, extrap);
    EXPECT_GT(interp, 33.0);
    EXPECT_GT(extrap, 28.0);
    expect_no_validation_errors();
}

TEST(Scenes, AnyAlphaInterpolates) {
    SyntheticScene scene(SceneOptions{});
    for (float a : {0.1f, 0.3f, 0.7f, 0.9f}) {
        double p = mean_psnr(scene, generate(scene, MotionModel::quadratic, false, a, 4));
        std::printf("[ measured ] alpha %.1f: %.2f dB\n", double(a), p);
        EXPECT_GT(p, 33.0) << "alpha " << a;
    }
}

TEST(Scenes, QuadraticBeatsLinearOnAcceleratedMotion) {
    SyntheticScene accel(SceneOptions{});
    for (bool extrap : {false, true}) {
        double q = mean_psnr(accel, generate(accel, MotionModel::quadratic, extrap, 0.5f, 7));
        double l = mean_psnr(accel, generate(accel, MotionModel::linear, extrap, 0.5f, 7));
        std::printf("[ measured ] %s: quadratic %.2f dB, linear %.2f dB\n",
                    extrap ? "extrapolation" : "interpolation", q, l);
        EXPECT_GT(q, l + 0.3) << (extrap ? "extrapolation" : "interpolation") << ": quadratic " << q
                              << " linear " << l;
    }
    // Control: without acceleration both models predict the same positions.
    SceneOptions o;
    o.accelerated = false;
    SyntheticScene uniform(o);
    double q = mean_psnr(uniform, generate(uniform, MotionModel::quadratic, false, 0.5f, 5));
    double l = mean_psnr(uniform, generate(uniform, MotionModel::linear, false, 0.5f, 5));
    std::printf("[ measured ] uniform velocity: quadratic %.2f dB, linear %.2f dB\n", q, l);
    EXPECT_NEAR(q, l, 0.15);
}

TEST(Scenes, ImplausibleAccelerationFallsBackToUniformVelocity) {
    // After a cut the previous input's vectors describe another shot: the quadratic model must not
    // read an acceleration from them (shaders/motion.h, MOTION_ACCEL_PX). Pairs (t-1, t) for
    // t = 2..5; input 3's vectors are a cut's, so the pair (3, 4) reads them as frame-0 motion.
    // Ingest's cut stage (Params::vector_cuts) would find this cut first (its vectors explain none
    // of the colour) and drop them: it is off here, so that the bound is tested for the cuts the
    // stage does not see (one that leaves under half of the blocks unmatched, or aliased input
    // whose blocks never match; Cut.* test the stage).
    SyntheticScene accel(SceneOptions{});
    for (bool extrap : {false, true}) {
        const Generated q = generate(accel, MotionModel::quadratic, extrap, 0.5f, 6, 3, false);
        const Generated l = generate(accel, MotionModel::linear, extrap, 0.5f, 6, 3, false);
        ASSERT_EQ(q.frames.size(), 4u);
        const size_t pair = 2; // generated after input 4 was submitted: from the pair (3, 4)
        const double qp = *capture::psnr(q.frames[pair], accel.render_color(q.times[pair]));
        const double lp = *capture::psnr(l.frames[pair], accel.render_color(l.times[pair]));
        std::printf("[ measured ] %s after a cut: quadratic %.2f dB, linear %.2f dB\n",
                    extrap ? "extrapolation" : "interpolation", qp, lp);
        EXPECT_NEAR(qp, lp, 0.05) << "the quadratic model used the cut's vectors";
        EXPECT_GT(qp, 28.0);
    }
}

// A w x h frame of one grey surface at depth 1 with vectors (set by the caller).
ref::InternalFrame flat_frame(uint32_t w, uint32_t h) {
    ref::InternalFrame f;
    f.width = w;
    f.height = h;
    f.color.assign(size_t(w) * h, glm::vec4(0.5f));
    f.depth.assign(size_t(w) * h, 1.f);
    f.has_mv = true;
    return f;
}

// The plausibility bound of shaders/motion.h on the CPU reference: a surface whose motion changes
// by less than MOTION_ACCEL_PX + MOTION_ACCEL_RATIO |m1| (2 px + |m1|) between frames follows the
// parabola (supplement Eqs. 1, 2); one that turns back, or changes by more, moves uniformly.
TEST(Scenes, AccelerationBoundChoosesParabolaOrUniformVelocity) {
    const uint32_t w = 32, h = 16;
    struct Case {
        glm::vec2 m1, m0; // motion frame 0 -> 1 and frame -1 -> 0, pixels
        bool parabola;
    };
    const Case cases[] = {
        {{4.f, 0.f}, {3.f, 0.f}, true},   // speeding up: |m1 - m0| = 1 < 6
        {{4.f, 0.f}, {4.f, 3.f}, true},   // turning: 3 < 6
        {{4.f, 0.f}, {-4.f, 0.f}, false}, // turning back: 8 > 6
        {{0.5f, 0.f}, {-1.f, 0.f}, true}, // slow, reversing within 2 px: 1.5 < 2.5
        {{1.f, 1.f}, {-3.f, 1.f}, false}, // reversing beyond it: 4 > 3.41
    };
    for (const Case& c : cases)
        for (bool extrap : {false, true}) {
            ref::InternalFrame f0 = flat_frame(w, h), f1 = flat_frame(w, h);
            f1.mv.assign(size_t(w) * h, -c.m1); // internal vectors point to the previous frame
            f0.mv.assign(size_t(w) * h, -c.m0);
            Params p = given_field();
            const float a = 0.5f;
            const ref::GenParams g = params::gen_params(internal_format(w, h), p, a, extrap, true, true);
            const ref::Splat sp = ref::splat(f0, f1, g);
            const glm::ivec2 px(16, 8);
            const size_t i = size_t(px.y) * w + size_t(px.x);
            const glm::vec2 c1 = glm::vec2(px) + 0.5f, p0 = c1 - c.m1;
            const glm::vec4 v = ref::source_field_vectors(f0, f1, sp, uint32_t(i), g);
            const glm::vec2 pt = c1 - glm::vec2(v.z, v.w);
            const glm::vec2 accel = 0.5f * a * a * (c.m1 - c.m0);
            const glm::vec2 parabola =
                extrap ? c1 + 0.5f * a * (3.f * c.m1 - c.m0) + accel : p0 + 0.5f * a * (c.m1 + c.m0) + accel;
            const glm::vec2 uniform = extrap ? c1 + a * c.m1 : p0 + a * c.m1;
            const glm::vec2 want = c.parabola ? parabola : uniform;
            EXPECT_LT(glm::length(pt - want), 1e-4f)
                << "m1 (" << c.m1.x << ", " << c.m1.y << "), m0 (" << c.m0.x << ", " << c.m0.y << "), "
                << (extrap ? "extrapolation" : "interpolation") << ": at (" << pt.x << ", " << pt.y << ")";
            EXPECT_GT(glm::length(parabola - uniform), 0.1f); // the cases tell the two apart
            // The vectors the later passes recompute from splat's m0 are the position splat used:
            // under this uniform motion the pixel holding pt holds exactly this source's key.
            const glm::ivec2 t(glm::floor(pt));
            ASSERT_TRUE(t.x >= 0 && t.y >= 0 && t.x < int(w) && t.y < int(h));
            EXPECT_EQ(sp.keys[size_t(t.y) * w + size_t(t.x)] & 0xffffffffu, uint64_t(i));
        }
}

// Where the CPU reference puts frame-1 pixel px at the generated time a (splat, then its field
// vectors).
glm::vec2 generated_position(const ref::InternalFrame& f0, const ref::InternalFrame& f1, const Params& p,
                             float a, bool extrap, glm::ivec2 px) {
    const ref::GenParams g =
        params::gen_params(internal_format(f1.width, f1.height), p, a, extrap, true, true);
    const ref::Splat sp = ref::splat(f0, f1, g);
    const size_t i = size_t(px.y) * f1.width + size_t(px.x);
    const glm::vec4 v = ref::source_field_vectors(f0, f1, sp, uint32_t(i), g);
    return glm::vec2(px) + 0.5f - glm::vec2(v.z, v.w);
}

// The extrapolation search of shaders/motion.h (docs/ACCURACY.md, change 13): the edge pixel of a
// uniformly sliding object whose frame-0 position lands on the still ground beside it (zero vector,
// a depth within the tolerance: a false deceleration). In extrapolation the edge neighbour of the
// same surface with the smallest acceleration wins, so the object moves uniformly; a neighbour of
// another depth is not taken; interpolation, and Params::accel_search off (the balanced and
// performance presets), keep the pixel under p0.
TEST(Scenes, ExtrapolationTakesTheSmallestAccelerationOfTheSameSurface) {
    const uint32_t w = 32, h = 16;
    const glm::vec2 m1(2.f, 0.f); // frame 0 -> 1; frame -1 -> 0 the same (uniform sliding)
    const glm::ivec2 px(16, 8);
    const glm::vec2 c1 = glm::vec2(px) + 0.5f, p0 = c1 - m1;
    const glm::ivec2 under(glm::floor(p0)), beside = under + glm::ivec2(1, 0); // ground, object
    for (bool search : {true, false})
        for (bool same_depth : {true, false})
            for (bool extrap : {false, true}) {
                ref::InternalFrame f0 = flat_frame(w, h), f1 = flat_frame(w, h);
                f1.mv.assign(size_t(w) * h, -m1);
                f0.mv.assign(size_t(w) * h, glm::vec2(0.f)); // the ground
                const size_t b = size_t(beside.y) * w + size_t(beside.x);
                f0.mv[b] = -m1;                     // the object's frame-0 motion
                if (!same_depth) f0.depth[b] = 2.f; // another surface: not a candidate
                Params p = given_field();
                p.accel_search = search;
                const float a = 0.5f;
                const glm::vec2 pt = generated_position(f0, f1, p, a, extrap, px);
                const glm::vec2 m0_ground(0.f);
                const glm::vec2 accel = 0.5f * a * a * (m1 - m0_ground);
                const glm::vec2 decelerated = extrap ? c1 + 0.5f * a * (3.f * m1 - m0_ground) + accel
                                                     : p0 + 0.5f * a * (m1 + m0_ground) + accel;
                const glm::vec2 uniform = extrap ? c1 + a * m1 : p0 + a * m1;
                ASSERT_GT(glm::length(decelerated - uniform), 0.1f); // the case tells the two apart
                const glm::vec2 want = search && extrap && same_depth ? uniform : decelerated;
                EXPECT_LT(glm::length(pt - want), 1e-4f)
                    << (extrap ? "extrapolation" : "interpolation")
                    << (same_depth ? ", same depth" : ", other depth") << (search ? "" : ", no search")
                    << ": at (" << pt.x << ", " << pt.y << ")";
            }
}

// The frame-0 depth test of shaders/motion.h with Params::accel_depth_motion (docs/ACCURACY.md,
// change 21), on the CPU reference, with the median and the search off (each tested on its own):
// a surface growing 1.3x a frame (a zoom about the frame's centre, as the camera approaches; its
// growth slowing from 1.2x the frame before: an acceleration) or shrinking to 1 / 1.3 (receding,
// faster than the frame before), its frame-0 depth 30 % larger or smaller than its frame-1 depth.
// That is more than 4 T_D (20 %), so without the rule the pixel moves uniformly; with it the depth
// change the vectors imply is expected and the pixel follows the parabola through its frame-0
// vector. Where the vectors imply no change (a uniform slide), a frame-0 depth 30 % away is another
// surface with the rule too.
TEST(Scenes, FrameZeroDepthTestExpectsTheDepthChangeTheMotionImplies) {
    const uint32_t w = 64, h = 32;
    const glm::vec2 centre(32.f, 16.f);
    const float a = 0.5f;
    struct Case {
        float k1, k0;  // growth from frame 0 to 1 and from frame -1 to 0 (1: a uniform slide)
        float depth0;  // frame-0 depth (frame 1: 1)
        bool expected; // the depth change is what the vectors imply
    };
    const Case cases[] = {
        {1.3f, 1.2f, 1.3f, true}, {1.f / 1.3f, 1.f / 1.1f, 1.f / 1.3f, true}, {1.f, 1.f, 1.3f, false}};
    for (const Case& c : cases)
        for (bool rule : {true, false})
            for (bool extrap : {false, true}) {
                Params p = given_field();
                p.accel_depth_motion = rule;
                p.accel_median = false;
                p.accel_search = false;
                ref::InternalFrame f0 = flat_frame(w, h), f1 = flat_frame(w, h);
                const glm::vec2 slide = c.k1 == 1.f ? glm::vec2(2.f, 0.f) : glm::vec2(0.f); // a = 1 px
                const glm::vec2 slide0 = c.k1 == 1.f ? glm::vec2(1.f, 0.f) : glm::vec2(0.f);
                for (uint32_t y = 0; y < h; ++y)
                    for (uint32_t x = 0; x < w; ++x) {
                        const glm::vec2 r = glm::vec2(float(x), float(y)) + 0.5f - centre;
                        f1.mv.push_back(-r * (1.f - 1.f / c.k1) - slide); // to the frame-0 position
                        f0.mv.push_back(-r * (1.f - 1.f / c.k0) - slide0);
                        f0.depth[size_t(y) * w + x] = c.depth0;
                    }
                const glm::ivec2 px(44, 16);
                const glm::vec2 c1 = glm::vec2(px) + 0.5f, m1 = -f1.mv[size_t(px.y) * w + size_t(px.x)];
                const glm::ivec2 q(glm::floor(c1 - m1));
                const glm::vec2 m0 = -f0.mv[size_t(q.y) * w + size_t(q.x)];
                auto at = [&](glm::vec2 m0_used) {
                    const glm::vec2 accel = 0.5f * a * a * (m1 - m0_used), p0 = c1 - m1;
                    return extrap ? c1 + 0.5f * a * (3.f * m1 - m0_used) + accel
                                  : p0 + 0.5f * a * (m1 + m0_used) + accel;
                };
                ASSERT_GT(glm::length(at(m0) - at(m1)), 0.1f); // the case tells the two apart
                const glm::vec2 want = rule && c.expected ? at(m0) : at(m1);
                const glm::vec2 pt = generated_position(f0, f1, p, a, extrap, px);
                EXPECT_LT(glm::length(pt - want), 1e-4f)
                    << "growth " << c.k1 << ", frame-0 depth " << c.depth0 << ", "
                    << (extrap ? "extrapolation" : "interpolation") << (rule ? "" : ", no rule") << ": at ("
                    << pt.x << ", " << pt.y << ")";
            }
}

// The median of the acceleration in shaders/motion.h (docs/ACCURACY.md, change 18): a surface
// accelerating uniformly (m0 = (2, 0) px a frame, m1 = (3, 0)) whose pixel px reads its frame-0
// vector from a pixel of another surface at the same depth (zero vector: a false deceleration, as
// from another leaf of a canopy). Its 3x3 neighbours, each followed to its own frame-0 pixel, give
// the surface's acceleration, so in interpolation px follows the parabola of the true motion. It
// keeps its own acceleration with Params::accel_median off, in extrapolation, and on a surface one
// pixel high (its same-surface neighbours are 2 of the 9; fewer than MOTION_MEDIAN_MIN take part).
TEST(Scenes, InterpolationTakesTheMedianAccelerationOfTheSameSurface) {
    const uint32_t w = 32, h = 16;
    const glm::vec2 m1(3.f, 0.f), m0(2.f, 0.f), wrong(0.f); // paper notation: motion towards frame 1
    const glm::ivec2 px(16, 8);
    const glm::vec2 c1 = glm::vec2(px) + 0.5f, p0 = c1 - m1;
    const glm::ivec2 under(glm::floor(p0));
    for (bool median : {true, false})
        for (bool thin : {false, true})
            for (bool extrap : {false, true}) {
                ref::InternalFrame f0 = flat_frame(w, h), f1 = flat_frame(w, h);
                f1.mv.assign(size_t(w) * h, -m1);
                f0.mv.assign(size_t(w) * h, -m0);
                f0.mv[size_t(under.y) * w + size_t(under.x)] = -wrong;
                if (thin) // only row px.y is the surface: the rows above and below lie far behind
                    for (uint32_t y = 0; y < h; ++y)
                        for (uint32_t x = 0; x < w; ++x)
                            if (int(y) != px.y)
                                f0.depth[size_t(y) * w + x] = f1.depth[size_t(y) * w + x] = 4.f;
                Params p = given_field();
                p.accel_median = median;
                p.accel_search = false; // extrapolation's own remedy, tested above
                const float a = 0.5f;
                const glm::vec2 pt = generated_position(f0, f1, p, a, extrap, px);
                auto at = [&](glm::vec2 m0_used) {
                    const glm::vec2 accel = 0.5f * a * a * (m1 - m0_used);
                    return extrap ? c1 + 0.5f * a * (3.f * m1 - m0_used) + accel
                                  : p0 + 0.5f * a * (m1 + m0_used) + accel;
                };
                ASSERT_GT(glm::length(at(m0) - at(wrong)), 0.1f); // the case tells the two apart
                const glm::vec2 want = median && !thin && !extrap ? at(m0) : at(wrong);
                EXPECT_LT(glm::length(pt - want), 1e-4f)
                    << (extrap ? "extrapolation" : "interpolation") << (thin ? ", thin surface" : "")
                    << (median ? "" : ", no median") << ": at (" << pt.x << ", " << pt.y << ")";
                // Another pixel of the surface (its own frame-0 pixel right) follows the parabola.
                const glm::ivec2 other = px + glm::ivec2(3, 0);
                EXPECT_LT(glm::length(generated_position(f0, f1, p, a, extrap, other) -
                                      (at(m0) + glm::vec2(3.f, 0.f))),
                          1e-4f);
            }
}

// The edge cover of shaders/disocc.h (docs/ACCURACY.md, change 14) on the CPU reference: a bright
// bar sliding right over a still, darker ground, antialiased in colour and point-sampled in depth
// and vectors as a renderer gives them. The ground truth at the generated time is the analytic
// coverage of each pixel by the bar. Over a sweep of sub-pixel edge positions and speeds, the
// pixels at the bar's edges come closer to it with the cover than without in interpolation (and
// no further from it in extrapolation); pixels more than 3 px from an edge are left exactly as
// they were; the separate passes and the fused pass agree, with the cover and without.
// The CPU reference's frame at alpha (1 + alpha when extrap) with one Params switch off and on
// (`set`), by the separate passes and by the fused pass, which are expected to agree pixel by pixel.
struct Toggled {
    std::vector<glm::vec4> out[2]; // separate passes: [0] off, [1] on
};
Toggled generate_toggled(const ref::InternalFrame& f0, const ref::InternalFrame& f1, float a, bool extrap,
                         const std::function<void(Params&, bool)>& set) {
    Toggled t;
    for (bool on : {false, true}) {
        Params p = given_field();
        set(p, on);
        const ref::GenParams g =
            params::gen_params(internal_format(f0.width, f0.height), p, a, extrap, true, true);
        t.out[on] = ref::generate(f0, f1, g);
        const std::vector<glm::vec4> fused = ref::generate_fused(f0, f1, ref::splat(f0, f1, g), g);
        for (size_t i = 0; i < fused.size(); ++i)
            EXPECT_LT(glm::length(t.out[on][i] - fused[i]), 1e-5f)
                << "separate vs fused, switch " << on << ", pixel " << i;
    }
    return t;
}

struct BarCase {
    float start, end, speed; // the bar's extent in frame 1 and its speed (px per frame, to the right)
};
ref::InternalFrame bar_frame(uint32_t w, uint32_t h, const BarCase& c, float time) {
    const glm::vec4 ground(0.2f, 0.2f, 0.2f, 1.f), bar(1.f, 0.9f, 0.6f, 1.f);
    const float shift = (time - 1.f) * c.speed, b = c.start + shift, e = c.end + shift;
    ref::InternalFrame f = flat_frame(w, h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const float cover = std::clamp(std::min(e, float(x) + 1.f) - std::max(b, float(x)), 0.f, 1.f);
            f.color[i] = glm::mix(ground, bar, cover);
            const bool front = float(x) + 0.5f > b && float(x) + 0.5f < e; // point-sampled
            f.depth[i] = front ? 1.f : 10.f;
            f.mv.push_back(front ? glm::vec2(-c.speed, 0.f) : glm::vec2(0.f)); // to the previous frame
        }
    return f;
}

TEST(Scenes, EdgeCoverBringsMovingEdgesCloserToTheirCoverage) {
    const uint32_t w = 64, h = 4;
    for (bool extrap : {false, true}) {
        double err_on = 0, err_off = 0;
        size_t changed = 0, edge_pixels = 0;
        for (float speed : {3.3f, 5.6f, 7.9f})
            for (int k = 0; k < 10; ++k) {
                const BarCase c{14.f + 0.1f * float(k) + 0.05f, 34.f + 0.07f * float(k) + 0.03f, speed};
                const float a = 0.5f, time = extrap ? 1.f + a : a;
                const ref::InternalFrame f0 = bar_frame(w, h, c, 0.f), f1 = bar_frame(w, h, c, 1.f);
                const ref::InternalFrame truth = bar_frame(w, h, c, time);
                const Toggled t =
                    generate_toggled(f0, f1, a, extrap, [](Params& p, bool on) { p.cover_edges = on; });
                const auto& out = t.out;
                for (size_t i = 0; i < out[1].size(); ++i) {
                    const float x = float(i % w) + 0.5f, shift = (time - 1.f) * speed;
                    const bool edge = std::abs(x - (c.start + shift)) < 3.f || std::abs(x - (c.end + shift)) < 3.f;
                    if (!edge) {
                        EXPECT_EQ(out[0][i], out[1][i]) << "pixel " << i << " away from the edges";
                        continue;
                    }
                    ++edge_pixels;
                    changed += out[0][i] != out[1][i];
                    err_off += glm::length(glm::vec3(out[0][i] - truth.color[i]));
                    err_on += glm::length(glm::vec3(out[1][i] - truth.color[i]));
                }
            }
        std::printf("[ measured ] %s: edge error %.4f without the cover, %.4f with it (%zu of %zu edge pixels changed)\n",
                    extrap ? "extrapolation" : "interpolation", err_off / double(edge_pixels),
                    err_on / double(edge_pixels), changed, edge_pixels);
        EXPECT_GT(changed, edge_pixels / 20) << "the cases have covered holes";
        // Measured: interpolation 0.0541 -> 0.0309; extrapolation 0.0379 either way (its holes'
        // fill, frame 1's own vector there, is already the front's at this trailing edge).
        if (extrap)
            EXPECT_LE(err_on, err_off * 1.001) << "extrapolation";
        else
            EXPECT_LT(err_on, 0.75 * err_off) << "interpolation";
    }
}

// Extrapolation's holes that frame 0 saw (shaders/disocc.h, fill_hole; shaders/warp.h,
// frame0_behind; docs/ACCURACY.md, change 50) on the CPU reference: a bright bar 12 px wide
// accelerating right over still ground, x(t) = s + 13 (t - 1) + 3 (t - 1)^2 (steps of 4 and 10 px),
// point-sampled in depth and vectors, frames 0 and 1 with their vectors. At 1.5 the bar has moved
// 7.25 px; the paper's fill of the uncovered ground reads frame 1 half a step back along the bar's
// vector (5 px), which for the last 2.25 px lands on the bar itself: a strip of bar. Frame 0,
// where the bar was 10 px further left, shows the ground there. The analytic frame at 1.5 is the truth. Over
// a sweep of sub-pixel positions, the uncovered ground's error falls with the rule and is large without it;
// pixels more than 3 px from the uncovered span are left exactly as they were; the separate passes equal the
// fused pass with the rule and without.
ref::InternalFrame accelerating_bar(uint32_t w, uint32_t h, float s, float time) {
    const glm::vec4 ground(0.2f, 0.25f, 0.3f, 1.f), bar(1.f, 0.9f, 0.6f, 1.f);
    const float width = 12.f;
    auto x_at = [&](float t) { return s + 13.f * (t - 1.f) + 3.f * (t - 1.f) * (t - 1.f); };
    const float b = x_at(time), step = x_at(time - 1.f) - b; // to the previous frame
    ref::InternalFrame f = flat_frame(w, h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const float cover =
                std::clamp(std::min(b + width, float(x) + 1.f) - std::max(b, float(x)), 0.f, 1.f);
            f.color[i] = glm::mix(ground, bar, cover);
            const bool front = float(x) + 0.5f > b && float(x) + 0.5f < b + width;
            f.depth[i] = front ? 1.f : 10.f;
            f.mv.push_back(front ? glm::vec2(step, 0.f) : glm::vec2(0.f));
        }
    return f;
}

TEST(Scenes, ExtrapolatedHolesTakeFrameZeroWhereFrameOneShowsTheSurfaceThatLeft) {
    const uint32_t w = 64, h = 4;
    const float a = 0.5f, moved = 13.f * a + 3.f * a * a; // 7.25 px by 1.5
    double err_on = 0, err_off = 0;
    size_t uncovered = 0;
    for (int k = 0; k < 10; ++k) {
        const float s = 20.f + 0.1f * float(k) + 0.03f;
        const ref::InternalFrame f0 = accelerating_bar(w, h, s, 0.f), f1 = accelerating_bar(w, h, s, 1.f);
        const ref::InternalFrame truth = accelerating_bar(w, h, s, 1.f + a);
        const Toggled t = generate_toggled(f0, f1, a, true, [](Params& p, bool on) { p.hole_frame0 = on; });
        const auto& out = t.out;
        for (size_t i = 0; i < out[1].size(); ++i) {
            const float x = float(i % w) + 0.5f;
            if (x < s - 3.f || x > s + moved + 3.f) {
                EXPECT_EQ(out[0][i], out[1][i]) << "pixel " << i << " away from the uncovered ground";
                continue;
            }
            if (x < s + 0.5f || x > s + moved - 0.5f) continue; // partly covered in the truth
            ++uncovered;
            err_off += glm::length(glm::vec3(out[0][i] - truth.color[i]));
            err_on += glm::length(glm::vec3(out[1][i] - truth.color[i]));
        }
    }
    err_off /= double(uncovered);
    err_on /= double(uncovered);
    std::printf(
        "[ measured ] accelerating bar, extrapolation to 1.5: uncovered ground's error %.4f without the "
        "rule, %.4f with it (%zu pixels)\n",
        err_off, err_on, uncovered);
    EXPECT_GT(err_off, 0.1) << "the paper's fill shows the bar a second time";
    EXPECT_LT(err_on, 0.25 * err_off);
}

// Content leaving the frame (shaders/splat.h, splat_leaving, and shaders/disocc.h, leaving_frame0;
// docs/ACCURACY.md, changes 28 and 29) on the CPU reference: a textured ground panning left at
// 12 px a frame and a near post crossing the left edge at 40 px a frame, gone by frame 1,
// point-sampled. Frame 1 has no pixel of the post, so only frame 0 can put it into the generated
// frame; and interpolation's holes at the left edge (ground that frame 1 no longer has) take the
// background's vectors, whose frame-0 sample can land on the post where it has already moved on.
// The analytic frame at alpha 0.5 is the truth. With frame 0's vectors both rules apply; without
// them (frame0_has_mv false: the motion is uniform, so nothing else differs) neither can. Over a
// sweep of the post's widths and positions, the left part's error falls; columns the post never
// reaches, and a ground without a post, are left exactly as they were; the separate passes and
// the fused pass agree.
struct LeavingCase {
    float start, end; // the post's extent in frame 0 (px); it and the ground move left
};
ref::InternalFrame leaving_frame(uint32_t w, uint32_t h, const LeavingCase& c, bool post, float time) {
    constexpr float ground_speed = 12.f, post_speed = 40.f;
    const float b = c.start - time * post_speed, e = c.end - time * post_speed;
    ref::InternalFrame f = flat_frame(w, h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const float centre = float(x) + 0.5f;
            const bool front = post && centre > b && centre < e;
            const float u = centre + time * ground_speed; // the ground's own coordinate
            const float grey = 0.45f + 0.3f * std::sin(0.9f * u) + 0.1f * std::sin(0.23f * u);
            f.color[i] = front ? glm::vec4(0.9f, 0.5f, 0.2f, 1.f) : glm::vec4(grey, grey, grey, 1.f);
            f.depth[i] = front ? 2.f : 20.f;
            f.mv.push_back(glm::vec2(front ? post_speed : ground_speed, 0.f)); // to the previous frame
        }
    return f;
}

// out[0] without frame 0's vectors, out[1] with them; the separate passes against the fused pass.
void generate_with_and_without_frame0_vectors(const ref::InternalFrame& f0, const ref::InternalFrame& f1,
                                              float a, std::vector<glm::vec4> out[2]) {
    for (bool frame0_mv : {false, true}) {
        Params p = given_field();
        p.motion = MotionModel::linear;
        const ref::GenParams g =
            params::gen_params(internal_format(f0.width, f0.height), p, a, false, frame0_mv, true);
        out[frame0_mv] = ref::generate(f0, f1, g);
        const std::vector<glm::vec4> fused = ref::generate_fused(f0, f1, ref::splat(f0, f1, g), g);
        for (size_t i = 0; i < fused.size(); ++i)
            ASSERT_LT(glm::length(out[frame0_mv][i] - fused[i]), 1e-5f) << "separate vs fused, pixel " << i;
    }
}

TEST(Scenes, ContentLeavingTheFrameComesFromFrameZero) {
    // Holes are at x < 6 (half the ground's motion); the post reaches x = 43 at most by alpha.
    const uint32_t w = 96, h = 3, holes = 6, edge = 48;
    const float a = 0.5f;
    double err_with = 0, err_without = 0, holes_with = 0, holes_without = 0;
    size_t changed = 0;
    for (bool post : {true, false})
        for (float width : {7.f, 31.f})
            for (int k = 0; k < 12; ++k) {
                const LeavingCase c{6.f + 2.3f * float(k), 6.f + 2.3f * float(k) + width};
                const ref::InternalFrame f0 = leaving_frame(w, h, c, post, 0.f),
                                         f1 = leaving_frame(w, h, c, post, 1.f);
                const ref::InternalFrame truth = leaving_frame(w, h, c, post, a);
                std::vector<glm::vec4> out[2];
                generate_with_and_without_frame0_vectors(f0, f1, a, out);
                for (size_t i = 0; i < out[0].size(); ++i) {
                    if (i % w >= edge || !post) {
                        EXPECT_EQ(out[0][i], out[1][i])
                            << "pixel " << i << (post ? " away from the edge" : " without a post");
                        continue;
                    }
                    const double without = glm::length(glm::vec3(out[0][i] - truth.color[i]));
                    const double with = glm::length(glm::vec3(out[1][i] - truth.color[i]));
                    changed += out[0][i] != out[1][i];
                    err_without += without;
                    err_with += with;
                    if (i % w >= holes) continue;
                    holes_without += without;
                    holes_with += with;
                }
            }
    std::printf("[ measured ] the left %u columns' error %.4f without frame 0's vectors, %.4f with them "
                "(%zu pixels changed); in the holes (x < %u) %.4f and %.4f\n",
                edge, err_without, err_with, changed, holes, holes_without, holes_with);
    // Measured: 338.64 -> 28.22 over the left 48 columns (540 pixels changed), 123.13 -> 28.22 in
    // the holes; what remains is ground that was behind the post in frame 0 and is off the frame in
    // frame 1: no input sees it.
    EXPECT_GE(changed, 100u) << "the cases exercise the rules";
    EXPECT_LT(err_with, 0.5 * err_without);
    EXPECT_LT(holes_with, holes_without);
}

// The frame's edge under a pan with parallax (shaders/splat.h, splat_leaving, the same surface;
// docs/ACCURACY.md, change 30): a far wall (depth 40, 3 px a frame) over a near ground (depth 20,
// 12 px a frame), both textured and moving left. The ground's holes at the left edge (ground that
// frame 1 no longer shows) took the vectors of the farthest splatted pixel nearby, which is the
// wall's within 16 rows of it, and so read frame 0 at the wall's shorter motion. Frame 0's own
// pixels of the ground now fill them. The analytic frame at alpha 0.5 is the truth.
ref::InternalFrame parallax_frame(uint32_t w, uint32_t h, float time) {
    ref::InternalFrame f = flat_frame(w, h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const bool wall = y < h / 2;
            const float speed = wall ? 3.f : 12.f, u = float(x) + 0.5f + time * speed;
            const float grey = wall ? 0.5f + 0.3f * std::sin(0.6f * u)
                                    : 0.45f + 0.3f * std::sin(0.9f * u) + 0.1f * std::sin(0.23f * u);
            const size_t i = size_t(y) * w + x;
            f.color[i] = glm::vec4(grey, grey, grey, 1.f);
            f.depth[i] = wall ? 40.f : 20.f;
            f.mv.push_back(glm::vec2(speed, 0.f)); // to the previous frame
        }
    return f;
}

TEST(Scenes, EdgeHolesTakeTheirOwnSurfacesMotion) {
    const uint32_t w = 64, h = 24;
    const ref::InternalFrame f0 = parallax_frame(w, h, 0.f), f1 = parallax_frame(w, h, 1.f);
    const ref::InternalFrame truth = parallax_frame(w, h, 0.5f);
    std::vector<glm::vec4> out[2];
    generate_with_and_without_frame0_vectors(f0, f1, 0.5f, out);
    double err[2] = {0, 0};
    size_t changed = 0;
    for (size_t i = 0; i < out[0].size(); ++i) {
        changed += out[0][i] != out[1][i];
        for (int k : {0, 1}) err[k] += glm::length(glm::vec3(out[k][i] - truth.color[i]));
    }
    std::printf("[ measured ] error %.4f without frame 0's vectors, %.4f with them (%zu pixels changed)\n",
                err[0], err[1], changed);
    // Measured: 48.89 -> 12.38 (84 pixels changed).
    EXPECT_GE(changed, 24u) << "the ground's holes at the left edge";
    EXPECT_LT(err[1], 0.35 * err[0]);
}

// The same scene at a camera cut that the session did not see: frame 0 is already the new shot,
// but its vectors are the reprojection to the old one, far off (300 px), while the content stays
// where it is (here: a still ground and a still post). Frame 1 shows the same surface at every
// frame-0 pixel, so nothing there is leaving, and the generated frame is what it is without
// frame 0's vectors.
TEST(Scenes, FrameZeroVectorsOfAnUnseenCutMoveNothingOut) {
    const uint32_t w = 96, h = 3;
    for (float offset : {-300.f, 300.f, 60.f}) {
        ref::InternalFrame f0 = leaving_frame(w, h, LeavingCase{30.f, 45.f}, true, 0.f);
        for (glm::vec2& v : f0.mv) v = glm::vec2(offset, 0.f);
        ref::InternalFrame f1 = f0;
        for (glm::vec2& v : f1.mv) v = glm::vec2(0.f);
        std::vector<glm::vec4> out[2];
        generate_with_and_without_frame0_vectors(f0, f1, 0.5f, out);
        for (size_t i = 0; i < out[0].size(); ++i)
            EXPECT_EQ(out[0][i], out[1][i]) << "offset " << offset << ", pixel " << i;
    }
}

// Pixels at time t whose visible surface point, followed along its layer's path, is visible
// (or hidden) at time `other`; eroded by one pixel so that edges do not count.
std::vector<uint8_t> visibility_mask(const SyntheticScene& scene, double t, double other, bool want_visible) {
    const SceneOptions& o = scene.options();
    std::vector<uint8_t> layers = scene.layer_map(t), m(size_t(o.width) * o.height, 0);
    for (uint32_t y = 1; y + 1 < o.height; ++y)
        for (uint32_t x = 1; x + 1 < o.width; ++x) {
            size_t i = size_t(y) * o.width + x;
            bool uniform = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    uniform = uniform && layers[size_t(int(i) + dy * int(o.width) + dx)] == layers[i];
            if (!uniform) continue;
            size_t l = layers[i];
            glm::dvec2 p =
                glm::dvec2(x + 0.5, y + 0.5) + scene.layer_position(l, other) - scene.layer_position(l, t);
            bool inside = p.x >= 1 && p.y >= 1 && p.x < o.width - 1 && p.y < o.height - 1;
            bool visible = inside && scene.visible_layer(p.x, p.y, other) == l;
            bool hidden = inside && !visible;
            // Require a clear answer one pixel around the point too.
            for (int k = 0; k < 4 && inside; ++k) {
                glm::dvec2 q = p + glm::dvec2(k == 0   ? 1.5
                                              : k == 1 ? -1.5
                                                       : 0,
                                              k == 2   ? 1.5
                                              : k == 3 ? -1.5
                                                       : 0);
                bool v = scene.visible_layer(q.x, q.y, other) == l;
                visible = visible && v;
                hidden = hidden && !v;
            }
            m[i] = want_visible ? visible : hidden;
        }
    return m;
}

std::vector<uint8_t> both(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    std::vector<uint8_t> m(a.size());
    for (size_t i = 0; i < a.size(); ++i) m[i] = a[i] && b[i];
    return m;
}

TEST(Scenes, DisoccludedRegionsComeFromTheFrameThatSeesThem) {
    SyntheticScene scene(SceneOptions{});
    Generated g = generate(scene, MotionModel::quadratic, false, 0.5f, 9);
    size_t revealed_px = 0, covered_px = 0;
    double revealed_err = 0, covered_err = 0, revealed_wrong = 0, covered_wrong = 0;
    for (size_t f = 0; f < g.frames.size(); ++f) {
        const double t = g.times[f], t0 = std::floor(t), t1 = t0 + 1;
        const ImageRGBA gt = scene.render_color(t);
        const ImageRGBA c0 = scene.render_color(t0), c1 = scene.render_color(t1);
        // Revealed: hidden at frame 0, visible at frame 1. Covered: the opposite.
        auto revealed = both(visibility_mask(scene, t, t0, false), visibility_mask(scene, t, t1, true));
        auto covered = both(visibility_mask(scene, t, t0, true), visibility_mask(scene, t, t1, false));
        // Error of the output, and error of the same pixel taken from the wrong input at the
        // same place (what a ghost would look like), against the truth.
        for (size_t i = 0; i < revealed.size(); ++i) {
            auto err = [&](const ImageRGBA& a) {
                double e = 0;
                for (int k = 0; k < 3; ++k)
                    e += std::abs(a.rgba[4 * i + size_t(k)] - gt.rgba[4 * i + size_t(k)]);
                return e / 3;
            };
            if (revealed[i]) {
                ++revealed_px;
                revealed_err += err(g.frames[f]);
                revealed_wrong += err(c0);
            }
            if (covered[i]) {
                ++covered_px;
                covered_err += err(g.frames[f]);
                covered_wrong += err(c1);
            }
        }
    }
    ASSERT_GT(revealed_px, 200u) << "the scene must reveal background";
    ASSERT_GT(covered_px, 200u) << "the scene must cover background";
    revealed_err /= double(revealed_px);
    covered_err /= double(covered_px);
    revealed_wrong /= double(revealed_px);
    covered_wrong /= double(covered_px);
    std::printf("[ measured ] revealed %zu px: error %.4f (wrong frame %.4f); covered %zu px: error %.4f "
                "(wrong frame %.4f)\n",
                revealed_px, revealed_err, revealed_wrong, covered_px, covered_err, covered_wrong);
    // The output must be far closer to the truth than the occluder a wrong pick would show.
    EXPECT_LT(revealed_err, 0.25 * revealed_wrong)
        << "revealed: " << revealed_err << " vs " << revealed_wrong;
    EXPECT_LT(covered_err, 0.25 * covered_wrong) << "covered: " << covered_err << " vs " << covered_wrong;
    EXPECT_LT(revealed_err, 0.03);
    EXPECT_LT(covered_err, 0.03);
}

TEST(Scenes, ForegroundWinsAtOverlaps) {
    SyntheticScene scene(SceneOptions{});
    for (bool extrap : {false, true}) {
        Generated g = generate(scene, MotionModel::quadratic, extrap, 0.5f, 9);
        const SceneOptions& o = scene.options();
        size_t n = 0, right = 0;
        for (size_t f = 0; f < g.frames.size(); ++f) {
            const double t = g.times[f];
            std::vector<uint8_t> layers = scene.layer_map(t);
            for (uint32_t y = 2; y + 2 < o.height; ++y)
                for (uint32_t x = 2; x + 2 < o.width; ++x) {
                    size_t i = size_t(y) * o.width + x;
                    size_t front = layers[i];
                    bool interior = true;
                    for (int dy = -2; dy <= 2; ++dy)
                        for (int dx = -2; dx <= 2; ++dx)
                            interior = interior && layers[size_t(int(i) + dy * int(o.width) + dx)] == front;
                    if (!interior || front == 0) continue;
                    // Another non-background layer behind it at this pixel?
                    size_t behind = 0;
                    for (size_t l = 1; l < scene.layer_count() && !behind; ++l)
                        if (l != front && scene.layer_depth(l) > scene.layer_depth(front) &&
                            scene.layer_covers(l, x + 0.5, y + 0.5, t))
                            behind = l;
                    if (!behind) continue;
                    // The front surface must be visible in the newest input: a point it does not
                    // show (off screen, or disoccluded since) is a disocclusion, not an overlap.
                    const double newest = extrap ? std::floor(t) : std::ceil(t);
                    glm::dvec2 p1 = glm::dvec2(x + 0.5, y + 0.5) + scene.layer_position(front, newest) -
                                    scene.layer_position(front, t);
                    if (p1.x < 2 || p1.y < 2 || p1.x > o.width - 2 || p1.y > o.height - 2) continue;
                    if (scene.visible_layer(p1.x, p1.y, newest) != front) continue;
                    glm::vec3 want = scene.layer_color(front, x + 0.5, y + 0.5, t);
                    glm::vec3 hidden = scene.layer_color(behind, x + 0.5, y + 0.5, t);
                    glm::vec3 got(g.frames[f].rgba[4 * i], g.frames[f].rgba[4 * i + 1],
                                  g.frames[f].rgba[4 * i + 2]);
                    if (glm::length(want - hidden) < 0.1f) continue; // indistinguishable here
                    ++n;
                    right += glm::length(got - want) < glm::length(got - hidden);
                }
        }
        ASSERT_GT(n, 500u) << "the scene must have overlaps";
        std::printf("[ measured ] %s: foreground at %zu of %zu overlap pixels\n",
                    extrap ? "extrapolation" : "interpolation", right, n);
        EXPECT_GT(double(right) / double(n), 0.98)
            << (extrap ? "extrapolation" : "interpolation") << ": " << right << "/" << n;
    }
}

// The warps' colour kernel (shaders/warp.h, Params::warp_kernel; docs/ACCURACY.md change 39). A
// band-limited pattern (three sinusoids per channel, at most 0.25 cycles a pixel: point samples of it
// are antialiased) translates by u = (3, 1) px a frame with exact vectors, so that interpolation at
// alpha 0.5 samples both inputs half a pixel off their grid, where bilinear sampling is a [1/2 1/2]
// low-pass per axis. The truth is the pattern at the generated instant, scored away from the
// frame's edges (content entering there is not the kernel's).
struct MovingPattern {
    uint32_t w = 160, h = 96;
    glm::vec2 u{3.f, 1.f};
    bool aliased = false; // a per-texel hash of 0.7 px texels, point-sampled: aliased input

    float value(glm::vec2 q, int c) const {
        if (aliased) {
            const glm::ivec2 t = glm::ivec2(glm::floor(q / 0.7f));
            uint32_t x = uint32_t(t.x) * 73856093u ^ uint32_t(t.y) * 19349663u ^ uint32_t(c + 1) * 83492791u;
            x ^= x >> 13;
            x *= 0x5bd1e995u;
            x ^= x >> 15;
            return 0.2f + 0.6f * float(x & 1023u) / 1023.f;
        }
        const float k = 6.2831853f, ph = float(c);
        return 0.5f + 0.18f * std::sin(k * (0.23f * q.x + 0.05f * q.y) + ph) +
               0.12f * std::sin(k * (0.07f * q.x - 0.21f * q.y) + 1.f + 2.f * ph) +
               0.08f * std::sin(k * (0.17f * q.x + 0.13f * q.y) + 2.f + ph);
    }
    std::vector<glm::vec4> colour(float t) const {
        std::vector<glm::vec4> c(size_t(w) * h);
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const glm::vec2 q = glm::vec2(float(x) + 0.5f, float(y) + 0.5f) - u * t;
                c[size_t(y) * w + x] = glm::vec4(value(q, 0), value(q, 1), value(q, 2), 1.f);
            }
        return c;
    }
    RawFrame frame(float t) const {
        return make_raw(colour(t), std::vector<float>(size_t(w) * h, 10.f),
                        t == 0.f ? std::vector<glm::vec2>{} : std::vector<glm::vec2>(size_t(w) * h, -u));
    }
    // PSNR of rgba32f pixels against the truth over the pixels at least 8 from the frame's edges.
    double interior_psnr(const std::vector<float>& got, const std::vector<glm::vec4>& truth) const {
        double se = 0;
        size_t count = 0;
        for (uint32_t y = 8; y + 8 < h; ++y)
            for (uint32_t x = 8; x + 8 < w; ++x)
                for (int k = 0; k < 3; ++k) {
                    const size_t i = size_t(y) * w + x;
                    const double d = double(got[4 * i + size_t(k)]) - double(truth[i][k]);
                    se += d * d;
                    ++count;
                }
        return 10.0 * std::log10(1.0 / std::max(se / double(count), 1e-12));
    }
};

struct WarpRun {
    std::vector<float> interp, extrap;
    float aliasing = -1.f;
    std::vector<glm::vec4> reference; // ref::generate of the interpolated frame, with the session's measure
};

// colour_only: a session without vectors and depth (motion estimated from colour).
WarpRun run_warp(const MovingPattern& scene, WarpKernel kernel, bool colour_only = false) {
    Params p = given_field();
    p.warp_kernel = kernel;
    WarpRun r;
    FrameFormat format = internal_format(scene.w, scene.h);
    format.has_vectors = format.has_depth = !colour_only;
    auto s = engine().create_session(format, p);
    EXPECT_TRUE(s);
    if (!s) return r;
    for (float t : {0.f, 1.f, 2.f}) {
        const RawFrame f = scene.frame(t);
        FrameView v = f.view();
        if (colour_only) v.depth = v.mv = {};
        EXPECT_TRUE((*s)->submit(v));
    }
    const float a[] = {0.5f};
    auto i = (*s)->interpolate(a);
    auto e = (*s)->extrapolate(a);
    EXPECT_TRUE(i && e);
    if (!i || !e) return r;
    r.interp = i->front().color.rgba;
    r.extrap = e->front().color.rgba;
    r.aliasing = (*s)->input_aliasing();
    auto f0 = (*s)->read_frame(0), f1 = (*s)->read_frame(1);
    EXPECT_TRUE(f0 && f1);
    if (f0 && f1 && !colour_only)
        r.reference = ref::generate(to_internal(*f0, scene.w, scene.h), to_internal(*f1, scene.w, scene.h),
                                    params::gen_params(internal_format(scene.w, scene.h), p, 0.5f, false,
                                                       true, true, params::input_measure(**s)));
    return r;
}

float largest_difference(const std::vector<float>& a, const std::vector<float>& b) {
    EXPECT_EQ(a.size(), b.size());
    float m = 0.f;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) m = std::max(m, std::abs(a[i] - b[i]));
    return m;
}

// On antialiased input the cubic keeps the detail bilinear sampling blurs, and automatic takes it in
// interpolation with the client's vectors only (not in extrapolation, nor with vectors estimated from
// colour); the engine's frame is the CPU reference's.
TEST(Warp, CubicKeepsTheDetailOfAntialiasedInputThatBilinearBlurs) {
    const MovingPattern scene;
    const WarpRun bil = run_warp(scene, WarpKernel::bilinear), cub = run_warp(scene, WarpKernel::cubic),
                  aut = run_warp(scene, WarpKernel::automatic);
    ASSERT_FALSE(aut.interp.empty());
    EXPECT_GE(aut.aliasing, 0.f);
    EXPECT_LT(aut.aliasing, defaults::antialiased_aliasing) << "the pattern is band-limited";
    const auto truth = scene.colour(1.5f);
    const double pb = scene.interior_psnr(bil.interp, truth), pc = scene.interior_psnr(cub.interp, truth);
    std::printf("[ measured ] band-limited pattern at half-pixel phases, interpolated: bilinear %.2f dB, "
                "cubic %.2f dB (input aliasing %.2f)\n",
                pb, pc, aut.aliasing);
    EXPECT_GT(pc, pb + 3.0);
    EXPECT_EQ(largest_difference(aut.interp, cub.interp), 0.f) << "automatic interpolates with the cubic";
    EXPECT_EQ(largest_difference(aut.extrap, bil.extrap), 0.f) << "automatic extrapolates with bilinear";
    const WarpRun colour_bil = run_warp(scene, WarpKernel::bilinear, true),
                  colour_aut = run_warp(scene, WarpKernel::automatic, true);
    ASSERT_FALSE(colour_aut.interp.empty());
    EXPECT_EQ(largest_difference(colour_aut.interp, colour_bil.interp), 0.f)
        << "automatic interpolates with bilinear where the vectors are estimated from colour";
    EXPECT_GT(largest_difference(cub.interp, bil.interp), 0.01f);
    std::vector<float> expected;
    for (const glm::vec4& c : aut.reference) expected.insert(expected.end(), {c.x, c.y, c.z, c.w});
    EXPECT_LT(largest_difference(aut.interp, expected), 1e-4f) << "against the CPU reference";
    expect_no_validation_errors();
}

// On aliased input (point samples of texels smaller than a pixel) automatic keeps bilinear sampling:
// the cubic would interpolate the aliasing (docs/ACCURACY.md change 39, the jittered SR captures).
TEST(Warp, AutomaticKeepsBilinearOnAliasedInput) {
    MovingPattern scene;
    scene.aliased = true;
    const WarpRun bil = run_warp(scene, WarpKernel::bilinear), cub = run_warp(scene, WarpKernel::cubic),
                  aut = run_warp(scene, WarpKernel::automatic);
    ASSERT_FALSE(aut.interp.empty());
    EXPECT_GE(aut.aliasing, defaults::antialiased_aliasing);
    EXPECT_EQ(largest_difference(aut.interp, bil.interp), 0.f);
    EXPECT_GT(largest_difference(cub.interp, bil.interp), 0.01f);
    expect_no_validation_errors();
}

// The cubic is clamped to the range of its inner 2x2 taps: a highlight (400 in linear colour, one
// pixel, on 0.02) moving a pixel a frame casts no negative lobes. Without the clamp the Catmull-Rom
// weight of a tap 1.5 pixels away at phase 1/2 is -1/16, which would put 0.02 - 400/16 < 0 there.
TEST(Warp, CubicCastsNoRingingAroundAHighlight) {
    const uint32_t w = 64, h = 32;
    const float background = 0.02f, peak = 400.f;
    auto frame = [&](int t) {
        std::vector<glm::vec4> c(size_t(w) * h, glm::vec4(background, background, background, 1.f));
        c[size_t(16) * w + 20 + uint32_t(t)] = glm::vec4(peak, peak, peak, 1.f);
        return make_raw(c, std::vector<float>(size_t(w) * h, 10.f),
                        t == 0 ? std::vector<glm::vec2>{}
                               : std::vector<glm::vec2>(size_t(w) * h, glm::vec2(-1.f, 0.f)));
    };
    // Keys' cubic convolution kernel with a = -0.5 (Catmull-Rom) at 1 < |x| < 2.
    const float a = -0.5f, x = 1.5f, outer = a * x * x * x - 5.f * a * x * x + 8.f * a * x - 4.f * a;
    ASSERT_LT(background + peak * outer, 0.f) << "the unclamped cubic rings below zero";
    Params p = given_field();
    p.warp_kernel = WarpKernel::cubic;
    auto s = engine().create_session(internal_format(w, h), p);
    ASSERT_TRUE(s);
    for (int t : {0, 1, 2}) ASSERT_TRUE((*s)->submit(frame(t).view()));
    const float alpha[] = {0.5f};
    auto r = (*s)->interpolate(alpha);
    ASSERT_TRUE(r) << r.error().message;
    const std::vector<float>& c = r->front().color.rgba;
    float lowest = 1e9f, highest = 0.f;
    for (size_t i = 0; i < c.size(); i += 4)
        for (int k = 0; k < 3; ++k) {
            lowest = std::min(lowest, c[i + size_t(k)]);
            highest = std::max(highest, c[i + size_t(k)]);
        }
    EXPECT_GE(lowest, background - 1e-4f);
    EXPECT_GT(highest, 0.25f * peak) << "the highlight is kept";
    EXPECT_LE(highest, peak);
    expect_no_validation_errors();
}

} // namespace
} // namespace fgsr::test
