// Scene cuts in sessions with vectors (ingest's cut stage, shaders/cut.h; Params::vector_cuts):
// a frame whose own vectors do not explain its colour against the previous frame starts the
// session afresh, as FrameView::reset would have. Analytic scenes: value noise panned by a known
// amount per frame, so that the vectors given are exact where the scene goes on, and a second
// scene (another texture) after a cut, whose vectors point where a renderer would reproject them
// (far off, into the other shot) or are zero (a client that writes none at a cut).
#include "engine_fixture.hpp"
#include "value_noise.hpp"

#include <fgsr/engine/reference.hpp>

#include <cmath>
#include <functional>

namespace fgsr::test {
namespace {

constexpr uint32_t kW = 128, kH = 96;

struct Pan {
    uint32_t seed = 3;
    glm::vec2 start{0.f}, velocity{5.f, 2.f}, accel{0.f}; // scene offset at frame t: start + v t + a t^2 / 2
    // A square occluder in front (depth 2) moving its own way: disocclusion behind it.
    bool occluder = false;
    // The lighting of the whole frame t (a fade, a flash): colour = lift + gain x colour, with
    // light(t) = (gain, lift); none: (1, 0).
    std::function<glm::vec2(int)> light;

    glm::vec2 offset(float t) const { return start + velocity * t + 0.5f * accel * t * t; }
    glm::vec2 square(float t) const { return glm::vec2(30.f, 30.f) + glm::vec2(-6.f, 3.f) * t; }
    bool on_square(glm::vec2 p, float t) const {
        const glm::vec2 d = p - square(t);
        return occluder && d.x >= 0.f && d.y >= 0.f && d.x < 28.f && d.y < 28.f;
    }
    // Frame t: colour of the scene sampled at pixel centres, depth (10 behind, 2 on the square),
    // vectors to frame t - 1 (none for t = 0).
    RawFrame frame(int t, const glm::vec2* mv_override = nullptr) const {
        std::vector<glm::vec4> col(size_t(kW) * kH);
        std::vector<float> depth(col.size());
        std::vector<glm::vec2> mv(t == 0 ? 0 : col.size());
        for (uint32_t y = 0; y < kH; ++y)
            for (uint32_t x = 0; x < kW; ++x) {
                const size_t i = size_t(y) * kW + x;
                const glm::vec2 c(float(x) + 0.5f, float(y) + 0.5f);
                const bool sq = on_square(c, float(t));
                const glm::vec2 q = sq ? c - square(float(t)) : c + offset(float(t));
                const float v = value_noise(q.x, q.y, sq ? 3.f : 4.f, sq ? seed + 100 : seed);
                col[i] = sq ? glm::vec4(0.9f * v, 0.5f * v, 0.2f, 1.f) : glm::vec4(v, v, 0.8f * v, 1.f);
                if (light) {
                    const glm::vec2 gl = light(t);
                    col[i] = glm::vec4(glm::vec3(gl.y) + gl.x * glm::vec3(col[i]), 1.f);
                }
                depth[i] = sq ? 2.f : 10.f;
                if (t > 0) {
                    // The point at c was at c + (offset(t) - offset(t - 1)) in frame t - 1 (the
                    // scene slides by minus the offset); the square's points move with it.
                    mv[i] = mv_override ? *mv_override
                            : sq        ? square(float(t - 1)) - square(float(t))
                                        : offset(float(t)) - offset(float(t - 1));
                }
            }
        return make_raw(col, depth, mv);
    }
};

std::unique_ptr<Session> session(bool vector_cuts = true, bool correct_vectors = false) {
    Params p = given_field();
    p.vector_cuts = vector_cuts;
    p.correct_vectors = correct_vectors;
    auto s = engine().create_session(internal_format(kW, kH), p);
    EXPECT_TRUE(s) << s.error().message;
    return s ? std::move(*s) : nullptr;
}

std::vector<float> interpolated(Session& s) {
    const float a[] = {0.5f};
    auto out = s.interpolate(a);
    EXPECT_TRUE(out) << out.error().message;
    return out ? (*out)[0].color.rgba : std::vector<float>{};
}

// The stage on the GPU and on the CPU (the same header) count the same blocks: frame 2's vectors
// are exact on the left half and point elsewhere on the right half (share near a half, so a
// block counted differently shows).
TEST(Cut, StageMatchesTheCpuReference) {
    const Pan pan;
    auto s = session();
    ASSERT_TRUE(s);
    ASSERT_TRUE(s->submit(pan.frame(0).view()));
    ASSERT_TRUE(s->submit(pan.frame(1).view()));
    RawFrame f2 = pan.frame(2);
    std::vector<glm::vec2> mv(size_t(kW) * kH);
    std::memcpy(mv.data(), f2.mv.data(), f2.mv.size());
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = kW / 2; x < kW; ++x) mv[size_t(y) * kW + x] = glm::vec2(37.f, -23.f);
    f2.mv = bytes_of(mv);
    ASSERT_TRUE(s->submit(f2.view()));
    auto cur = s->read_frame(1), prev = s->read_frame(0);
    ASSERT_TRUE(cur && prev);
    const std::vector<ref::CutBlock> blocks =
        ref::cut_stage(to_internal(*cur, kW, kH), to_internal(*prev, kW, kH));
    ASSERT_EQ(blocks.size(), size_t(ref::cut_blocks(kW, kH)));
    const float cpu = ref::cut_share(blocks);
    EXPECT_GT(cpu, 0.35f) << "the right half's blocks find no match";
    EXPECT_LT(cpu, 0.65f) << "the left half's do";
    EXPECT_NEAR(s->last_cut_share(), cpu, 0.5f / float(blocks.size())) << "GPU and CPU count the same blocks";
    expect_no_validation_errors();
}

// A cut the client does not announce: scene B's first frame carries vectors into scene A (far off)
// or zero ones. The session starts afresh there, exactly as if the frame had come with
// FrameView::reset and without vectors: the pair across it is refused, its vectors are not read as
// frame-0 motion by the next pairs, whose frames equal those of the announced cut value for value.
// The same in sessions that correct their vectors by colour (Params::correct_vectors), whose block
// matching's own cut test only skips the correction: until change 27 of docs/ACCURACY.md they ran
// no cut stage, and carried the vectors across.
TEST(Cut, UnannouncedCutStartsTheSessionAfresh) {
    const Pan a{.seed = 3, .start = glm::vec2(0.f), .velocity = glm::vec2(5.f, 2.f), .accel = glm::vec2(0.6f, 0.f)};
    const Pan b{.seed = 41, .start = glm::vec2(400.f, -300.f), .velocity = glm::vec2(-3.f, 4.f), .accel = glm::vec2(0.f, -0.5f)};
    const glm::vec2 reprojected(-211.f, 97.f), zero(0.f);
    for (const bool correct : {false, true})
        for (const glm::vec2* cut_mv : {&reprojected, &zero}) {
            SCOPED_TRACE(cut_mv == &zero ? "zero vectors at the cut" : "vectors into the other shot");
            SCOPED_TRACE(correct ? "vectors corrected by colour" : "given vectors");
            auto unannounced = session(true, correct), announced = session(true, correct);
            ASSERT_TRUE(unannounced && announced);
            for (int t = 0; t < 4; ++t) {
                ASSERT_TRUE(unannounced->submit(a.frame(t).view()));
                ASSERT_TRUE(announced->submit(a.frame(t).view()));
                EXPECT_FALSE(unannounced->last_scene_cut()) << "scene A, frame " << t;
            }
            EXPECT_LT(unannounced->last_cut_share(), 0.1f)
                << "exact vectors (or block matching) explain the colour";
            const RawFrame cut = b.frame(4, cut_mv);
            ASSERT_TRUE(unannounced->submit(cut.view()));
            FrameView reset = cut.view();
            reset.mv = {};
            reset.reset = true;
            ASSERT_TRUE(announced->submit(reset));
            EXPECT_TRUE(unannounced->last_scene_cut());
            EXPECT_GT(unannounced->last_cut_share(), 0.5f);
            EXPECT_EQ(unannounced->frames_submitted(), 1u) << "the cut starts the session afresh";
            const float alpha = 0.5f;
            EXPECT_FALSE(unannounced->interpolate(std::span<const float>(&alpha, 1)))
                << "nothing across the cut";
            auto r = unannounced->read_frame(1);
            ASSERT_TRUE(r);
            EXPECT_FALSE(r->has_mv) << "its vectors are not the next pair's frame-0 motion";
            for (int t = 5; t < 7; ++t) {
                ASSERT_TRUE(unannounced->submit(b.frame(t).view()));
                ASSERT_TRUE(announced->submit(b.frame(t).view()));
                EXPECT_FALSE(unannounced->last_scene_cut()) << "scene B goes on, frame " << t;
                const std::vector<float> x = interpolated(*unannounced), y = interpolated(*announced);
                ASSERT_EQ(x.size(), y.size());
                ASSERT_FALSE(x.empty());
                size_t differ = 0;
                for (size_t i = 0; i < x.size(); ++i) differ += x[i] != y[i];
                EXPECT_EQ(differ, 0u) << "frame " << t << ": as after an announced cut";
            }
        }
    expect_no_validation_errors();
}

// An announced cut (FrameView::reset) whose frame still carries vectors, zero here (what a client
// that writes none at a cut hands over; zero is a plausible frame-0 motion for the quadratic
// model, which far-off reprojected vectors would not be): the session keeps none of them, so the
// pairs after it equal those after the same reset frame handed over without vectors, value for
// value. Scene B accelerates, so a frame-0 motion of zero would bend its path. The same for a cut
// announced by Session::reset() before the frame.
TEST(Cut, AnnouncedResetKeepsNoVectors) {
    const Pan a{.seed = 3};
    const Pan b{.seed = 41, .start = glm::vec2(400.f, -300.f), .velocity = glm::vec2(-3.f, 4.f),
                .accel = glm::vec2(0.f, -0.5f)};
    const glm::vec2 zero(0.f);
    auto with = session(), by_call = session(), without = session();
    ASSERT_TRUE(with && by_call && without);
    for (int t = 0; t < 3; ++t)
        for (Session* s : {with.get(), by_call.get(), without.get()})
            ASSERT_TRUE(s->submit(a.frame(t).view()));
    const RawFrame cut = b.frame(3, &zero);
    FrameView v = cut.view();
    by_call->reset();
    ASSERT_TRUE(by_call->submit(v));
    v.reset = true;
    ASSERT_TRUE(with->submit(v));
    v.mv = {};
    ASSERT_TRUE(without->submit(v));
    for (Session* s : {with.get(), by_call.get()}) {
        auto r = s->read_frame(1);
        ASSERT_TRUE(r);
        EXPECT_FALSE(r->has_mv) << "the reset frame's vectors point into the shot before it";
    }
    for (int t = 4; t < 6; ++t) {
        for (Session* s : {with.get(), by_call.get(), without.get()})
            ASSERT_TRUE(s->submit(b.frame(t).view()));
        const std::vector<float> y = interpolated(*without);
        ASSERT_FALSE(y.empty());
        for (Session* s : {with.get(), by_call.get()}) {
            const std::vector<float> x = interpolated(*s);
            ASSERT_EQ(x.size(), y.size());
            size_t differ = 0;
            for (size_t i = 0; i < x.size(); ++i) differ += x[i] != y[i];
            EXPECT_EQ(differ, 0u) << "frame " << t
                                  << (s == with.get() ? " (FrameView::reset)" : " (Session::reset)")
                                  << ": as after a reset frame without vectors";
        }
    }
    expect_no_validation_errors();
}

// Right vectors are no cut, however fast the motion: an accelerating pan reaching 31 px a frame,
// an occluder moving against it (disocclusion behind it, content entering at the edges). The
// content entering at the edge alone is a quarter of this 128-pixel frame by the end, above block
// matching's kCutShare (0.22): given vectors are held to most of the frame (kCutShareVectors) and
// to a jump from the session's typical share (ref::is_vector_cut), and this share only grows.
TEST(Cut, FastMotionWithRightVectorsIsNoCut) {
    const Pan fast{.seed = 9, .start = glm::vec2(0.f), .velocity = glm::vec2(4.f, -1.f), .accel = glm::vec2(3.f, 1.f),
                   .occluder = true};
    auto s = session();
    ASSERT_TRUE(s);
    float most = 0.f;
    for (int t = 0; t < 10; ++t) {
        ASSERT_TRUE(s->submit(fast.frame(t).view()));
        EXPECT_FALSE(s->last_scene_cut()) << "frame " << t;
        most = std::max(most, s->last_cut_share());
    }
    EXPECT_EQ(s->frames_submitted(), 10u);
    EXPECT_GT(most, ref::kCutShare) << "block matching's threshold would have cut";
    EXPECT_LT(most, 0.4f) << "the unexplained blocks are those of the entering edge and the disocclusion";
    expect_no_validation_errors();
}

// With the switch off the stage does not run: the same unannounced cut goes through as before
// (the pair across it is generated from the vectors given).
TEST(Cut, SwitchOffTrustsTheVectors) {
    const Pan a{.seed = 3}, b{.seed = 41, .start = glm::vec2(400.f, -300.f)};
    const glm::vec2 reprojected(-211.f, 97.f);
    auto s = session(false);
    ASSERT_TRUE(s);
    for (int t = 0; t < 4; ++t) ASSERT_TRUE(s->submit(a.frame(t).view()));
    ASSERT_TRUE(s->submit(b.frame(4, &reprojected).view()));
    EXPECT_FALSE(s->last_scene_cut());
    EXPECT_LT(s->last_cut_share(), 0.f) << "not measured";
    EXPECT_EQ(s->frames_submitted(), 5u);
    EXPECT_FALSE(interpolated(*s).empty());
    expect_no_validation_errors();
}

// The share of the frame's blocks that the rule of change 22 alone (block_unmatched on the colour
// as given) counts: the session's last frame against the one before, on the CPU.
float share_as_given(Session& s) {
    auto cur = s.read_frame(1), prev = s.read_frame(0);
    EXPECT_TRUE(cur && prev);
    if (!cur || !prev) return -1.f;
    const std::vector<ref::CutBlock> blocks =
        ref::cut_stage(to_internal(*cur, kW, kH), to_internal(*prev, kW, kH));
    size_t high = 0;
    for (const ref::CutBlock& b : blocks) high += ref::block_unmatched(b.sad.x, b.sad.y) ? 1 : 0;
    return float(high) / float(blocks.size());
}

// A change of the whole frame's lighting is no cut: the vectors still explain the colour, up to
// a law that moves every block's mean together (ref::fit_lighting). A fade to black over 4 to 20
// frames and one-frame flashes (a lift of 0.1 and 0.2 in linear light, a gain of 1.4 and 1.8) on
// the moving scene with its occluder: the colour as given leaves most blocks unmatched at some
// frame of each but the slowest fade (the test's own check that these are hard cases: change 22's
// rule alone cut all but that one and the 10-frame fade, whose share rose slowly enough for the
// session's typical share to follow), and no frame is a cut, so every pair is generated. The last
// step of a fade, into a frame with nothing left to match (all black), is not asserted: it reads
// as a cut into a featureless shot, which it is as far as the colour can tell.
TEST(Cut, LightingChangeIsNoCut) {
    const Pan scene{.seed = 9, .velocity = glm::vec2(3.f, 1.f), .occluder = true};
    const float alpha = 0.5f;
    for (int frames : {4, 6, 10, 20}) {
        SCOPED_TRACE("fade to black over " + std::to_string(frames) + " frames");
        Pan fade = scene;
        fade.light = [frames](int t) {
            return glm::vec2(t < 4 ? 1.f : std::max(0.f, 1.f - float(t - 4) / float(frames)), 0.f);
        };
        auto s = session();
        ASSERT_TRUE(s);
        float given = 0.f;
        for (int t = 0; t < 4 + frames; ++t) { // up to the last frame before black
            ASSERT_TRUE(s->submit(fade.frame(t).view()));
            EXPECT_FALSE(s->last_scene_cut()) << "frame " << t;
            if (t > 0) {
                given = std::max(given, share_as_given(*s));
                EXPECT_TRUE(s->interpolate(std::span<const float>(&alpha, 1))) << "frame " << t;
            }
        }
        if (frames <= 10) {
            EXPECT_GT(given, ref::kCutShareVectors) << "the colour as given leaves most blocks unmatched";
        }
    }
    for (glm::vec2 flash :
         {glm::vec2(1.f, 0.1f), glm::vec2(1.f, 0.2f), glm::vec2(1.4f, 0.f), glm::vec2(1.8f, 0.f)}) {
        SCOPED_TRACE("a flash of gain " + std::to_string(flash.x) + ", lift " + std::to_string(flash.y));
        Pan lit = scene;
        lit.light = [flash](int t) { return t == 4 ? flash : glm::vec2(1.f, 0.f); };
        auto s = session();
        ASSERT_TRUE(s);
        float given = 0.f;
        for (int t = 0; t < 7; ++t) {
            ASSERT_TRUE(s->submit(lit.frame(t).view()));
            EXPECT_FALSE(s->last_scene_cut()) << "frame " << t;
            if (t > 0) {
                given = std::max(given, share_as_given(*s));
                EXPECT_LT(s->last_cut_share(), 0.45f) << "frame " << t;
                EXPECT_TRUE(s->interpolate(std::span<const float>(&alpha, 1))) << "frame " << t;
            }
        }
        EXPECT_GT(given, ref::kCutShareVectors) << "the colour as given would have cut";
    }
    expect_no_validation_errors();
}

// A cut is still a cut when the light changes with it: scene B's first frame, reprojected vectors
// into scene A, at twice and at half the brightness, and after scene A has faded halfway.
TEST(Cut, CutUnderChangingLightIsStillACut) {
    const Pan b{.seed = 41, .start = glm::vec2(400.f, -300.f), .velocity = glm::vec2(-3.f, 4.f)};
    const glm::vec2 reprojected(-211.f, 97.f);
    for (float gain : {2.f, 0.5f, 1.f}) {
        SCOPED_TRACE("scene B at gain " + std::to_string(gain));
        Pan a{.seed = 3, .velocity = glm::vec2(5.f, 2.f)};
        if (gain == 1.f) a.light = [](int t) { return glm::vec2(1.f - 0.125f * float(t), 0.f); };
        Pan bl = b;
        bl.light = [gain](int) { return glm::vec2(gain, 0.f); };
        auto s = session();
        ASSERT_TRUE(s);
        for (int t = 0; t < 5; ++t) {
            ASSERT_TRUE(s->submit(a.frame(t).view()));
            EXPECT_FALSE(s->last_scene_cut()) << "scene A, frame " << t;
        }
        ASSERT_TRUE(s->submit(bl.frame(5, &reprojected).view()));
        EXPECT_TRUE(s->last_scene_cut());
        EXPECT_GT(s->last_cut_share(), 0.5f);
    }
    expect_no_validation_errors();
}

// The fit itself, on blocks made to measure (every block's texture matches once its mean difference
// is out: bias-free SAD 0, contrast 0.05): means that follow a law are fitted to it and every block
// counts as matched relit; means with no relation to the previous frame's (a cut) fit a gain at
// the clamp's floor and leave most blocks unmatched relit.
TEST(Cut, LightingFitFindsTheLaw) {
    std::vector<ref::CutBlock> blocks(400);
    auto relit_unmatched = [&](const ref::LightingFit& fit) {
        size_t high = 0;
        for (const ref::CutBlock& b : blocks) high += ref::relit_unmatched(b, fit) ? 1 : 0;
        return high;
    };
    for (size_t i = 0; i < blocks.size(); ++i) {
        const float p = 0.1f + 0.8f * float((i * 37) % 101) / 100.f;
        blocks[i].sad = glm::vec4(0.5f, 0.05f, 0.f, 0.f);
        blocks[i].level = glm::vec4(1.3f * p + 0.05f, p, 0.f, 0.f);
    }
    ref::LightingFit fit = ref::fit_lighting(blocks);
    EXPECT_NEAR(fit.gain, 1.3f, 1e-4f);
    EXPECT_NEAR(fit.offset, 0.05f, 1e-4f);
    EXPECT_EQ(relit_unmatched(fit), 0u);
    EXPECT_GT(relit_unmatched(ref::LightingFit{}), blocks.size() / 2) << "unlit, the law's change is a mismatch";
    for (size_t i = 0; i < blocks.size(); ++i)
        blocks[i].level.x = 0.1f + 0.8f * float((i * 53 + 11) % 97) / 96.f;
    fit = ref::fit_lighting(blocks);
    EXPECT_EQ(fit.gain, ref::kCutLightGainMin);
    EXPECT_GT(relit_unmatched(fit), blocks.size() / 2) << "a cut's means follow no law";
}

FrameView colour_only(const RawFrame& f) {
    FrameView v = f.view();
    v.mv = {};
    v.depth = {};
    return v;
}

FrameFormat colour_only_format() {
    FrameFormat format = internal_format(kW, kH);
    format.has_vectors = false;
    format.has_depth = false;
    return format;
}

// The same in sessions without vectors (an unmodified application through the layer), where block
// matching's finest level decides (ref::summarise_motion, with the stage's build on the matched
// vectors, match.comp FGSR_MATCH_CUT): one-frame flashes are no cut and every pair is generated.
// A gain of the light (1.2, 1.4) or a small lift (0.1 in linear light) is matched as such once the
// previous frame's luma takes the lighting gain (shaders/luma.h); a larger lift (0.16) and a haze
// (half the contrast, a lift of 0.1) still leave block matching's SAD alone enough blocks
// unmatched to cut, and the relit count keeps them (the stage is exercised). The GPU's share
// equals the CPU reference's (the whole estimation on the same ingested frames, temporal
// candidates included) to a block at every frame. A cut under changing light is still a cut.
TEST(Cut, ColourOnlyLightingChangeIsNoCut) {
    const Pan scene{.seed = 9, .velocity = glm::vec2(3.f, 1.f), .occluder = true};
    const float alpha = 0.5f;
    struct Flash {
        glm::vec2 light; // (gain, lift)
        bool relit;      // block matching's SAD alone cuts it
    };
    for (Flash flash : {Flash{{1.f, 0.1f}, false}, Flash{{1.2f, 0.f}, false}, Flash{{1.4f, 0.f}, false},
                        Flash{{1.f, 0.16f}, true}, Flash{{0.5f, 0.1f}, true}}) {
        SCOPED_TRACE("a flash of gain " + std::to_string(flash.light.x) + ", lift " +
                     std::to_string(flash.light.y));
        Pan lit = scene;
        lit.light = [flash](int t) { return t == 4 ? flash.light : glm::vec2(1.f, 0.f); };
        auto s = engine().create_session(colour_only_format(), Params{});
        ASSERT_TRUE(s) << s.error().message;
        std::vector<glm::vec4> field; // the CPU reference's, carried from pair to pair as the GPU's
        float typical = -1.f, matched_at_flash = 0.f;
        for (int t = 0; t < 7; ++t) {
            const RawFrame f = lit.frame(t);
            ASSERT_TRUE((*s)->submit(colour_only(f)));
            EXPECT_FALSE((*s)->last_scene_cut()) << "frame " << t;
            if (t == 0) continue;
            EXPECT_TRUE((*s)->interpolate(std::span<const float>(&alpha, 1))) << "frame " << t;
            auto cur = (*s)->read_frame(1), prev = (*s)->read_frame(0);
            ASSERT_TRUE(cur && prev);
            ref::InternalFrame c0 = to_internal(*prev, kW, kH), c1 = to_internal(*cur, kW, kH);
            c1.has_mv = false;
            const ref::MotionSummary cpu = ref::estimate_motion(c0, c1, true, field, {}, false, typical);
            typical = ref::update_typical_share(typical, cpu.mismatch_share, cpu.cut);
            const float block = 1.f / float(ref::cut_blocks(kW, kH));
            EXPECT_NEAR((*s)->last_cut_share(), cpu.mismatch_share, block + 1e-6f) << "frame " << t;
            if (t == 4) matched_at_flash = cpu.matched_share;
        }
        if (flash.relit) {
            EXPECT_GT(matched_at_flash, ref::kCutShare) << "block matching's SAD alone cut (3 x typical is less)";
        } else {
            EXPECT_LT(matched_at_flash, ref::kCutShare) << "matched under the lighting gain";
        }
    }
    const Pan a{.seed = 3, .velocity = glm::vec2(5.f, 2.f)};
    for (float gain : {2.f, 0.5f}) {
        SCOPED_TRACE("scene B at gain " + std::to_string(gain));
        Pan b{.seed = 41, .start = glm::vec2(400.f, -300.f), .velocity = glm::vec2(-3.f, 4.f)};
        b.light = [gain](int) { return glm::vec2(gain, 0.f); };
        auto s = engine().create_session(colour_only_format(), Params{});
        ASSERT_TRUE(s);
        for (int t = 0; t < 4; ++t) ASSERT_TRUE((*s)->submit(colour_only(a.frame(t))));
        EXPECT_FALSE((*s)->last_scene_cut());
        ASSERT_TRUE((*s)->submit(colour_only(b.frame(4))));
        EXPECT_TRUE((*s)->last_scene_cut());
    }
    expect_no_validation_errors();
}

// A fade, out to black or in from it, in a session without vectors: the previous frame's luma
// takes the lighting gain (shaders/luma.h), so block matching still finds the scene's motion at
// every step, and no step is a cut until the frame is black. Fades over 4, 6 and 10 frames after
// three steady ones (light = 1 - (t - 3) / n), and in from 2 % over 4 and 6 frames. Ground truth:
// the pan's vectors, away from the occluder and 8 px from the border (the scene enters there).
// Without the gain the vectors strayed by 0.5-18 px on average from a fade's first step on, and
// the fades over 4 and 6 frames were cut at their second or fourth step, the fades in at their
// first. The gain is 1 on the steady frames, and the GPU's equals the CPU reference's (the same
// histogram on the same pyramids) at every frame.
TEST(Cut, ColourOnlyFadeKeepsTheVectors) {
    struct Fade {
        int frames;
        bool in;
    };
    for (Fade fade : {Fade{4, false}, Fade{6, false}, Fade{10, false}, Fade{4, true}, Fade{6, true}}) {
        SCOPED_TRACE(std::string(fade.in ? "in" : "out") + " over " + std::to_string(fade.frames) +
                     " frames");
        Pan scene{.seed = 9, .velocity = glm::vec2(3.f, 1.f), .occluder = true};
        scene.light = [fade](int t) {
            const float f =
                fade.in ? float(t - 1) / float(fade.frames) : 1.f - float(t - 3) / float(fade.frames);
            return glm::vec2(std::clamp(f, fade.in ? 0.02f : 0.f, 1.f), 0.f);
        };
        const int last = fade.frames + 2; // out: the frame before black; in: one steady frame after
        auto s = engine().create_session(colour_only_format(), Params{});
        ASSERT_TRUE(s) << s.error().message;
        const std::vector<ref::MotionLevel> levels = ref::motion_levels(kW, kH);
        int measured = 0;
        for (int t = 0; t <= last; ++t) {
            ASSERT_TRUE((*s)->submit(colour_only(scene.frame(t))));
            EXPECT_FALSE((*s)->last_scene_cut()) << "frame " << t;
            if (t == 0) continue;
            auto cur = (*s)->read_frame(1), prev = (*s)->read_frame(0);
            ASSERT_TRUE(cur && prev);
            const float gain =
                ref::luma_gain_of(ref::luma_pyramid(to_internal(*cur, kW, kH), levels),
                                  ref::luma_pyramid(to_internal(*prev, kW, kH), levels), levels);
            EXPECT_NEAR((*s)->last_lighting_gain(), gain, 1e-6f) << "frame " << t;
            const bool steady = scene.light(t) == scene.light(t - 1);
            if (steady) {
                EXPECT_EQ((*s)->last_lighting_gain(), 1.f) << "frame " << t;
            }
            measured += gain != 1.f;
            double error = 0;
            size_t n = 0;
            for (uint32_t y = 8; y < kH - 8; ++y)
                for (uint32_t x = 8; x < kW - 8; ++x) {
                    const glm::vec2 c(float(x) + 0.5f, float(y) + 0.5f);
                    if (scene.on_square(c, float(t)) || scene.on_square(c, float(t - 1))) continue;
                    const size_t i = size_t(y) * kW + x;
                    const glm::vec2 mv(cur->mv[2 * i], cur->mv[2 * i + 1]);
                    error += glm::length(mv - (scene.offset(float(t)) - scene.offset(float(t - 1))));
                    ++n;
                }
            EXPECT_LT(error / double(n), 0.15)
                << "frame " << t << ": mean vector error (px) of the background";
        }
        EXPECT_GE(measured, fade.frames - 2) << "steps of the fade that measured a gain";
    }
    expect_no_validation_errors();
}

} // namespace
} // namespace fgsr::test
