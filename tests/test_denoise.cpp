// The `denoise` pass of SR sessions (shaders/denoise.h): the noise estimate against the known
// noise of generated images, the identity on clean input, the pass against its CPU reference, and
// parameter validation. Its effect on super resolution is in test_sr.cpp (NoisyInput*).
#include "engine_fixture.hpp"

#include <cmath>
#include <random>

namespace fgsr::test {
namespace {

// Piecewise-smooth content with sharp edges (a gradient, rectangles and a disc), plus grey
// Gaussian noise of standard deviation `sigma` (the same on R, G and B, so the luminance noise is
// sigma too), clamped to >= 0 as ingest would.
RawFrame edged_frame(uint32_t w, uint32_t h, float sigma, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.f, 1.f);
    std::vector<glm::vec4> c(size_t(w) * h);
    std::vector<float> d(size_t(w) * h, 10.f);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            glm::vec3 v(0.3f + 0.4f * float(x) / float(w), 0.5f, 0.6f - 0.3f * float(y) / float(h));
            if ((x / 12 + y / 10) % 3 == 0) v = glm::vec3(0.9f, 0.2f, 0.1f);
            const float dx = float(x) - 0.6f * float(w), dy = float(y) - 0.5f * float(h);
            if (dx * dx + dy * dy < 0.04f * float(w * w)) v = glm::vec3(0.05f, 0.7f, 0.3f);
            const float n = sigma * noise(rng);
            c[size_t(y) * w + x] = glm::vec4(glm::max(v + glm::vec3(n), glm::vec3(0.f)), 1.f);
        }
    return make_raw(c, d, std::vector<glm::vec2>(size_t(w) * h, glm::vec2(0.f)));
}

// gamma: Params::denoise_gamma; 0 measures the noise in linear units, which the additive noise of
// edged_frame has.
Params sr_params(bool denoise = true, float gamma = 0.f) {
    Params p;
    p.scale = 2.f;
    p.denoise = denoise;
    p.denoise_gamma = gamma;
    return p;
}

// Content whose noise scales with its light, as a texture point-sampled below its detail does:
// vertical stripes of grey brightness levels[i] (each `stripe` pixels wide, in turn), times
// (1 + k n) with n standard normal. clean: the same without noise.
RawFrame lit_frame(uint32_t w, uint32_t h, const std::vector<float>& levels, uint32_t stripe, float k,
                   uint32_t seed, std::vector<float>* clean = nullptr) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.f, 1.f);
    std::vector<glm::vec4> c(size_t(w) * h);
    if (clean) clean->assign(size_t(w) * h, 0.f);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float v = levels[(x / stripe) % levels.size()];
            const float n = std::max(v * (1.f + k * noise(rng)), 0.f);
            c[size_t(y) * w + x] = glm::vec4(n, n, n, 1.f);
            if (clean) (*clean)[size_t(y) * w + x] = v;
        }
    return make_raw(c, std::vector<float>(size_t(w) * h, 10.f),
                    std::vector<glm::vec2>(size_t(w) * h, glm::vec2(0.f)));
}

TEST(Denoise, EstimatesTheNoiseOfGeneratedImages) {
    const uint32_t w = 160, h = 96;
    for (float sigma : {0.04f, 0.08f, 0.2f}) {
        auto s = engine().create_session(internal_format(w, h), sr_params());
        ASSERT_TRUE(s) << s.error().message;
        const RawFrame f = edged_frame(w, h, sigma, 7);
        ASSERT_TRUE((*s)->submit(f.view()));
        const NoiseEstimate e = (*s)->last_noise_estimate();
        std::printf("[ measured ] noise sigma %.3f: estimated %.4f, filter range %.4f\n", sigma, e.sigma,
                    e.range);
        // Bins are 9 % wide and the edges add a little: within 15 %.
        EXPECT_NEAR(e.sigma, sigma, 0.15f * sigma);
        const Params p = sr_params();
        const float above = std::sqrt(std::max(e.sigma * e.sigma - p.noise_floor * p.noise_floor, 0.f));
        EXPECT_NEAR(e.range, p.denoise_strength * above, 1e-6f);
        EXPECT_GT(e.range, 0.f);
    }
    expect_no_validation_errors();
}

// With gamma 1 noise that scales with the light is measured as the fraction of the brightness it
// is, whatever the brightness levels in the frame.
TEST(Denoise, EstimatesNoiseRelativeToTheBrightness) {
    const uint32_t w = 160, h = 96;
    for (float k : {0.05f, 0.1f, 0.2f}) {
        auto s = engine().create_session(internal_format(w, h), sr_params(true, 1.f));
        ASSERT_TRUE(s) << s.error().message;
        const RawFrame f = lit_frame(w, h, {0.08f, 0.3f, 1.2f}, 20, k, 11);
        ASSERT_TRUE((*s)->submit(f.view()));
        const NoiseEstimate e = (*s)->last_noise_estimate();
        std::printf("[ measured ] relative noise %.3f: estimated %.4f\n", k, e.sigma);
        // The 3x3 mean carries its own noise (k / 3) and the stripes' edges add a little: 15 %.
        EXPECT_NEAR(e.sigma, k, 0.15f * k);
    }
    expect_no_validation_errors();
}

