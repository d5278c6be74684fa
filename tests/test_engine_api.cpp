// The engine's public surface: bad input gets a clear error and leaves the session usable,
// non-finite data never reaches the output, conventions convert as declared, several alphas per
// call equal single calls, and device selection by index or name.
#include "engine_fixture.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <thread>

namespace fgsr::test {
namespace {

constexpr uint32_t W = 40, H = 24;

std::unique_ptr<Session> session(const FrameFormat& f = internal_format(W, H), const Params& p = {}) {
    auto s = engine().create_session(f, p);
    EXPECT_TRUE(s) << s.error().message;
    return s ? std::move(*s) : nullptr;
}

// Engine::warm_up runs every session it describes to the end: two colour-only kinds and one with
// vectors; the full ones over a still and a panning background, three pairs each, every pair
// interpolating and extrapolating 1, 2 and 3 frames (2 x 3 x 6 x 2 = 72 frames); the half-float
// colour-only kind one pair, one frame each way (2); super resolution x2 over both backgrounds,
// the super-resolved frame of each of 4 submits and one frame each way at 3 pairs (2 x 10 = 20).
// Sessions made afterwards work as before.
TEST(EngineApi, WarmUpGeneratesEveryFrameOfItsSessions) {
    auto warmed = engine().warm_up();
    ASSERT_TRUE(warmed) << warmed.error().message;
    EXPECT_EQ(*warmed, 20u + 72u + 2u + 72u);
    auto s = session();
    ASSERT_TRUE(s);
    const std::vector<float> grey(size_t(W) * H * 4, 0.5f);
    const std::vector<float> depth(size_t(W) * H, 1.0f);
    const std::vector<float> mv(size_t(W) * H * 2, 0.0f);
    FrameView v;
    v.color = std::as_bytes(std::span(grey));
    v.depth = std::as_bytes(std::span(depth));
    v.mv = std::as_bytes(std::span(mv));
    ASSERT_TRUE(s->submit(v));
    ASSERT_TRUE(s->submit(v));
    const float half = 0.5f;
    auto out = s->interpolate(std::span(&half, 1));
    ASSERT_TRUE(out) << out.error().message;
    ASSERT_EQ(out->size(), 1u);
    for (size_t i = 0; i < (*out)[0].color.rgba.size(); i += 4) // two grey frames: grey between
        ASSERT_NEAR((*out)[0].color.rgba[i], 0.5f, 1e-3f) << i / 4;
}

// Pipelines are created at their first use (fgsrd listens at once; a process makes only those its
// sessions need), and warm_up creates every one.
TEST(EngineApi, PipelinesAreCreatedAtFirstUseAndAllByWarmUp) {
    auto e = Engine::create();
    ASSERT_TRUE(e) << e.error().message;
    EXPECT_EQ((*e)->pipelines_created(), 0u);
    auto s = (*e)->create_session(internal_format(W, H), given_field());
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ((*e)->pipelines_created(), 0u) << "a session alone dispatches nothing";
    const RawFrame f0 = random_frame(W, H, 1, 3.0f), f1 = random_frame(W, H, 2, 3.0f);
    ASSERT_TRUE((*s)->submit(f0.view()));
    ASSERT_TRUE((*s)->submit(f1.view()));
    const float half = 0.5f;
    ASSERT_TRUE((*s)->interpolate(std::span(&half, 1)));
    const uint32_t used = (*e)->pipelines_created();
    EXPECT_GT(used, 0u);
    EXPECT_LT(used, Engine::pipeline_variants() / 2) << "one interpolation needs a few of the variants";
    auto warmed = (*e)->warm_up();
    ASSERT_TRUE(warmed) << warmed.error().message;
    EXPECT_EQ((*e)->pipelines_created(), Engine::pipeline_variants());
}

// Sessions of one engine on several threads at once, all asking for the same pipelines first:
// each thread's frames equal those of the same session run alone.
TEST(EngineApi, SessionsOnSeveralThreadsShareTheLazyPipelines) {
    const RawFrame f0 = random_frame(W, H, 3, 4.0f), f1 = random_frame(W, H, 4, 4.0f);
    const std::array<float, 2> alphas{0.25f, 0.5f};
    auto run = [&](Engine& e, std::vector<float>& out) -> std::string {
        auto s = e.create_session(internal_format(W, H));
        if (!s) return s.error().message;
        if (auto r = (*s)->submit(f0.view()); !r) return r.error().message;
        if (auto r = (*s)->submit(f1.view()); !r) return r.error().message;
        auto in = (*s)->interpolate(alphas);
        if (!in) return in.error().message;
        auto ex = (*s)->extrapolate(alphas);
        if (!ex) return ex.error().message;
        for (const auto* frames : {&*in, &*ex})
            for (const auto& g : *frames) out.insert(out.end(), g.color.rgba.begin(), g.color.rgba.end());
        return {};
    };
    auto alone = Engine::create();
    ASSERT_TRUE(alone) << alone.error().message;
    std::vector<float> expected;
    ASSERT_EQ(run(**alone, expected), "");
    ASSERT_FALSE(expected.empty());

    auto shared = Engine::create();
    ASSERT_TRUE(shared) << shared.error().message;
    constexpr int kThreads = 4;
    std::array<std::vector<float>, kThreads> got;
    std::array<std::string, kThreads> errors;
    {
        std::vector<std::jthread> threads;
        for (int t = 0; t < kThreads; ++t)
            threads.emplace_back([&, t] { errors[t] = run(**shared, got[t]); });
    }
    for (int t = 0; t < kThreads; ++t) {
        EXPECT_EQ(errors[t], "") << "thread " << t;
        EXPECT_TRUE(got[t] == expected) << "thread " << t << "'s frames differ from the session run alone";
    }
    EXPECT_EQ((*shared)->pipelines_created(), (*alone)->pipelines_created());
}

TEST(EngineApi, CreateSessionRejectsBadFormats) {
    FrameFormat f = internal_format(0, 10);
    auto r = engine().create_session(f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::empty_input);
    EXPECT_NE(r.error().message.find("0x10"), std::string::npos) << r.error().message;

    f = internal_format(20000, 10);
    r = engine().create_session(f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::invalid_argument);

    f = internal_format(W, H);
    f.color_format = ColorFormat(7);
    r = engine().create_session(f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::unsupported);
    EXPECT_NE(r.error().message.find("colour format"), std::string::npos);

    f = internal_format(W, H);
    f.mv_format = MvFormat(9);
    r = engine().create_session(f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::unsupported);

    f = internal_format(W, H);
    f.conventions.depth_kind = DepthKind::device;
    f.conventions.near_plane = 0.f;
    r = engine().create_session(f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::invalid_argument);
    EXPECT_NE(r.error().message.find("near"), std::string::npos);

    f.conventions.near_plane = 1.f;
    f.conventions.far_plane = 0.5f;
    EXPECT_FALSE(engine().create_session(f));
    f.conventions.far_plane = std::numeric_limits<float>::infinity(); // infinite far plane is fine
    EXPECT_TRUE(engine().create_session(f));
}

TEST(EngineApi, SubmitRejectsBadPlanesAndKeepsTheSession) {
    auto s = session();
    RawFrame good = random_frame(W, H, 1, 3.f);
    ASSERT_TRUE(s->submit(good.view()));

    RawFrame bad = good;
    bad.color.resize(bad.color.size() - 16);
    auto r = s->submit(bad.view());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::size_mismatch);
    EXPECT_NE(r.error().message.find("colour"), std::string::npos) << r.error().message;

