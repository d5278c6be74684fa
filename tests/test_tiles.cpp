// Per-tile work skipping (Params::skip_tiles, shaders/classify.h): the classify pass against its
// CPU reference, and every mode run with skipping on and off on the same frames.
//
// Tolerance of on against off: per channel |on - off| <= 1e-5 * max(1, |off|) and PSNR >= 90 dB.
// Skipping is exact by construction (the static paths compute the same expressions on the same
// values: a static pixel's key, zero vectors, and phase-0 resampling, which every kind returns
// unchanged), so the only admissible difference is float rounding where the copy-through
// (classify) or the static sr / generate_sr variants are compiled separately from the full passes
// and the compiler may contract or reorder differently: a few ulps of values in [0, 65504].
// Measured: bit-identical on lavapipe (the tests report the max difference they saw).
#include "engine_fixture.hpp"

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

namespace fgsr::test {
namespace {

constexpr float kRelTolerance = 1e-5f;
constexpr double kMinPsnr = 90.0;

struct Diff {
    float max_abs = 0; // max over channels of |on - off| / max(1, |off|)
    double psnr = 1e9; // display-referred, capped at capture::kPsnrIdentical
};

Diff compare(const ImageRGBA& on, const ImageRGBA& off) {
    Diff d;
    EXPECT_EQ(on.rgba.size(), off.rgba.size());
    for (size_t i = 0; i < std::min(on.rgba.size(), off.rgba.size()); ++i)
        d.max_abs =
            std::max(d.max_abs, std::abs(on.rgba[i] - off.rgba[i]) / std::max(1.f, std::abs(off.rgba[i])));
    auto p = capture::psnr(on, off);
    d.psnr = p ? *p : 0.0;
    return d;
}

// Every output of a run: generated frames, then (with SR) the super-resolved frames.
struct Outputs {
    std::vector<ImageRGBA> frames;
    std::vector<GeneratedFrame> generated; // timings and tile counts of the generated frames
};

enum class Mode { interp, extrap, sr };

// Submits `inputs` in order; after each from the second on, generates at `alphas` (interp /
// extrap) or collects the super-resolved frame (sr, every input; with `generate_too` also an
// interpolation at 0.5, i.e. ISR).
Outputs run(const FrameFormat& format, const std::vector<FrameView>& inputs, const std::vector<float>& jitter,
            Params params, Mode mode, bool generate_too = false) {
    Outputs r;
    auto s = engine().create_session(format, params);
    EXPECT_TRUE(s) << s.error().message;
    if (!s) return r;
    const std::vector<float> alphas =
        mode == Mode::extrap ? std::vector<float>{0.5f, 1.f} : std::vector<float>{0.25f, 0.5f};
    for (size_t k = 0; k < inputs.size(); ++k) {
        FrameView v = inputs[k];
        if (!jitter.empty()) {
            v.jitter_x = jitter[(2 * k) % jitter.size()];
            v.jitter_y = jitter[(2 * k + 1) % jitter.size()];
        }
        auto ok = (*s)->submit(v);
        EXPECT_TRUE(bool(ok)) << (ok ? "" : ok.error().message);
        if (mode == Mode::sr) {
            auto f = (*s)->super_resolved();
            EXPECT_TRUE(f);
            if (f) r.frames.push_back(f->color);
        }
        if (k == 0 || (mode == Mode::sr && !generate_too)) continue;
        auto g = mode == Mode::extrap ? (*s)->extrapolate(alphas) : (*s)->interpolate(alphas);
        EXPECT_TRUE(g) << g.error().message;
        if (!g) continue;
        for (GeneratedFrame& f : *g) {
            r.frames.push_back(f.color);
            r.generated.push_back(std::move(f));
        }
    }
    expect_no_validation_errors();
    return r;
}

// Runs with skipping on and off and checks the tolerance; returns the run with skipping on.
Outputs expect_same_on_off(const FrameFormat& format, const std::vector<FrameView>& inputs,
                           const std::vector<float>& jitter, Params params, Mode mode,
                           bool generate_too = false) {
    params.skip_tiles = false;
    const Outputs off = run(format, inputs, jitter, params, mode, generate_too);
    params.skip_tiles = true;
    Outputs on = run(format, inputs, jitter, params, mode, generate_too);
    EXPECT_EQ(on.frames.size(), off.frames.size());
    Diff worst;
    for (size_t i = 0; i < std::min(on.frames.size(), off.frames.size()); ++i) {
        const Diff d = compare(on.frames[i], off.frames[i]);
        EXPECT_LE(d.max_abs, kRelTolerance) << "frame " << i;
        EXPECT_GE(d.psnr, kMinPsnr) << "frame " << i;
        worst.max_abs = std::max(worst.max_abs, d.max_abs);
        worst.psnr = std::min(worst.psnr, d.psnr);
    }
    std::printf("  on vs off: %zu frames, max relative difference %.3g, min PSNR %.1f dB\n", on.frames.size(),
                double(worst.max_abs), worst.psnr);
    return on;
}

// Share of tiles a pass skipped over a run.
double skipped_share(const Outputs& r, const std::string& pass) {
    uint64_t total = 0, skipped = 0;
    for (const GeneratedFrame& f : r.generated)
        for (const PassTiming& p : f.passes)
            if (p.name == pass) {
                total += p.tiles_total;
                skipped += p.tiles_skipped;
            }
    return total ? double(skipped) / double(total) : -1.0;
}

// A textured static background (depth 50) with, when `moving`, a 12x12 square (depth 5) at
// (x0 + k * speed, y0) in frame k, vectors to the previous frame.
RawFrame scene_frame(uint32_t w, uint32_t h, int k, float speed, bool with_square) {
    std::vector<glm::vec4> c(size_t(w) * h);
    std::vector<float> d(size_t(w) * h, 50.f);
    std::vector<glm::vec2> m(size_t(w) * h, glm::vec2(0.f));
    const float x0 = 10.f + float(k) * speed, y0 = 20.f;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            c[i] =
                glm::vec4(0.5f + 0.4f * std::sin(0.37f * float(x)), 0.5f + 0.4f * std::cos(0.23f * float(y)),
                          float((x / 4 + y / 4) % 2) * 0.5f + 0.25f, 1.f);
            if (with_square && float(x) + 0.5f >= x0 && float(x) + 0.5f < x0 + 12.f &&
                float(y) + 0.5f >= y0 && float(y) + 0.5f < y0 + 12.f) {
                c[i] = glm::vec4(0.9f, 0.1f, 0.1f, 1.f);
                d[i] = 5.f;
                m[i] = glm::vec2(-speed, 0.f);
            }
        }
    return make_raw(c, d, m);
}

std::vector<FrameView> views(const std::vector<RawFrame>& frames) {
    std::vector<FrameView> v;
    for (const RawFrame& f : frames) v.push_back(f.view());
    return v;
}

const std::vector<float> kJitter = {0.25f, -0.25f, -0.125f, 0.375f, 0.375f, 0.125f, -0.375f, -0.125f};

// A w x h pair for classify's stage 0: random frames; in the left half zero vectors in both
// frames, with equal depths in its left quarter (own-value test) and differing depths in the next
// quarter (static only when the 4 neighbours' frame-0 vectors are 0: the neighbour test); a moving
// pixel on the first pixel of tile column 1 (side 8), and a frame-0 vector on a tile border whose
// left neighbour, in the other tile, has differing depths.
std::pair<RawFrame, RawFrame> classify_scene(uint32_t w, uint32_t h, uint32_t seed) {
    RawFrame r0 = random_frame(w, h, seed, 4.f), r1 = random_frame(w, h, seed + 1, 4.f);
    auto* mv0 = reinterpret_cast<glm::vec2*>(r0.mv.data());
    auto* mv1 = reinterpret_cast<glm::vec2*>(r1.mv.data());
    auto* d0 = reinterpret_cast<float*>(r0.depth.data());
    auto* d1 = reinterpret_cast<float*>(r1.depth.data());
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w / 2; ++x) {
            const size_t i = size_t(y) * w + x;
            mv0[i] = mv1[i] = glm::vec2(0.f);
            d1[i] = x < w / 4 ? d0[i] : d0[i] * 2.f;
        }
    if (w > 8 && h > 3) mv1[size_t(3) * w + 8] = glm::vec2(0.f, 0.25f);
    if (w >= 80 && h > 5) mv0[size_t(5) * w + 32] = glm::vec2(-1.f, 0.f); // (31, 5) differs in depth
    return {std::move(r0), std::move(r1)};
}

