// The numerical stress cases (fgsr/capture/stress.hpp) in their reduced form: every case must
// pass (no crash, every output and ingested value finite, every rejection with a stated reason,
// the session working after it, no validation error), plus checks of the table itself.
#include "engine_fixture.hpp"

#include <fgsr/capture/stress.hpp>

#include <cmath>
#include <cstring>
#include <set>

namespace fgsr::test {
namespace {

std::vector<stress::Case> reduced_cases() {
    stress::CaseOptions o;
    o.reduced = true;
    o.sr_frames = 300;
    return stress::make_cases(o);
}

// The colour-only scene cut (also run here) has its own test naming the invariant.
constexpr const char* kColourCut = "colour-only/scene-cut";

TEST(Stress, EveryCasePasses) {
    const std::vector<stress::Case> cases = reduced_cases();
    size_t rejections = 0, outputs = 0;
    for (const stress::Case& c : cases) {
        const stress::CaseResult r = stress::run_on_engine(engine(), c);
        EXPECT_TRUE(r.pass) << c.name << ": " << r.failure;
        EXPECT_EQ(r.steps_run, c.reject_session.empty() ? c.step_count : 0) << c.name;
        for (const std::string& why : r.rejections) EXPECT_FALSE(why.empty()) << c.name;
        rejections += r.rejections.size();
        outputs += r.outputs_checked;
        if (r.drift_db) std::printf("[ measured ] %s: drift %.2f dB\n", c.name.c_str(), *r.drift_db);
    }
    std::printf("[ measured ] %zu cases, %zu outputs checked finite, %zu rejections with reasons\n",
                cases.size(), outputs, rejections);
    expect_no_validation_errors();
}

// The table covers what the issue lists, each name once.
TEST(Stress, TableCoversTheIssue) {
    const std::vector<stress::Case> cases = reduced_cases();
    std::set<std::string> names;
    for (const stress::Case& c : cases) EXPECT_TRUE(names.insert(c.name).second) << "duplicate " << c.name;
    for (const char* expected : {"colour/rgba16f_linear/nan",
                                 "colour/rgba32f_linear/+inf",
                                 "colour/rgba8_srgb/extremes",
                                 "colour/rgba32f_linear/denormal",
                                 "depth/reversed-infinite/specials",
                                 "depth/device/far-everywhere",
                                 "depth/ties-converging",
                                 "mv/rg16f/1e6-as-half",
                                 "mv/rg32f/-1e6",
                                 "mv/rg32f/off-screen",
                                 "alpha/extremes",
                                 "resolution/1x1",
                                 "resolution/1x7",
                                 "resolution/37x23",
                                 "resolution/8192x8",
                                 "scene-cut/reset-every-frame/sr",
                                 "scene-cut/no-vectors-every-frame",
                                 "reject/session/zero-width",
                                 "reject/plane/colour-short",
                                 "reject/alpha/interpolate",
                                 "reject/session/scale-5",
                                 "reject/session/lut-nan",
                                 "sr-long/static-loop",
                                 "colour-only/flat",
                                 "colour-only/noise/sr",
                                 "colour-only/scene-cut",
                                 "colour-only/pan-216px",
                                 "colour-only/pan-diagonal-quarter",
                                 "colour-only/fast/flat-changing",
                                 "colour-only/fast/noise",
                                 "colour-only/searched/flat-changing",
                                 "colour-only/searched/noise",
                                 "colour-only/searched/pan-specials",
                                 "corrected/flat-changing",
                                 "corrected/noise",
                                 "corrected/pan-216px"})
        EXPECT_TRUE(names.count(expected)) << "missing case " << expected;
}

// Colour-only cases withhold vectors and depth (format and every frame), and the pans are what the
// issue asks for: at 480x270, 200+ px per frame and more than a quarter of the frame.
TEST(Stress, ColourOnlyCasesWithholdVectorsAndDepth) {
    size_t colour_cases = 0;
    for (const stress::Case& c : reduced_cases()) {
        if (c.name.rfind("colour-only/", 0) != 0) continue;
        ++colour_cases;
        EXPECT_FALSE(c.format.has_vectors) << c.name;
        EXPECT_FALSE(c.format.has_depth) << c.name;
        EXPECT_GT(c.max_seconds, 0.0) << c.name << ": bounded in time";
        // The fast/ cases, and only they, estimate motion without refinement.
        EXPECT_EQ(c.params.fast_motion, c.name.rfind("colour-only/fast/", 0) == 0) << c.name;
        // The searched/ cases reach the patch inverse search on a level.
        if (c.name.rfind("colour-only/searched/", 0) == 0) {
            EXPECT_TRUE(c.params.motion_search) << c.name;
            EXPECT_TRUE(
                fgsr::ref::searches_level(fgsr::ref::motion_levels(c.format.width, c.format.height), 1))
                << c.name;
        }
        std::vector<std::vector<std::byte>> colours;
        for (size_t i = 0; i < c.step_count; ++i) {
            const stress::Step st = c.step(i);
            if (st.op != stress::Op::submit) continue;
            EXPECT_TRUE(st.frame.mv.empty()) << c.name << " step " << i;
            EXPECT_TRUE(st.frame.depth.empty()) << c.name << " step " << i;
            EXPECT_FALSE(st.frame.reset) << c.name << ": cuts are not flagged";
            colours.push_back(st.frame.color);
        }
        if (c.name.rfind("colour-only/pan", 0) == 0) {
            ASSERT_EQ(c.format.width, 480u);
            ASSERT_EQ(c.format.height, 270u);
            ASSERT_GE(colours.size(), 2u);
            // The content moves: frame 1 is frame 0 shifted by the pan (rgba16f: 8 bytes per pixel).
            const size_t row = size_t(c.format.width) * 8;
            const bool diagonal = c.name.find("diagonal") != std::string::npos;
            const size_t dx = diagonal ? 130 : 216, dy = diagonal ? 72 : 0;
            EXPECT_GT(dx, c.format.width / 4) << c.name;
            if (diagonal) {
                EXPECT_GT(dy, c.format.height / 4) << c.name;
            } else {
                EXPECT_GE(dx, 200u) << c.name;
            }
            // Pan (dx, dy) to the right/left: frame1(x, y) = frame0(x + dx, y) for 216 px right;
            // (x - 130, y + 72) for the diagonal one.
            const uint32_t x1 = diagonal ? 200 : 10, y1 = diagonal ? 10 : 100;
            const uint32_t x0 = diagonal ? x1 - 130 : x1 + 216, y0 = y1 + uint32_t(dy);
            EXPECT_EQ(std::memcmp(colours[1].data() + y1 * row + x1 * 8,
                                  colours[0].data() + y0 * row + x0 * 8, 64 * 8),
                      0)
                << c.name;
        }
    }
    EXPECT_EQ(colour_cases, 14u);
}

// The corrected-vectors cases give zero vectors and depth with every frame and turn the correction
// on (Params::correct_vectors), so EveryCasePasses checks its outputs and corrected vectors.
TEST(Stress, CorrectedCasesGiveVectorsAndCorrectThem) {
    size_t cases = 0;
    for (const stress::Case& c : reduced_cases()) {
        if (c.name.rfind("corrected/", 0) != 0) continue;
        ++cases;
        EXPECT_TRUE(c.format.has_vectors && c.format.has_depth) << c.name;
        EXPECT_TRUE(c.params.correct_vectors) << c.name;
        for (size_t i = 0; i < c.step_count; ++i) {
            const stress::Step st = c.step(i);
            if (st.op != stress::Op::submit) continue;
            EXPECT_EQ(st.frame.mv.size(), size_t(c.format.width) * c.format.height * 8) << c.name;
            EXPECT_EQ(st.frame.depth.size(), size_t(c.format.width) * c.format.height * 4) << c.name;
        }
    }
    EXPECT_EQ(cases, 3u);
}

// The agreeing cases give zero vectors and depth with every frame and turn colour_agree on, so
// EveryCasePasses runs the agree pass on them, at sizes whose sides hold no full segment of its box
// stages and at ones whose last segment is partial; four of them with super resolution (/sr: ESR
// from both fields, change 45) at scales 1.5, 2 and 3.
TEST(Stress, AgreeingCasesGiveVectorsAndAgree) {
    size_t cases = 0, partial = 0, upscaled = 0;
    for (const stress::Case& c : reduced_cases()) {
        if (c.name.rfind("agreeing/", 0) != 0) continue;
        ++cases;
        EXPECT_TRUE(c.format.has_vectors && c.format.has_depth) << c.name;
        EXPECT_TRUE(c.params.colour_agree) << c.name;
        EXPECT_FALSE(c.params.correct_vectors) << c.name;
        const bool sr = c.name.size() > 3 && c.name.compare(c.name.size() - 3, 3, "/sr") == 0;
        EXPECT_EQ(c.params.scale > 1.f, sr) << c.name;
        upscaled += sr ? 1u : 0u;
        partial += c.format.width % AGREE_SEGMENT != 0 && c.format.height % AGREE_SEGMENT != 0 ? 1u : 0u;
        for (size_t i = 0; i < c.step_count; ++i) {
            const stress::Step st = c.step(i);
            if (st.op != stress::Op::submit) continue;
            EXPECT_EQ(st.frame.mv.size(), size_t(c.format.width) * c.format.height * 8) << c.name;
        }
    }
    EXPECT_EQ(cases, 12u);
    EXPECT_EQ(upscaled, 4u);
    EXPECT_GE(partial, 7u);
}

// The check across a cut (Step::across_cut) holds the engine to "no warp across a cut": a session
// given two unrelated scenes with zero vectors and no reset blends them, which must fail; the same
// with the second frame flagged as a cut is refused with the reset's reason, which passes.
TEST(Stress, AcrossCutCheckDetectsBlends) {
    auto frame = [](uint32_t seed, bool reset) {
        RawFrame f = random_frame(24, 16, seed, 0.f);
        std::vector<float> zero(24 * 16 * 2, 0.f);
        f.mv = bytes_of(zero);
        stress::Frame fr{f.color, f.depth, f.mv};
        fr.reset = reset;
        return fr;
    };
    for (bool reset : {false, true}) {
        stress::Case c;
        c.name = reset ? "across-cut/flagged" : "across-cut/unflagged";
        c.format = internal_format(24, 16);
        c.cpu_reference = false;
        c.step_count = 3;
        c.step = [=](size_t i) {
            stress::Step s;
            if (i < 2) {
                s.frame = frame(uint32_t(100 + 7 * i), reset && i == 1);
                return s;
            }
            s.op = stress::Op::interpolate;
            s.alphas = {0.5f};
            s.across_cut = true;
            return s;
        };
        const stress::CaseResult r = stress::run_on_engine(engine(), c);
        if (reset) {
            EXPECT_TRUE(r.pass) << r.failure;
            ASSERT_EQ(r.rejections.size(), 1u);
            EXPECT_NE(r.rejections[0].find("needs two submitted frames"), std::string::npos)
                << r.rejections[0];
        } else {
            EXPECT_FALSE(r.pass);
            EXPECT_NE(r.failure.find("neither frame"), std::string::npos) << r.failure;
        }
    }
}

// Across an unflagged cut a colour-only session must not warp or blend the two scenes (issue 12:
// the engine detects the cut from colour and restarts, as after FrameView::reset).
TEST(Stress, ColourOnlyCutIsNotWarpedAcross) {
    for (const stress::Case& c : reduced_cases()) {
        if (c.name != kColourCut) continue;
        const stress::CaseResult r = stress::run_on_engine(engine(), c);
        EXPECT_TRUE(r.pass) << c.name << ": " << r.failure;
        return;
    }
    FAIL() << kColourCut << " is not in the table";
}

// The feeder reports what it finds: a case whose expected rejection is not met fails, and one
// whose output is NaN (a = 1 Eq. 2 with a session set up to produce it is refused now, so feed
// a request the engine accepts and claim it must be rejected) fails with the step named.
TEST(Stress, FeederDetectsFailures) {
    std::vector<stress::Case> cases = reduced_cases();
    auto it = std::find_if(cases.begin(), cases.end(),
                           [](const stress::Case& c) { return c.name == "alpha/extremes"; });
    ASSERT_NE(it, cases.end());
    stress::Case c = *it;
    auto inner = c.step;
    c.step = [inner](size_t i) {
        stress::Step s = inner(i);
        if (i == 2) s.reject = "alpha";
        return s;
    };
    const stress::CaseResult r = stress::run_on_engine(engine(), c);
    EXPECT_FALSE(r.pass);
    EXPECT_NE(r.failure.find("step 2"), std::string::npos) << r.failure;

    stress::Case s = *it;
    s.reject_session = "scale"; // a good session that is claimed to be refused
    EXPECT_FALSE(stress::run_on_engine(engine(), s).pass);
}

// Parameters outside their ranges are refused at creation and ignored by set_params.
TEST(Stress, ParamsAreValidated) {
    Params bad;
    bad.t_depth = std::nanf("");
    auto v = validate(bad);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().message.find("t_depth"), std::string::npos) << v.error().message;
    EXPECT_TRUE(validate(Params{}));