    bad = good;
    bad.depth.clear();
    r = s->submit(bad.view());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::empty_input);
    EXPECT_NE(r.error().message.find("depth"), std::string::npos);

    bad = good;
    bad.mv.resize(8);
    r = s->submit(bad.view());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::size_mismatch);
    EXPECT_NE(r.error().message.find("motion"), std::string::npos);

    EXPECT_EQ(s->frames_submitted(), 1u) << "rejected frames must not count";
    const float a[] = {0.5f};
    auto early = s->interpolate(a);
    ASSERT_FALSE(early);
    EXPECT_EQ(early.error().code, Errc::empty_input);

    ASSERT_TRUE(s->submit(random_frame(W, H, 2, 3.f).view()));
    EXPECT_TRUE(s->interpolate(a)) << "the session goes on after rejected frames";
    expect_no_validation_errors();
}

// The correction of given vectors: its parameters are range-checked, and it is refused with super
// resolution (scale > 1), where it measured worse on every capture (docs/ACCURACY.md, change 4).
TEST(EngineApi, VectorCorrectionParametersAreChecked) {
    const FrameFormat f = internal_format(W, H);
    Params p;
    p.correct_vectors = true;
    EXPECT_TRUE(engine().create_session(f, p));
    for (int k = 0; k < 5; ++k) {
        Params q = p;
        if (k == 0) q.correct_ratio = 1.5f;
        if (k == 1) q.correct_margin = -0.1f;
        if (k == 2) q.correct_depth = std::numeric_limits<float>::quiet_NaN();
        if (k == 3) q.scale = 2.f;
        if (k == 4) q.correct_front = -0.5f;
        auto r = engine().create_session(f, q);
        ASSERT_FALSE(r) << k;
        EXPECT_EQ(r.error().code, Errc::invalid_argument) << k;
        EXPECT_NE(r.error().message.find("correct"), std::string::npos) << r.error().message;
    }
    p.correct_vectors = false;
    p.scale = 2.f;
    EXPECT_TRUE(engine().create_session(f, p)) << "SR without the correction";
}