// Tile flags of the GPU classification against ref::classify (tiles 8 / 16 / 32, quadratic and
// linear motion), every pixel of the clean static tiles against ref::copy_through, and the
// generated frames with skipping on against off. Returns the number of static tiles seen.
size_t expect_classify_matches(uint32_t w, uint32_t h, uint32_t seed) {
    const auto [r0, r1] = classify_scene(w, h, seed);
    const FrameFormat fmt = internal_format(w, h);
    size_t statics = 0;
    for (uint32_t tile : {8u, 16u, 32u})
        for (MotionModel motion : {MotionModel::quadratic, MotionModel::linear}) {
            Params p = given_field();
            p.tile_size = tile;
            p.motion = motion;
            auto s = engine().create_session(fmt, p);
            EXPECT_TRUE(s) << s.error().message;
            if (!s) return statics;
            EXPECT_TRUE((*s)->submit(r0.view()));
            EXPECT_TRUE((*s)->submit(r1.view()));
            const float alpha = 0.5f;
            auto g = (*s)->interpolate(std::span(&alpha, 1));
            EXPECT_TRUE(g) << g.error().message;
            auto inter = (*s)->read_intermediates();
            EXPECT_TRUE(inter);
            if (!g || !inter) return statics;
            const ref::InternalFrame f0 = to_internal(*(*s)->read_frame(0), w, h);
            const ref::InternalFrame f1 = to_internal(*(*s)->read_frame(1), w, h);
            ref::ClassifyParams c{};
            c.g = params::gen_params(fmt, p, alpha, false, true, true, params::input_measure(**s));
            c.tile = tile;
            c.mode = CLASSIFY_GENERATE;
            const std::vector<uint32_t> want = ref::classify(f0, f1, c);
            EXPECT_EQ(inter->tile_flags.size(), want.size());
            if (inter->tile_flags.size() != want.size()) return statics;
            const uint32_t tx = (w + tile - 1) / tile;
            for (size_t i = 0; i < want.size(); ++i) {
                EXPECT_EQ((inter->tile_flags[i] & TILE_STATIC) != 0u, want[i] == TILE_STATIC)
                    << w << "x" << h << " tile " << i << " side " << tile;
                statics += want[i] == TILE_STATIC ? 1 : 0;
                if (inter->tile_flags[i] != TILE_STATIC) continue;
                for (uint32_t y = uint32_t(i / tx) * tile; y < std::min(h, uint32_t(i / tx + 1) * tile); ++y)
                    for (uint32_t x = uint32_t(i % tx) * tile; x < std::min(w, uint32_t(i % tx + 1) * tile);
                         ++x) {
                        const glm::vec4 e = ref::copy_through(f0, f1, glm::ivec2(int(x), int(y)), c.g);
                        const float* got = &(*g)[0].color.rgba[(size_t(y) * w + x) * 4];
                        for (int ch = 0; ch < 4; ++ch)
                            if (got[ch] != e[ch]) {
                                ADD_FAILURE() << w << "x" << h << " side " << tile << " pixel " << x << ","
                                              << y << " channel " << ch << ": " << got[ch] << " != " << e[ch];
                                return statics;
                            }
                    }
            }
        }
    (void)expect_same_on_off(fmt, {r0.view(), r1.view()}, {}, given_field(), Mode::interp);
    expect_no_validation_errors();
    return statics;
}

