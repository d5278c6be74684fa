// Every pass on the GPU against the CPU reference (the same algorithm header compiled with GLM),
// pass by pass: each CPU pass is fed exactly what the GPU pass read, so a difference cannot
// cascade. Tolerances: ingest and vectors 1e-4 relative (GPU math may fuse multiply-adds and use
// its own pow); splat keys and field states must agree on at least 99.9% of pixels (a position
// that lands exactly on a pixel border may round either way under fused arithmetic).
#include "engine_fixture.hpp"

#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/params.hpp>

#include <cmath>

namespace fgsr::test {
namespace {

struct PassCase {
    uint32_t width, height;
    bool extrapolate;
    MotionModel motion;
    float alpha;
    float range; // vector magnitude in pixels
    ColorFormat color_format;
    MvFormat mv_format;
    bool structured = false; // frames of the analytic scene (edges, occlusion, thin bars) instead of random
    bool depth_motion = false; // Params::accel_depth_motion (docs/ACCURACY.md, changes 21, 23)
};

std::string case_name(const testing::TestParamInfo<PassCase>& info) {
    const PassCase& c = info.param;
    return std::to_string(c.width) + "x" + std::to_string(c.height) +
           (c.extrapolate ? "_extrap" : "_interp") +
           (c.motion == MotionModel::quadratic ? "_quadratic" : "_linear") + "_a" +
           std::to_string(int(std::lround(c.alpha * 100))) + "_r" + std::to_string(int(c.range)) + "_" +
           std::string(to_string(c.color_format)) + "_" + std::string(to_string(c.mv_format)) +
           (c.structured ? "_scene" : "_random") + (c.depth_motion ? "_depthmotion" : "");
}

// Converts internal-convention planes to the case's client formats (so ingest is exercised too).
RawFrame to_client(const RawFrame& f, const PassCase& c, size_t n) {
    RawFrame out;
    out.depth = f.depth;
    const float* col = reinterpret_cast<const float*>(f.color.data());
    if (c.color_format == ColorFormat::rgba32f_linear) {
        out.color = f.color;
    } else if (c.color_format == ColorFormat::rgba16f_linear) {
        std::vector<uint32_t> w(n * 2);
        for (size_t i = 0; i < n; ++i) {
            w[2 * i] = glm::packHalf2x16(glm::vec2(col[4 * i], col[4 * i + 1]));
            w[2 * i + 1] = glm::packHalf2x16(glm::vec2(col[4 * i + 2], col[4 * i + 3]));
        }
        out.color = bytes_of(w);
    } else {
        std::vector<uint32_t> w(n);
        for (size_t i = 0; i < n; ++i)
            w[i] = glm::packUnorm4x8(glm::vec4(col[4 * i], col[4 * i + 1], col[4 * i + 2], col[4 * i + 3]));
        out.color = bytes_of(w);
    }
    if (!f.mv.empty()) {
        const float* m = reinterpret_cast<const float*>(f.mv.data());
        if (c.mv_format == MvFormat::rg32f) {
            out.mv = f.mv;
        } else {
            std::vector<uint32_t> w(n);
            for (size_t i = 0; i < n; ++i) w[i] = glm::packHalf2x16(glm::vec2(m[2 * i], m[2 * i + 1]));
            out.mv = bytes_of(w);
        }
    }
    return out;
}

double max_rel(float a, float b) {
    return std::abs(a - b) / std::max(1.0, double(std::max(std::abs(a), std::abs(b))));
}

class PassesMatchReference : public testing::TestWithParam<PassCase> {};

TEST_P(PassesMatchReference, EveryPass) {
    const PassCase c = GetParam();
    const size_t n = size_t(c.width) * c.height;
    FrameFormat fmt = internal_format(c.width, c.height);
    fmt.color_format = c.color_format;
    fmt.mv_format = c.mv_format;
    Params params = given_field();
    params.motion = c.motion;
    params.accel_depth_motion = c.depth_motion;
    params.fill_holes = false;
    params.separate_passes = true;
    auto s = engine().create_session(fmt, params);
    ASSERT_TRUE(s) << s.error().message;
    Session& session = **s;

    auto frame_at = [&](int t) {
        if (!c.structured) return random_frame(c.width, c.height, 10 + uint32_t(t), c.range);
        capture::SceneOptions o;
        o.width = c.width;
        o.height = c.height;
        o.speed = c.range / 10.f;
        auto smp = capture::SyntheticScene(o).render(t + 3, t + 2);
        const auto* px = reinterpret_cast<const glm::vec4*>(smp.color.rgba.data());
        return make_raw(std::vector<glm::vec4>(px, px + n), smp.depth, smp.mv);
    };
    RawFrame raw0 = to_client(frame_at(1), c, n);
    RawFrame raw1 = to_client(frame_at(2), c, n);
    ASSERT_TRUE(session.submit(raw0.view()));
    ASSERT_TRUE(session.submit(raw1.view()));

    // ingest
    auto g0 = session.read_frame(0);
    auto g1 = session.read_frame(1);
    ASSERT_TRUE(g0 && g1);
    ref::InternalFrame f0 = to_internal(*g0, c.width, c.height), f1 = to_internal(*g1, c.width, c.height);
    ref::InternalFrame c0 = ref::ingest(fmt, raw0.view()), c1 = ref::ingest(fmt, raw1.view());
    // With the dilate stage as the session runs it: frame 0 without a previous frame, frame 1 after it.
    gpu::IngestParams ip0 = params::ingest_params(fmt, c0.has_mv), ip1 = params::ingest_params(fmt, c1.has_mv);
    params::set_dilate(ip0, fmt, params, false);
    params::set_dilate(ip1, fmt, params, true);
    ref::dilate(c1, &c0, ip1); // reads frame 0's colour, which dilation leaves as it is
    ref::dilate(c0, nullptr, ip0);
    double ingest_err = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 4; ++k)
            ingest_err = std::max(ingest_err, max_rel(f1.color[i][k], c1.color[i][k]));
        ingest_err = std::max(ingest_err, max_rel(f1.depth[i], c1.depth[i]));
        for (int k = 0; k < 2; ++k) ingest_err = std::max(ingest_err, max_rel(f1.mv[i][k], c1.mv[i][k]));
        for (int k = 0; k < 4; ++k)
            ingest_err = std::max(ingest_err, max_rel(f0.color[i][k], c0.color[i][k]));
    }
    EXPECT_LT(ingest_err, 1e-4) << "ingest";

