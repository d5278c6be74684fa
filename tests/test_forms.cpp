// The two forms of the passes (DeviceOptions::workgroup): CPU devices run the 32x32 builds and
// their CPU forms (generate in two passes, over the tile lists too; generate_sr from the field
// written once per input pixel; classify and ingest several pixels per invocation), GPUs the 8x8
// builds and the one-pass forms. Both are the same functions of the same values, so on the same
// inputs they must give the same frames; here both run on the test device (lavapipe), so that the
// GPU forms are checked without a GPU. Tolerance: per channel |a - b| <= 1e-5 * max(1, |b|), the
// separately compiled forms may round differently (a few ulps).
#include "engine_fixture.hpp"

#include <algorithm>
#include <cmath>

namespace fgsr::test {
namespace {

constexpr float kRelTolerance = 1e-5f;

std::unique_ptr<Engine> engine_of_group(uint32_t group) {
    DeviceOptions o;
    o.workgroup = group;
    auto r = Engine::create(o);
    if (!r) {
        ADD_FAILURE() << "workgroup " << group << ": " << r.error().message;
        std::abort();
    }
    return std::move(*r);
}

// Each engine is created in its static's initialiser, so that its destruction at exit is
// registered after the Vulkan layers it loads and runs before their globals go: a static created
// empty and filled later was destroyed after them, and the validation layer crashed in
// vkDestroyPipeline at exit.
Engine& engine_with_group(uint32_t group) {
    if (group == 8) {
        static const std::unique_ptr<Engine> e8 = engine_of_group(8);
        return *e8;
    }
    static const std::unique_ptr<Engine> e32 = engine_of_group(32);
    return *e32;
}

enum class Mode { interp, extrap, sr, isr, esr };

// Every output of a session over `inputs`: per input from the second on the generated frames at
// alphas 0.25 and 0.5 (interp, isr) or 0.5 and 1 (extrap, esr), and with super resolution every
// super-resolved frame first.
std::vector<ImageRGBA> outputs(Engine& e, Mode mode, bool skip_tiles, const std::vector<RawFrame>& inputs,
                               uint32_t w, uint32_t h) {
    Params p = given_field();
    p.skip_tiles = skip_tiles;
    if (mode == Mode::sr || mode == Mode::isr || mode == Mode::esr) p.scale = 2.f;
    auto s = e.create_session(internal_format(w, h), p);
    EXPECT_TRUE(s) << s.error().message;
    if (!s) return {};
    std::vector<ImageRGBA> out;
    const bool extrap = mode == Mode::extrap || mode == Mode::esr;
    const std::vector<float> alphas =
        extrap ? std::vector<float>{0.5f, 1.f} : std::vector<float>{0.25f, 0.5f};
    for (size_t k = 0; k < inputs.size(); ++k) {
        FrameView v = inputs[k].view();
        v.jitter_x = k % 2 ? 0.25f : -0.25f;
        v.jitter_y = k % 3 ? 0.125f : -0.375f;
        EXPECT_TRUE((*s)->submit(v));
        if (p.scale > 1.f) {
            auto f = (*s)->super_resolved();
            EXPECT_TRUE(f);
            if (f) out.push_back(f->color);
        }
        if (k == 0 || mode == Mode::sr) continue;
        auto g = extrap ? (*s)->extrapolate(alphas) : (*s)->interpolate(alphas);
        EXPECT_TRUE(g) << g.error().message;
        if (g)
            for (GeneratedFrame& f : *g) out.push_back(std::move(f.color));
    }
    EXPECT_EQ(e.validation_errors(), 0u) << "Vulkan validation errors were reported (see stderr)";
    return out;
}

TEST(Forms, EngineRejectsAWorkgroupOtherThan8Or32) {
    DeviceOptions o;
    o.workgroup = 16;
    auto e = Engine::create(o);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().code, Errc::invalid_argument);
}

// Every mode, with and without tile skipping, on random frames (vectors up to 6 px, so splats
// collide and leave holes and gaps) and on frames whose left half is still (so that the tiled
// forms run over a partial list and static tiles get dirty).
TEST(Forms, GpuAndCpuFormsGiveTheSameFrames) {
    const uint32_t w = 64, h = 48;
    std::vector<RawFrame> random, half_still;
    for (uint32_t k = 0; k < 4; ++k) {
        random.push_back(random_frame(w, h, 300 + k, 6.f));
        RawFrame f = random_frame(w, h, 400 + k, 3.f);
        RawFrame still = random_frame(w, h, 500, 3.f); // the same every frame
        auto* m = reinterpret_cast<glm::vec2*>(f.mv.data());
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w / 2; ++x) {
                const size_t i = size_t(y) * w + x;
                std::memcpy(f.color.data() + i * 16, still.color.data() + i * 16, 16);
                std::memcpy(f.depth.data() + i * 4, still.depth.data() + i * 4, 4);
                m[i] = glm::vec2(0.f);
            }
        half_still.push_back(std::move(f));
    }
    ASSERT_EQ(engine_with_group(8).workgroup(), 8u);
    ASSERT_EQ(engine_with_group(32).workgroup(), 32u);
    for (const auto* inputs : {&random, &half_still})
        for (Mode mode : {Mode::interp, Mode::extrap, Mode::sr, Mode::isr, Mode::esr})
            for (bool skip : {false, true}) {
                const std::vector<ImageRGBA> gpu = outputs(engine_with_group(8), mode, skip, *inputs, w, h);
                const std::vector<ImageRGBA> cpu = outputs(engine_with_group(32), mode, skip, *inputs, w, h);
                const std::string what = std::string(inputs == &random ? "random" : "half still") +
                                         ", mode " + std::to_string(int(mode)) + (skip ? ", skipping" : "");
                ASSERT_EQ(gpu.size(), cpu.size()) << what;
                ASSERT_FALSE(gpu.empty()) << what;
                float worst = 0;
                for (size_t f = 0; f < gpu.size(); ++f) {
                    ASSERT_EQ(gpu[f].rgba.size(), cpu[f].rgba.size()) << what;
                    for (size_t i = 0; i < gpu[f].rgba.size(); ++i)
                        worst = std::max(worst, std::abs(gpu[f].rgba[i] - cpu[f].rgba[i]) /
                                                    std::max(1.f, std::abs(cpu[f].rgba[i])));
                }
                EXPECT_LE(worst, kRelTolerance) << what;
            }
}

} // namespace
} // namespace fgsr::test