// Widths divisible by 4 take classify's wide form on CPU devices (4 pixels per access), the
// others the per-pixel form; both against the CPU reference, with the odd sizes.
TEST(Tiles, ClassifyBothFormsMatchCpuReference) {
    EXPECT_GT(expect_classify_matches(77, 45, 5), 0u) << "77x45 (partial border tiles at every side)";
    EXPECT_GT(expect_classify_matches(80, 45, 21), 0u) << "80x45 has static tiles";
    EXPECT_GT(expect_classify_matches(79, 45, 23), 0u) << "79x45 has static tiles";
    for (auto [w, h] : {std::pair{20u, 9u}, std::pair{17u, 9u}, std::pair{4u, 1u}, std::pair{1u, 1u}})
        (void)expect_classify_matches(w, h, 25);
}

// A still pair (identical frames, zero vectors) at widths of both forms: every tile static and
// the output equal to the copy-through of the CPU reference at every pixel.
TEST(Tiles, StillPairIsStaticInBothForms) {
    for (uint32_t w : {64u, 61u}) {
        const uint32_t h = 19;
        const RawFrame f = scene_frame(w, h, 0, 0.f, false);
        const FrameFormat fmt = internal_format(w, h);
        auto s = engine().create_session(fmt, given_field());
        ASSERT_TRUE(s);
        ASSERT_TRUE((*s)->submit(f.view()));
        ASSERT_TRUE((*s)->submit(f.view()));
        const float alpha = 0.3f;
        auto g = (*s)->interpolate(std::span(&alpha, 1));
        ASSERT_TRUE(g) << g.error().message;
        auto inter = (*s)->read_intermediates();
        ASSERT_TRUE(inter);
        for (uint32_t flag : inter->tile_flags) EXPECT_EQ(flag, TILE_STATIC) << "width " << w;
        const ref::InternalFrame f0 = to_internal(*(*s)->read_frame(0), w, h);
        const ref::InternalFrame f1 = to_internal(*(*s)->read_frame(1), w, h);
        const ref::GenParams gp =
            params::gen_params(fmt, given_field(), alpha, false, true, true, params::input_measure(**s));
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const glm::vec4 e = ref::copy_through(f0, f1, glm::ivec2(int(x), int(y)), gp);
                for (int ch = 0; ch < 4; ++ch)
                    ASSERT_EQ((*g)[0].color.rgba[(size_t(y) * w + x) * 4 + size_t(ch)], e[ch])
                        << x << "," << y;
            }
    }
    expect_no_validation_errors();
}