    // splat and refine, disocc skipped
    std::vector<float> alphas{c.alpha};
    auto out_pre = c.extrapolate ? session.extrapolate(alphas) : session.interpolate(alphas);
    ASSERT_TRUE(out_pre) << out_pre.error().message;
    auto pre = session.read_intermediates();
    ASSERT_TRUE(pre);
    ref::GenParams g =
        params::gen_params(fmt, params, c.alpha, c.extrapolate, true, true, params::input_measure(session));
    ref::Splat sp = ref::splat(f0, f1, g);
    size_t key_diff = 0, occupied = 0;
    double motion_err = 0;
    for (size_t i = 0; i < n; ++i) {
        key_diff += sp.keys[i] != pre->keys[i];
        for (int k = 0; k < 4; ++k)
            motion_err = std::max(motion_err, max_rel(sp.motion[i][k], pre->motion[4 * i + size_t(k)]));
        occupied += (pre->keys[i] & 0xffffffffull) != 0xffffffffull;
    }
    EXPECT_LE(key_diff, n / 1000) << "splat keys differ on " << key_diff << " of " << n << " pixels";
    EXPECT_LT(motion_err, 1e-4) << "splat motion";
    // Later passes run on exactly what the GPU splat produced.
    ref::Splat gpu_splat{pre->keys, std::vector<glm::vec4>(n)};
    std::memcpy(gpu_splat.motion.data(), pre->motion.data(), n * 16);
    if (n >= 64) {
        EXPECT_GT(occupied, n / 4) << "the case must exercise splatting";
    }