// A frame mostly in shade with a sunlit part, the same relative noise in both: the absolute estimate
// follows the shade (the median) and leaves the sunlit part's noise, the relative one filters both.
// Scored against the clean frame.
TEST(Denoise, FiltersSunlitAndShadedPartsAlike) {
    const uint32_t w = 160, h = 96, stripe = 40; // 3 of 4 stripes shaded
    std::vector<float> clean;
    const RawFrame f = lit_frame(w, h, {0.05f, 0.05f, 0.05f, 1.f}, stripe, 0.15f, 5, &clean);
    const ref::InternalFrame in = ref::ingest(internal_format(w, h), f.view());
    // Residual RMS error over the input's, per part (shaded, sunlit), interior pixels only.
    auto residual = [&](float gamma) {
        auto s = engine().create_session(internal_format(w, h), sr_params(true, gamma));
        EXPECT_TRUE(s);
        EXPECT_TRUE((*s)->submit(f.view()));
        auto got = (*s)->read_frame(1);
        EXPECT_TRUE(got);
        double before[2] = {0, 0}, after[2] = {0, 0};
        for (uint32_t y = 1; y + 1 < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                if (x % stripe < 2 || x % stripe >= stripe - 2) continue; // stripe edges
                const size_t i = size_t(y) * w + x;
                const int part = clean[i] > 0.5f ? 1 : 0;
                before[part] += std::pow(in.color[i].x - clean[i], 2.0);
                after[part] += std::pow(got->color[4 * i] - clean[i], 2.0);
            }
        return std::pair{std::sqrt(after[0] / before[0]), std::sqrt(after[1] / before[1])};
    };
    const auto [shade_abs, sun_abs] = residual(0.f);
    EXPECT_GT(sun_abs, 0.9) << "the absolute level barely touches the sunlit part";
    // gamma 1 (noise as a fraction of the light) and the default both filter both parts.
    for (float gamma : {1.f, Params{}.denoise_gamma}) {
        const auto [shade, sun] = residual(gamma);
        std::printf("[ measured ] residual noise, shaded / sunlit: absolute %.3f / %.3f, "
                    "gamma %.2f %.3f / %.3f\n",
                    shade_abs, sun_abs, gamma, shade, sun);
        EXPECT_LT(sun, 0.75) << "gamma " << gamma;
        EXPECT_LT(shade, 0.75) << "gamma " << gamma;
    }
    expect_no_validation_errors();
}

// Clean content (sharp edges, gradients) estimates at most the floor, and the frame the SR pass
// reads and the SR output are bit-identical to a session without the pass.
TEST(Denoise, CleanInputPassesUnchanged) {
    const uint32_t w = 96, h = 64;
    for (float gamma : {0.f, Params{}.denoise_gamma}) {
        auto on = engine().create_session(internal_format(w, h), sr_params(true, gamma));
        auto off = engine().create_session(internal_format(w, h), sr_params(false));
        ASSERT_TRUE(on && off);
        for (uint32_t k = 0; k < 3; ++k) {
            RawFrame f = edged_frame(w, h, 0.f, k);
            FrameView v = f.view();
            v.jitter_x = 0.25f * float(k) - 0.25f;
            ASSERT_TRUE((*on)->submit(v));
            ASSERT_TRUE((*off)->submit(v));
            const NoiseEstimate e = (*on)->last_noise_estimate();
            EXPECT_LE(e.sigma, Params{}.noise_floor);
            EXPECT_EQ(e.range, 0.f);
            EXPECT_EQ((*off)->last_noise_estimate().sigma, 0.f) << "no estimate without the pass";
            auto a = (*on)->read_frame(1), b = (*off)->read_frame(1);
            ASSERT_TRUE(a && b);
            EXPECT_EQ(a->color, b->color);
            auto oa = (*on)->super_resolved(), ob = (*off)->super_resolved();
            ASSERT_TRUE(oa && ob);
            EXPECT_EQ(oa->color.rgba, ob->color.rgba);
            ASSERT_FALSE(oa->passes.empty());
            EXPECT_EQ(oa->passes.front().name, "denoise");
            for (const PassTiming& t : ob->passes) EXPECT_NE(t.name, "denoise");
        }
    }
    expect_no_validation_errors();
}