TEST(Tiles, ClassifySrMatchesCpuReference) {
    const uint32_t w = 50, h = 34;
    RawFrame r0 = random_frame(w, h, 8, 2.f), r1 = random_frame(w, h, 9, 2.f);
    auto* mv1 = reinterpret_cast<glm::vec2*>(r1.mv.data());
    auto* d0 = reinterpret_cast<float*>(r0.depth.data());
    auto* d1 = reinterpret_cast<float*>(r1.depth.data());
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (x < 24) {
                mv1[i] = glm::vec2(0.f);
                d1[i] = d0[i] * 1.01f; // within T_D
            }
        }
    d1[size_t(20) * w + 10] *= 2.f; // a disocclusion without motion: tile (1, 2) needs rectification
    const FrameFormat fmt = internal_format(w, h);
    for (bool dilate : {false, true}) {
        Params p = given_field();
        p.scale = 2.f;
        p.tile_size = 8;
        p.dilate_mvs = dilate;
        auto s = engine().create_session(fmt, p);
        ASSERT_TRUE(s);
        ASSERT_TRUE((*s)->submit(r0.view()));
        EXPECT_TRUE((*s)->last_sr_tile_flags().empty()) << "no history: nothing classified";
        ASSERT_TRUE((*s)->submit(r1.view()));
        const ref::InternalFrame f0 = to_internal(*(*s)->read_frame(0), w, h);
        const ref::InternalFrame f1 = to_internal(*(*s)->read_frame(1), w, h);
        ref::ClassifyParams c{};
        c.g.width = w;
        c.g.height = h;
        c.g.t_depth = p.t_depth;
        c.tile = 8;
        c.mode = CLASSIFY_SR;
        c.dilate = dilate ? 1u : 0u;
        const std::vector<uint32_t> want = ref::classify(f0, f1, c);
        const std::vector<uint32_t> got = (*s)->last_sr_tile_flags();
        ASSERT_EQ(got.size(), want.size());
        size_t statics = 0;
        for (size_t i = 0; i < want.size(); ++i) {
            EXPECT_EQ(got[i], want[i]) << "tile " << i << " dilate " << dilate;
            statics += want[i] == TILE_STATIC ? 1 : 0;
        }
        // Tile columns 0-2 of 5 rows have zero vectors (0-1 with the dilation halo), less tile (1, 2).
        EXPECT_EQ(statics, dilate ? 9u : 14u);
    }
    expect_no_validation_errors();
}