    ref::Field field = ref::refine(f0, f1, gpu_splat, g);
    size_t state_diff = 0, gaps = 0, holes = 0;
    double field_err = 0;
    for (size_t i = 0; i < n; ++i) {
        state_diff += field.state[i] != pre->field_state[i];
        gaps += pre->field_state[i] == ref::kFieldGapFilled;
        holes += pre->field_state[i] == ref::kFieldHole;
        if (field.state[i] == pre->field_state[i]) {
            for (int k = 0; k < 4; ++k)
                field_err = std::max(field_err, max_rel(field.v[i][k], pre->field[4 * i + size_t(k)]));
            field_err = std::max(field_err, max_rel(field.depth[i], pre->field_depth[i]));
        }
    }
    EXPECT_LE(state_diff, n / 1000) << "refine states differ on " << state_diff << " pixels";
    EXPECT_LT(field_err, 1e-4) << "refine vectors";
    if (n >= 64) {
        EXPECT_GT(gaps + holes, 0u) << "the case must exercise gap filling or holes";
    }

    // disocc, warp, blend on the GPU's own refine output
    ref::Field gpu_field;
    gpu_field.v.resize(n);
    std::memcpy(gpu_field.v.data(), pre->field.data(), n * 16);
    gpu_field.depth = pre->field_depth;
    gpu_field.state = pre->field_state;

    params.fill_holes = true;
    session.set_params(params);
    g = params::gen_params(fmt, params, c.alpha, c.extrapolate, true, true, params::input_measure(session));
    auto out = c.extrapolate ? session.extrapolate(alphas) : session.interpolate(alphas);
    ASSERT_TRUE(out) << out.error().message;
    auto post = session.read_intermediates();
    ASSERT_TRUE(post);
    ref::disocc(f0, f1, gpu_splat, gpu_field, g);
    double disocc_err = 0;
    size_t disocc_diff = 0;
    for (size_t i = 0; i < n; ++i) {
        disocc_diff += gpu_field.state[i] != post->field_state[i];
        for (int k = 0; k < 4; ++k)
            disocc_err = std::max(disocc_err, max_rel(gpu_field.v[i][k], post->field[4 * i + size_t(k)]));
    }
    EXPECT_EQ(disocc_diff, 0u) << "disocc states";
    EXPECT_LT(disocc_err, 1e-4) << "disocc vectors";