    auto s = engine().create_session(internal_format(8, 8));
    ASSERT_TRUE(s) << s.error().message;
    (*s)->set_params(bad);
    EXPECT_EQ((*s)->params().t_depth, Params{}.t_depth);
    Params good;
    good.t_depth = 0.1f;
    (*s)->set_params(good);
    EXPECT_EQ((*s)->params().t_depth, 0.1f);
}

// Eq. 2 with a = 1 and b so large that no current sample has weight: the SR output stays finite
// (it was 0 / 0 = NaN on 1456 of 3072 output pixels before the guard in shaders/sr.h).
TEST(Stress, SrWithNoWeightedSampleIsFinite) {
    const uint32_t w = 24, h = 16;
    Params p;
    p.scale = 2.f;
    p.sr_a = 1.f;
    p.sr_b = 10.f;
    auto s = engine().create_session(internal_format(w, h), p);
    ASSERT_TRUE(s) << s.error().message;
    for (uint32_t k = 0; k < 3; ++k) {
        RawFrame f = random_frame(w, h, 40 + k, 2.f);
        FrameView v = f.view();
        v.jitter_x = 0.3f * float(k) - 0.3f;
        ASSERT_TRUE((*s)->submit(v));
        auto out = (*s)->super_resolved();
        ASSERT_TRUE(out) << out.error().message;
        size_t bad = 0;
        for (float x : out->color.rgba) bad += std::isfinite(x) ? 0 : 1;
        EXPECT_EQ(bad, 0u) << "frame " << k;
    }
    expect_no_validation_errors();
}

} // namespace
} // namespace fgsr::test