TEST(Tiles, StillSceneIsCopiedThroughAndSkipsEverything) {
    const uint32_t w = 64, h = 40;
    const RawFrame f = scene_frame(w, h, 0, 0.f, false);
    const std::vector<FrameView> in = {f.view(), f.view(), f.view()};
    const FrameFormat fmt = internal_format(w, h);
    for (Mode mode : {Mode::interp, Mode::extrap}) {
        const Outputs on = expect_same_on_off(fmt, in, {}, given_field(), mode);
        EXPECT_EQ(skipped_share(on, "splat"), 1.0);
        EXPECT_EQ(skipped_share(on, "generate"), 1.0);
        // Identical frames: the generated frame is the input (colours are exact halves).
        const auto* src = reinterpret_cast<const float*>(f.color.data());
        for (const ImageRGBA& img : on.frames)
            for (size_t i = 0; i < img.rgba.size(); ++i)
                ASSERT_NEAR(img.rgba[i], src[i], 1e-3f * src[i]) << i;
    }
}

TEST(Tiles, PartiallyMovingSceneSkipsTheStaticTiles) {
    const uint32_t w = 96, h = 64;
    std::vector<RawFrame> frames;
    for (int k = 0; k < 4; ++k) frames.push_back(scene_frame(w, h, k, 3.f, true));
    const FrameFormat fmt = internal_format(w, h);
    for (Mode mode : {Mode::interp, Mode::extrap}) {
        const Outputs on = expect_same_on_off(fmt, views(frames), {}, given_field(), mode);
        const double share = skipped_share(on, "generate");
        EXPECT_GT(share, 0.5) << "a 12x12 square moves on a 96x64 background";
        EXPECT_LT(share, 1.0);
        EXPECT_LE(share, skipped_share(on, "splat")) << "splat dirties static tiles, never cleans them";
    }
    Params linear = given_field();
    linear.motion = MotionModel::linear;
    linear.blend = BlendMode::select;
    (void)expect_same_on_off(fmt, views(frames), {}, linear, Mode::interp);
}

TEST(Tiles, SuperResolutionOnOff) {
    const uint32_t w = 48, h = 40;
    std::vector<RawFrame> still, moving;
    for (int k = 0; k < 5; ++k) {
        still.push_back(scene_frame(w, h, 0, 0.f, false));
        moving.push_back(scene_frame(w, h, k, 2.f, true));
    }
    const FrameFormat fmt = internal_format(w, h);
    for (float scale : {2.f, 1.5f})
        for (Resample resample : {Resample::lut, Resample::catmull_rom}) {
            Params p = given_field();
            p.scale = scale;
            p.resample = resample;
            p.tile_size = 8;
            (void)expect_same_on_off(fmt, views(still), kJitter, p, Mode::sr);
            (void)expect_same_on_off(fmt, views(moving), kJitter, p, Mode::sr);
            p.dilate_mvs = true;
            (void)expect_same_on_off(fmt, views(moving), kJitter, p, Mode::sr);
        }
    // ISR and ESR: classify and splat at input resolution, generate_sr over the listed tiles.
    Params p = given_field();
    p.scale = 2.f;
    p.tile_size = 8;
    const Outputs isr = expect_same_on_off(fmt, views(moving), kJitter, p, Mode::sr, true);
    EXPECT_GT(skipped_share(isr, "generate_sr"), 0.3);
    (void)expect_same_on_off(fmt, views(still), kJitter, p, Mode::sr, true);
    (void)expect_same_on_off(fmt, views(moving), kJitter, p, Mode::extrap);
}

