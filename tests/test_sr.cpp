// Super resolution on analytic scenes: jittered point-sampled low-resolution frames of the
// synthetic scene (sampled exactly at pixel centre + jitter) against its antialiased
// high-resolution rendering, plus the `sr` pass against its CPU reference.
#include "engine_fixture.hpp"

#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/lut.hpp>

#include <cmath>

namespace fgsr::test {
namespace {

using capture::SceneOptions;
using capture::SyntheticScene;

// Halton radical inverse.
float halton(uint32_t i, uint32_t base) {
    float f = 1.f, r = 0.f;
    for (; i > 0; i /= base) {
        f /= float(base);
        r += f * float(i % base);
    }
    return r;
}

glm::vec2 halton_jitter(uint32_t frame) {
    return glm::vec2(halton(frame % 16 + 1, 2) - 0.5f, halton(frame % 16 + 1, 3) - 0.5f);
}

// The scene at time t seen by a w x h camera whose pixels each take one sample at centre + jitter
// (in pixels of that camera); vectors towards t_prev for the same surface points.
RawFrame point_sampled(const SyntheticScene& scene, uint32_t w, uint32_t h, double t, double t_prev, glm::vec2 jitter) {
    const SceneOptions& o = scene.options();
    const double sx = double(o.width) / w, sy = double(o.height) / h;
    std::vector<glm::vec4> c(size_t(w) * h);
    std::vector<float> d(size_t(w) * h);
    std::vector<glm::vec2> m(size_t(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const double px = (x + 0.5 + jitter.x) * sx, py = (y + 0.5 + jitter.y) * sy;
            const size_t l = scene.visible_layer(px, py, t), i = size_t(y) * w + x;
            c[i] = glm::vec4(scene.layer_color(l, px, py, t), 1.f);
            d[i] = scene.layer_depth(l);
            glm::dvec2 mv = scene.layer_position(l, t_prev) - scene.layer_position(l, t);
            m[i] = glm::vec2(float(mv.x / sx), float(mv.y / sy));
        }
    RawFrame f = make_raw(c, d, m);
    return f;
}

struct SrRun {
    std::vector<double> psnr; // per frame, against the antialiased high-resolution truth
    std::vector<ImageRGBA> frames;
};

SrRun run_sr(const SyntheticScene& hr_scene, uint32_t lr_w, uint32_t lr_h, float scale, int frames, Params p,
             bool moving, int reset_at = -1) {
    p.scale = scale;
    auto s = engine().create_session(internal_format(lr_w, lr_h), p);
    EXPECT_TRUE(s) << s.error().message;
    SrRun r;
    for (int k = 0; k < frames; ++k) {
        const double t = moving ? k : 0.0;
        const glm::vec2 j = halton_jitter(uint32_t(k));
        RawFrame f = point_sampled(hr_scene, lr_w, lr_h, t, moving ? t - 1 : 0.0, j);
        FrameView v = f.view();
        v.jitter_x = j.x;
        v.jitter_y = j.y;
        v.reset = k == reset_at;
        EXPECT_TRUE((*s)->submit(v));
        auto out = (*s)->super_resolved();
        EXPECT_TRUE(out) << out.error().message;
        EXPECT_EQ(out->color.width, (*s)->output_width());
        r.psnr.push_back(*capture::psnr(out->color, hr_scene.render_color(t)));
        r.frames.push_back(std::move(out->color));
    }
    return r;
}

SceneOptions hr_options(uint32_t w, uint32_t h, float speed) {
    SceneOptions o;
    o.width = w;
    o.height = h;
    o.speed = speed;
    o.supersample = 4;
    return o;
}

TEST(Sr, StaticJitteredContentConverges) {
    SyntheticScene scene(hr_options(320, 180, 0.f));
    for (float a : {0.34f, 0.15f}) for (float b : {0.81f, 1.0f}) {
        Params q; q.sr_a = a; q.sr_b = b;
        SrRun e = run_sr(scene, 160, 90, 2.f, 16, q, false);
        std::printf("a %.2f b %.2f: %.2f -> %.2f\n", a, b, e.psnr.front(), e.psnr.back());
    }
    SrRun r = run_sr(scene, 160, 90, 2.f, 16, Params{}, false);
    std::printf("[ measured ] static 2x: first frame %.2f dB, frame 8 %.2f dB, last %.2f dB\n", r.psnr.front(), r.psnr[7],
                r.psnr.back());
    EXPECT_GT(r.psnr.back(), r.psnr.front() + 3.0) << "accumulating jittered samples must beat the spatial upsample";
}

} // namespace
} // namespace fgsr::test