    ref::Field post_field;
    post_field.v.resize(n);
    std::memcpy(post_field.v.data(), post->field.data(), n * 16);
    post_field.depth = post->field_depth;
    post_field.state = post->field_state;
    ref::Warped warped = ref::warp(f0, f1, post_field, g);
    double warp_err = 0;
    size_t depth_diff = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 4; ++k) {
            warp_err =
                std::max(warp_err, max_rel(warped.color[n + i][k], post->warped_color1[4 * i + size_t(k)]));
            if (!c.extrapolate)
                warp_err =
                    std::max(warp_err, max_rel(warped.color[i][k], post->warped_color0[4 * i + size_t(k)]));
        }
        depth_diff += warped.depth[n + i] != post->warped_depth1[i];
        if (!c.extrapolate) depth_diff += warped.depth[i] != post->warped_depth0[i];
    }
    EXPECT_LT(warp_err, 1e-4) << "warp colour";
    EXPECT_LE(depth_diff, n / 1000) << "warp depth (nearest pixel) differs on " << depth_diff << " pixels";

    if (!c.extrapolate) {
        std::vector<glm::vec4> blended = ref::blend(f0, f1, warped_of(*post), post_field, g);
        double blend_err = 0;
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < 4; ++k)
                blend_err =
                    std::max(blend_err, max_rel(blended[i][k], (*out)[0].color.rgba[4 * i + size_t(k)]));
        EXPECT_LT(blend_err, 1e-4) << "blend";
    } else {
        double out_err = 0;
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < 4; ++k)
                out_err = std::max(out_err,
                                   max_rel(warped.color[n + i][k], (*out)[0].color.rgba[4 * i + size_t(k)]));
        EXPECT_LT(out_err, 1e-4) << "extrapolated output";
    }

    // The fused pass: against the CPU reference on the GPU's keys, and against the separate passes.
    params.separate_passes = false;
    params.skip_tiles = false; // the fused pass over every tile (tests/test_tiles.cpp covers skipping)
    session.set_params(params);
    auto fused = c.extrapolate ? session.extrapolate(alphas) : session.interpolate(alphas);
    ASSERT_TRUE(fused) << fused.error().message;
    auto fk = session.read_intermediates();
    ASSERT_TRUE(fk);
    ref::Splat fused_splat{fk->keys, std::vector<glm::vec4>(n)};
    std::memcpy(fused_splat.motion.data(), fk->motion.data(), n * 16);
    std::vector<glm::vec4> fused_ref = ref::generate_fused(f0, f1, fused_splat, g);
    double fused_err = 0, chain_err = 0;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 4; ++k) {
            const float got = (*fused)[0].color.rgba[4 * i + size_t(k)];
            fused_err = std::max(fused_err, max_rel(fused_ref[i][k], got));
            chain_err = std::max(chain_err, max_rel((*out)[0].color.rgba[4 * i + size_t(k)], got));
        }
    EXPECT_LT(fused_err, 1e-4) << "fused pass vs CPU reference";
    EXPECT_LT(chain_err, 1e-4) << "fused pass vs separate passes";
    EXPECT_EQ((*fused)[0].passes.size(), 2u);
    expect_no_validation_errors();
}

INSTANTIATE_TEST_SUITE_P(Random, PassesMatchReference,
                         testing::Values(PassCase{64, 48, false, MotionModel::quadratic, 0.5f, 6.f,
                                                  ColorFormat::rgba32f_linear, MvFormat::rg32f},
                                         PassCase{64, 48, false, MotionModel::linear, 0.25f, 6.f,
                                                  ColorFormat::rgba16f_linear, MvFormat::rg16f},
                                         PassCase{61, 37, true, MotionModel::quadratic, 0.5f, 8.f,
                                                  ColorFormat::rgba8_srgb, MvFormat::rg32f},
                                         PassCase{61, 37, true, MotionModel::linear, 1.0f, 8.f,
                                                  ColorFormat::rgba32f_linear, MvFormat::rg16f},
                                         PassCase{200, 120, false, MotionModel::quadratic, 0.8f, 30.f,
                                                  ColorFormat::rgba8_srgb, MvFormat::rg16f},
                                         PassCase{1, 1, false, MotionModel::quadratic, 0.5f, 2.f,
                                                  ColorFormat::rgba32f_linear, MvFormat::rg32f},
                                         PassCase{240, 135, false, MotionModel::quadratic, 0.5f, 10.f,
                                                  ColorFormat::rgba16f_linear, MvFormat::rg32f, true},
                                         PassCase{240, 135, true, MotionModel::quadratic, 0.7f, 20.f,
                                                  ColorFormat::rgba8_srgb, MvFormat::rg16f, true},
                                         PassCase{64, 48, false, MotionModel::quadratic, 0.5f, 6.f,
                                                  ColorFormat::rgba32f_linear, MvFormat::rg32f, false, true},
                                         PassCase{240, 135, true, MotionModel::quadratic, 0.7f, 20.f,
                                                  ColorFormat::rgba8_srgb, MvFormat::rg16f, true, true}),
                         case_name);

} // namespace
} // namespace fgsr::test