TEST(Tiles, SyntheticCaptureOnOff) {
    capture::SceneOptions o;
    o.width = 160;
    o.height = 90;
    o.supersample = 1;
    auto c = capture::make_synthetic_capture(o, 3);
    ASSERT_TRUE(c) << c.error().message;
    std::vector<FrameView> in;
    for (const capture::Frame& f : c->inputs) in.push_back(f.view());
    for (Mode mode : {Mode::interp, Mode::extrap})
        (void)expect_same_on_off(c->format, in, {}, given_field(), mode);
}

// The shared captures (CI has them), a few frames each.
void shared_capture_on_off(const char* name, bool lr, bool sr) {
    const std::filesystem::path dir = std::filesystem::path(FGSR_SHARED_CAPTURES) / name;
    if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " not found (captures exist in CI only)";
    auto c = capture::load(dir, lr, 3);
    ASSERT_TRUE(c) << c.error().message;
    std::vector<FrameView> in;
    std::vector<float> jitter;
    for (const capture::Frame& f : c->inputs) {
        in.push_back(f.view());
        in.back().jitter_x = f.jitter_x;
        in.back().jitter_y = f.jitter_y;
    }
    if (!sr) {
        for (Mode mode : {Mode::interp, Mode::extrap})
            (void)expect_same_on_off(c->format, in, {}, given_field(), mode);
        return;
    }
    Params p = given_field();
    p.scale = 2.f;
    (void)expect_same_on_off(c->format, in, {}, p, Mode::sr, true);
}

TEST(Tiles, TossFgOnOff) {
    shared_capture_on_off("blender/toss-fg", false, false);
}
TEST(Tiles, MobfgsrBunkerOnOff) {
    shared_capture_on_off("mobfgsr-bunker", true, false);
}
TEST(Tiles, OrbitSrOnOff) {
    shared_capture_on_off("blender/orbit-sr", false, true);
}

// Whether a generated frame's or an sr submit's passes include a classify.
bool classified(const std::vector<PassTiming>& passes) {
    for (const PassTiming& p : passes)
        if (p.name == "classify") return true;
    return false;
}