TEST(EngineApi, AlphaOutOfRangeIsRejected) {
    auto s = session();
    ASSERT_TRUE(s->submit(random_frame(W, H, 1, 3.f).view()));
    ASSERT_TRUE(s->submit(random_frame(W, H, 2, 3.f).view()));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (float a : {0.f, 1.f, -0.1f, 1.5f, nan}) {
        const float list[] = {0.5f, a};
        auto r = s->interpolate(list);
        ASSERT_FALSE(r) << a;
        EXPECT_EQ(r.error().code, Errc::invalid_argument);
        EXPECT_NE(r.error().message.find("alpha"), std::string::npos);
    }
    for (float a : {0.f, 1.0001f, -1.f, nan}) {
        const float list[] = {a};
        EXPECT_FALSE(s->extrapolate(list)) << a;
    }
    const float one[] = {1.f};
    EXPECT_TRUE(s->extrapolate(one)) << "extrapolation reaches 1 + 1";
    EXPECT_FALSE(s->interpolate(std::span<const float>())) << "no alpha";
    std::vector<float> many(65, 0.5f);
    EXPECT_FALSE(s->interpolate(many)) << "more than 64 alphas per call";
}

TEST(EngineApi, NonFiniteInputsNeverReachTheOutput) {
    const size_t n = size_t(W) * H;
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float denorm = std::numeric_limits<float>::denorm_min();
    for (bool separate : {false, true}) {
        Params p;
        p.separate_passes = separate;
        auto s = session(internal_format(W, H), p);
        for (uint32_t seed = 1; seed <= 3; ++seed) {
            std::vector<glm::vec4> c(n, glm::vec4(0.5f));
            std::vector<float> d(n, 10.f);
            std::vector<glm::vec2> m(n, glm::vec2(2.f, -1.f));
            const float bad[] = {nan, inf, -inf, denorm, -denorm, 1e30f, -1e30f, 0.f};
            for (size_t i = 0; i < n; i += 3) {
                float v = bad[(i / 3 + seed) % 8];
                c[i] = glm::vec4(v, 0.2f, v, v);
                d[i] = v;
                d[(i + 1) % n] = -v;
                m[i] = glm::vec2(v, -v);
                m[(i + 2) % n] = glm::vec2(1e7f, -1e7f);
            }
            ASSERT_TRUE(s->submit(make_raw(c, d, m).view()));
        }
        const float alphas[] = {1e-6f, 0.5f, 1.f - 1e-6f};
        for (bool extrap : {false, true}) {
            auto out = extrap ? s->extrapolate(alphas) : s->interpolate(alphas);
            ASSERT_TRUE(out) << out.error().message;
            for (const GeneratedFrame& f : *out)
                for (float v : f.color.rgba) ASSERT_TRUE(std::isfinite(v)) << (extrap ? "extrap" : "interp");
        }
    }
    expect_no_validation_errors();
}

// Also across splat's multi-alpha chunks (FGSR_SPLAT_ALPHAS frames per splat dispatch without
// tiles: 6 alphas are a chunk of 4 and one of 2), fused and separate passes, tiled or not, with
// uniform acceleration and with uniform velocity (splat's builds without the frame-0 lookup).
TEST(EngineApi, SeveralAlphasInOneCallEqualSingleCalls) {
    for (int variant = 0; variant < 6; ++variant) {
        SCOPED_TRACE(variant);
        Params p;
        p.skip_tiles = variant % 3 == 0;
        p.separate_passes = variant % 3 == 2;
        p.motion = variant < 3 ? MotionModel::quadratic : MotionModel::linear;
        auto s = session(internal_format(W, H), p);
        ASSERT_TRUE(s->submit(random_frame(W, H, 5, 6.f).view()));
        ASSERT_TRUE(s->submit(random_frame(W, H, 6, 6.f).view()));
        const float alphas[] = {0.1f, 0.2f, 0.35f, 0.5f, 0.65f, 0.8f};
        constexpr size_t count = std::size(alphas);
        for (bool extrap : {false, true}) {
            auto all = extrap ? s->extrapolate(alphas) : s->interpolate(alphas);
            ASSERT_TRUE(all);
            ASSERT_EQ(all->size(), count);
            for (size_t k = 0; k < count; ++k) {
                const float one[] = {alphas[k]};
                auto single = extrap ? s->extrapolate(one) : s->interpolate(one);
                ASSERT_TRUE(single);
                EXPECT_FLOAT_EQ((*all)[k].time, extrap ? 1.f + alphas[k] : alphas[k]);
                EXPECT_EQ((*all)[k].color.rgba, (*single)[0].color.rgba) << "alpha " << alphas[k];
                EXPECT_GT((*all)[k].gpu_ms, 0.0);
            }
            EXPECT_NE((*all)[0].color.rgba, (*all)[2].color.rgba) << "different alphas give different frames";
        }
    }
}