// Params::denoise can be turned on and off on a live SR session (set_params).
TEST(Denoise, CanBeToggledOnALiveSession) {
    const uint32_t w = 64, h = 40;
    auto s = engine().create_session(internal_format(w, h), sr_params(false));
    ASSERT_TRUE(s);
    const RawFrame f = edged_frame(w, h, 0.1f, 9);
    ASSERT_TRUE((*s)->submit(f.view()));
    EXPECT_EQ((*s)->last_noise_estimate().sigma, 0.f);
    (*s)->set_params(sr_params(true));
    ASSERT_TRUE((*s)->params().denoise);
    ASSERT_TRUE((*s)->submit(f.view()));
    EXPECT_NEAR((*s)->last_noise_estimate().sigma, 0.1f, 0.015f);
    auto out = (*s)->super_resolved();
    ASSERT_TRUE(out);
    EXPECT_EQ(out->passes.front().name, "denoise");
    (*s)->set_params(sr_params(false));
    ASSERT_TRUE((*s)->submit(f.view()));
    EXPECT_EQ((*s)->last_noise_estimate().sigma, 0.f);
    expect_no_validation_errors();
}

TEST(Denoise, PassMatchesReference) {
    for (float gamma : {0.f, Params{}.denoise_gamma})
        for (auto [w, h] : {std::pair{64u, 40u}, std::pair{17u, 9u}, std::pair{33u, 3u}}) {
            auto s = engine().create_session(internal_format(w, h), sr_params(true, gamma));
            ASSERT_TRUE(s);
            const RawFrame f = edged_frame(w, h, 0.08f, w);
            ASSERT_TRUE((*s)->submit(f.view()));
            const ref::InternalFrame in = ref::ingest(internal_format(w, h), f.view());
            const ref::DenoiseParams dp =
                params::denoise_params(internal_format(w, h), sr_params(true, gamma));
            const NoiseEstimate cpu = ref::noise_level(in, dp);
            const NoiseEstimate gpu = (*s)->last_noise_estimate();
            // Same histogram up to log2 rounding at bin edges: the same or the adjacent bin.
            EXPECT_LE(std::abs(std::log2(gpu.sigma / cpu.sigma)), 0.126f)
                << w << "x" << h << " gamma " << gamma;
            // The filter with the range the GPU used.
            const std::vector<glm::vec4> expect = ref::denoise(in, dp, gpu.range);
            auto got = (*s)->read_frame(1);
            ASSERT_TRUE(got);
            double err = 0;
            for (size_t i = 0; i < expect.size(); ++i)
                for (int k = 0; k < 4; ++k)
                    err = std::max(err, double(std::abs(expect[i][k] - got->color[4 * i + size_t(k)])) /
                                            std::max(1.0, double(std::abs(expect[i][k]))));
            EXPECT_LT(err, 2e-3) << w << "x" << h << " (half rounding of a few-ulp float difference)";
            // The filter did something: the output is not the input.
            double moved = 0;
            for (size_t i = 0; i < expect.size(); ++i) moved += std::abs(expect[i].x - in.color[i].x);
            EXPECT_GT(moved, 0.0);
        }
    expect_no_validation_errors();
}

// Sizes without an interior 2x2 block estimate no noise and leave the frame as it is.
TEST(Denoise, TinyFramesEstimateNothing) {
    for (auto [w, h] : {std::pair{1u, 1u}, std::pair{2u, 2u}, std::pair{1u, 40u}, std::pair{40u, 2u}}) {
        auto s = engine().create_session(internal_format(w, h), sr_params());
        ASSERT_TRUE(s);
        const RawFrame f = edged_frame(w, h, 0.2f, 3);
        ASSERT_TRUE((*s)->submit(f.view()));
        EXPECT_EQ((*s)->last_noise_estimate().sigma, 0.f) << w << "x" << h;
        const ref::InternalFrame in = ref::ingest(internal_format(w, h), f.view());
        auto got = (*s)->read_frame(1);
        ASSERT_TRUE(got);
        for (size_t i = 0; i < in.color.size(); ++i) EXPECT_EQ(got->color[4 * i], in.color[i].x);
    }
    expect_no_validation_errors();
}

TEST(Denoise, ParametersAreValidated) {
    // Each value of `field` in `bad` is refused with an error naming the field.
    auto refused = [](const char* name, float Params::*field, std::initializer_list<float> bad) {
        for (float v : bad) {
            Params p = sr_params();
            p.*field = v;
            auto r = validate(p);
            ASSERT_FALSE(r) << name << " " << v;
            EXPECT_NE(r.error().message.find(name), std::string::npos);
        }
    };
    refused("denoise_strength", &Params::denoise_strength, {-1.f, 65.f, std::nanf("")});
    refused("noise_floor", &Params::noise_floor, {-0.1f, INFINITY, std::nanf("")});
    refused("denoise_gamma", &Params::denoise_gamma, {-0.5f, 2.5f, std::nanf("")});
    Params p = sr_params();
    p.denoise_strength = 0.f; // estimate only
    EXPECT_TRUE(validate(p));
}

} // namespace
} // namespace fgsr::test