// The adaptive fallback (daemon/engine/src/session.hpp, kUnclassifiedRun): on content that keeps
// moving, a call classifies after 7, 15, 31 and then every 63 unclassified calls; those calls
// after a miss only probe (classify, then every pass over every tile: nothing skipped). Content
// that turns still is found by the next probe and classified from the call after it on, at every
// call; motion after that starts again at 7. Which calls classified is read from the passes each
// call reports; the expected calls follow from the rule, not from a run. Every frame equals the
// one of a session without skipping (the tolerance of this file).
TEST(Tiles, ClassifiesMovingContentLessAndLessOften) {
    const uint32_t w = 64, h = 48;
    // Random frames stand for moving content: not a stream, and ingest's cut stage would take the
    // switch between still and random frames for a scene cut and refuse the pair (Cut.* test it).
    Params p = given_field();
    p.vector_cuts = false;
    auto s = engine().create_session(internal_format(w, h), p);
    ASSERT_TRUE(s) << s.error().message;
    Params no_skip = p;
    no_skip.skip_tiles = false;
    auto off = engine().create_session(internal_format(w, h), no_skip);
    ASSERT_TRUE(off) << off.error().message;
    const RawFrame still = scene_frame(w, h, 0, 0.f, false); // zero vectors: every tile static
    const RawFrame first = random_frame(w, h, 1000, 4.f);
    ASSERT_TRUE((*s)->submit(first.view()));
    ASSERT_TRUE((*off)->submit(first.view()));
    const float alpha = 0.5f;
    // Call i submits a new input, then interpolates: moving content (random vectors in every tile)
    // for calls [0, 130), still for [130, 190) (the first still pair is call 131), moving again
    // from 190.
    std::vector<int> calls;
    for (int i = 0; i < 210; ++i) {
        const bool moving = i < 130 || i >= 190;
        const RawFrame f = moving ? random_frame(w, h, uint32_t(i), 4.f) : RawFrame{};
        ASSERT_TRUE((*s)->submit(moving ? f.view() : still.view())) << "call " << i;
        ASSERT_TRUE((*off)->submit(moving ? f.view() : still.view())) << "call " << i;
        auto g = (*s)->interpolate(std::span(&alpha, 1));
        ASSERT_TRUE(g) << g.error().message;
        auto plain = (*off)->interpolate(std::span(&alpha, 1));
        ASSERT_TRUE(plain) << plain.error().message;
        EXPECT_LE(compare((*g)[0].color, (*plain)[0].color).max_abs, kRelTolerance) << "call " << i;
        const std::vector<PassTiming>& passes = (*g)[0].passes;
        if (classified(passes)) calls.push_back(i);
        if (i == 8 || i == 24 || i == 56 || i == 120 || i == 184) { // probes: nothing skipped
            ASSERT_EQ(passes.size(), 3u) << "call " << i;
            EXPECT_EQ(passes[0].name, "classify");
            EXPECT_EQ(passes[0].tiles_total, 12u); // 4 x 3 tiles of 16 px
            EXPECT_EQ(passes[1].tiles_skipped, 0u);
            EXPECT_EQ(passes[2].tiles_skipped, 0u);
        }
        if (i == 186) { // a still pair after the probe found it: every tile skipped
            ASSERT_EQ(passes.size(), 3u);
            EXPECT_EQ(passes[2].tiles_skipped, 12u);
        }
    }
    // Moving: 0, then after 7, 15, 31, 63 unclassified calls the probes 8, 24, 56, 120; the next
    // probe, 184, finds the pair still: every call from there classifies; call 190 (moving)
    // misses, then 7 calls without and a probe.
    std::vector<int> want = {0, 8, 24, 56, 120};
    for (int i = 184; i <= 190; ++i) want.push_back(i);
    want.push_back(198);
    EXPECT_EQ(calls, want);
    expect_no_validation_errors();
}

// Where classifying pays on CPU devices (kMinSkipShareCpu, 0.45 of the tiles skippable; on GPUs
// kMinSkipShare, 0.25): a scene whose left 9/16 pans (3 of 8 tile columns skippable) backs off
// after its first call on a CPU device and keeps classifying on a GPU; one whose left 3/8 pan
// (4 or 5 of 8 skippable, as the splat dirties the next column or not) keeps classifying on both.
// The shares are read from the first call and checked to lie on the sides of the thresholds the
// expectations take (the second below the 0.7 that CPU devices took before the split form of
// tiled generate).
TEST(Tiles, CpuDevicesClassifyOnlyWhereMostTilesCanBeSkipped) {
    const uint32_t w = 128, h = 64; // 8 x 4 tiles of 16 px
    const auto frame = [&](int k, uint32_t moving_columns) {
        RawFrame f = scene_frame(w, h, 0, 0.f, false);
        auto* c = reinterpret_cast<glm::vec4*>(f.color.data());
        auto* m = reinterpret_cast<glm::vec2*>(f.mv.data());
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < moving_columns; ++x) { // a stripe pattern panning 2 px a frame
                c[size_t(y) * w + x] = glm::vec4(float((x + 2 * uint32_t(k)) / 3 % 2), 0.5f, 0.5f, 1.f);
                m[size_t(y) * w + x] = glm::vec2(2.f, 0.f);
            }
        return f;
    };
    for (uint32_t moving : {w * 9 / 16, w * 3 / 8}) {
        auto s = engine().create_session(internal_format(w, h), given_field());
        ASSERT_TRUE(s) << s.error().message;
        std::vector<bool> calls;
        double share = -1;
        for (int k = 0; k < 4; ++k) {
            const RawFrame f = frame(k, moving);
            ASSERT_TRUE((*s)->submit(f.view()));
            if (k == 0) continue;
            const float alpha = 0.5f;
            auto g = (*s)->interpolate(std::span(&alpha, 1));
            ASSERT_TRUE(g) << g.error().message;
            const std::vector<PassTiming>& passes = (*g)[0].passes;
            calls.push_back(classified(passes));
            if (k == 1) {
                ASSERT_EQ(passes.size(), 3u);
                share = double(passes[2].tiles_skipped) / double(passes[2].tiles_total);
            }
        }
        if (moving == w * 3 / 8) {
            EXPECT_GE(share, 0.45) << "skippable on both devices";
            EXPECT_LT(share, 0.7);
        } else {
            EXPECT_GE(share, 0.25) << "skippable on a GPU";
            EXPECT_LT(share, 0.45) << "not on a CPU device";
        }
        const bool keeps = moving == w * 3 / 8 || !engine().is_cpu_device();
        EXPECT_EQ(calls, (std::vector<bool>{true, keeps, keeps})) << moving << " moving columns";
    }
    expect_no_validation_errors();
}