// Declared conventions convert to the internal one (checked against values computed here).
TEST(EngineApi, ConventionsConvertAsDeclared) {
    const size_t n = size_t(W) * H;
    const float near = 0.5f, far = 200.f;
    std::vector<float> linear(n), dev(n), rev(n), rev_inf(n);
    std::vector<glm::vec2> mv(n);
    for (size_t i = 0; i < n; ++i) {
        linear[i] = 1.f + float(i % 97);
        // Standard perspective depth: d = far (z - near) / (z (far - near)).
        dev[i] = far * (linear[i] - near) / (linear[i] * (far - near));
        rev[i] = near * (far - linear[i]) / (linear[i] * (far - near));
        rev_inf[i] = near / linear[i];
        mv[i] = glm::vec2(float(i % 7) - 3.f, float(i % 5) - 2.f); // internal: pixels, to previous, y down
    }
    std::vector<glm::vec4> c(n, glm::vec4(0.25f));
    struct Case {
        DepthKind kind;
        float far_plane;
        const std::vector<float>* depth;
        MvUnits units;
        MvDirection dir;
        bool y_up;
    };
    const Case cases[] = {
        {DepthKind::linear, far, &linear, MvUnits::pixels, MvDirection::to_previous, false},
        {DepthKind::device, far, &dev, MvUnits::uv, MvDirection::from_previous, true},
        {DepthKind::device_reversed, far, &rev, MvUnits::pixels, MvDirection::from_previous, false},
        {DepthKind::device_reversed, std::numeric_limits<float>::infinity(), &rev_inf, MvUnits::uv,
         MvDirection::to_previous, true},
    };
    for (const Case& k : cases) {
        FrameFormat f = internal_format(W, H);
        f.conventions = Conventions{k.kind, near, k.far_plane, k.units, k.dir, k.y_up};
        std::vector<glm::vec2> declared(n);
        for (size_t i = 0; i < n; ++i) {
            glm::vec2 v = mv[i];
            if (k.dir == MvDirection::from_previous) v = -v;
            if (k.y_up) v.y = -v.y;
            if (k.units == MvUnits::uv) v /= glm::vec2(W, H);
            declared[i] = v;
        }
        auto s = session(f);
        ASSERT_TRUE(s->submit(make_raw(c, *k.depth, declared).view()));
        auto got = s->read_frame(1);
        ASSERT_TRUE(got);
        for (size_t i = 0; i < n; ++i) {
            ASSERT_NEAR(got->depth[i], linear[i], 2e-3f * linear[i])
                << "depth kind " << int(k.kind) << " pixel " << i;
            ASSERT_NEAR(got->mv[2 * i], mv[i].x, 1e-4f);
            ASSERT_NEAR(got->mv[2 * i + 1], mv[i].y, 1e-4f);
        }
    }
}

TEST(EngineApi, DeviceSelection) {
    auto list = Engine::list_devices();
    ASSERT_TRUE(list);
    ASSERT_FALSE(list->empty());
    auto missing = Engine::create(DeviceOptions{"no-such-device-anywhere", false});
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, Errc::no_device);
    EXPECT_NE(missing.error().message.find("0: "), std::string::npos) << "the error lists the devices";
    auto by_index = Engine::create(DeviceOptions{"0", false});
    ASSERT_TRUE(by_index) << by_index.error().message;
    auto by_name = Engine::create(DeviceOptions{by_index.value()->device_name().substr(0, 4), false});
    ASSERT_TRUE(by_name) << by_name.error().message;
    EXPECT_EQ(by_name.value()->device_name(), by_index.value()->device_name());
}

} // namespace
} // namespace fgsr::test