// The probe in a call of two frames with super resolution (ISR): it classifies the first frame
// only, the frames equal those of a session without skipping, and the calls that classify follow
// the rule (the first call, then the probes after 7 and 15 plain calls).
TEST(Tiles, ProbesInIsrCallsOfTwoFramesChangeNoFrame) {
    const uint32_t w = 64, h = 48;
    Params p = given_field();
    p.scale = 2.f;
    auto s = engine().create_session(internal_format(w, h), p);
    ASSERT_TRUE(s) << s.error().message;
    Params no_skip = p;
    no_skip.skip_tiles = false;
    auto off = engine().create_session(internal_format(w, h), no_skip);
    ASSERT_TRUE(off) << off.error().message;
    const float alphas[2] = {0.5f, 0.75f};
    std::vector<int> calls;
    for (int i = 0; i < 30; ++i) {
        const RawFrame f = random_frame(w, h, uint32_t(i), 4.f);
        ASSERT_TRUE((*s)->submit(f.view()));
        ASSERT_TRUE((*off)->submit(f.view()));
        if (i == 0) continue;
        auto g = (*s)->interpolate(std::span(alphas, 2));
        ASSERT_TRUE(g) << g.error().message;
        auto e = (*off)->interpolate(std::span(alphas, 2));
        ASSERT_TRUE(e) << e.error().message;
        for (size_t k = 0; k < 2; ++k)
            EXPECT_LE(compare((*g)[k].color, (*e)[k].color).max_abs, kRelTolerance) << "call " << i;
        if (classified((*g)[0].passes)) calls.push_back(i);
        if (i > 1) {
            EXPECT_FALSE(classified((*g)[1].passes)) << "a probe classifies the first frame only, call " << i;
        }
    }
    EXPECT_EQ(calls, (std::vector<int>{1, 9, 25}));
    expect_no_validation_errors();
}

// The same rule for super resolution, per submit: the first submit has no history (nothing to
// classify), the second classifies and misses on moving content, then 7, 15, 31 submits without.
TEST(Tiles, SuperResolutionClassifiesMovingContentLessAndLessOften) {
    const uint32_t w = 48, h = 40;
    Params p = given_field();
    p.scale = 2.f;
    auto s = engine().create_session(internal_format(w, h), p);
    ASSERT_TRUE(s) << s.error().message;
    std::vector<int> calls;
    for (int i = 0; i < 70; ++i) {
        const RawFrame f = random_frame(w, h, uint32_t(i), 4.f);
        ASSERT_TRUE((*s)->submit(f.view())) << "submit " << i;
        auto sr = (*s)->super_resolved();
        ASSERT_TRUE(sr) << sr.error().message;
        if (classified(sr->passes)) calls.push_back(i);
    }
    EXPECT_EQ(calls, (std::vector<int>{1, 9, 25, 57}));
    expect_no_validation_errors();
}

TEST(Tiles, RejectsBadTileSize) {
    Params p = given_field();
    p.tile_size = 12;
    auto s = engine().create_session(internal_format(16, 16), p);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, Errc::invalid_argument);
}

} // namespace
} // namespace fgsr::test
