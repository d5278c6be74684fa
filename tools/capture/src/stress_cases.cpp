// The table of numerical stress cases (make_cases, fgsr/capture/stress.hpp): colour, depth, vector,
// alpha, combined, resolution, scene-cut and rejection cases, and the long SR drift run; the
// colour-only cases are stress_colour.cpp's. Frames, poisons and the step builders come from
// stress_internal.hpp.
#include "stress_internal.hpp"

#include <fgsr/core/halton.hpp>
#include <fgsr/engine/lut.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

namespace fgsr::stress {

namespace {

using namespace detail;

const std::vector<float> kInterpAlphas = {1e-6f, 0.5f, 1.f - 1e-6f};
const std::vector<float> kExtrapAlphas = {1e-6f, 0.5f, 1.f};

// The standard scenario: two frames (both poisoned), every request kind at the extreme alphas,
// then a clean frame and one more interpolation, and another clean frame and interpolation (the
// session recovers from poisoned history). The first clean frame's vectors do not explain its
// colour against a poisoned frame's (sanitised) colour: ingest's cut stage (Params::vector_cuts)
// may take it for a scene cut and restart, so the interpolation after it may be refused as after
// a reset; the one after the second clean frame must succeed either way.
std::vector<StepFn> standard_steps(const FrameFormat& f, float scale, std::vector<Poison> poisons,
                                   glm::vec2 motion, bool with_mv = true) {
    const bool sr = scale > 1.f;
    std::vector<StepFn> s;
    for (int k = 0; k < 2; ++k) {
        s.push_back([=] {
            Frame fr = encode(f, content(f.width, f.height, k, motion), with_mv);
            for (const Poison& p : poisons) apply(fr, f, p);
            fr.jitter_x = k == 0 ? 0.25f : -0.25f;
            fr.jitter_y = k == 0 ? -0.125f : 0.375f;
            return submit(std::move(fr));
        });
        if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
    }
    s.push_back([] { return request(Op::interpolate, kInterpAlphas); });
    s.push_back([] { return request(Op::extrapolate, kExtrapAlphas); });
    for (int k = 2; k < 4; ++k) {
        s.push_back([=] { return submit(encode(f, content(f.width, f.height, k, motion))); });
        if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
        s.push_back([k] {
            Step st = request(Op::interpolate, {0.5f});
            st.cut_allowed = k == 2;
            return st;
        });
    }
    return s;
}

Case standard_case(std::string name, std::string checks, const FrameFormat& f, float scale,
                   Poison poison = {}, glm::vec2 motion = {2.f, 1.f}, bool with_mv = true) {
    Case c;
    c.name = scale > 1.f ? name + "/sr" : std::move(name);
    c.checks = std::move(checks);
    c.format = f;
    c.params = params_of(scale);
    auto steps = standard_steps(f, scale, {std::move(poison)}, motion, with_mv);
    c.step_count = steps.size();
    c.step = sequence(std::move(steps));
    return c;
}

constexpr uint32_t kW = 24, kH = 16; // size of the small cases

void add_color_cases(std::vector<Case>& out) {
    const std::vector<Special> f16 = {{"nan", kNaN, {}},    {"+inf", kInf, {}},
                                      {"-inf", -kInf, {}},  {"denormal", 6e-8f, uint16_t(0x0001)},
                                      {"max", 65504.f, {}}, {"-max", -65504.f, {}}};
    const std::vector<Special> f32 = {{"nan", kNaN, {}},         {"+inf", kInf, {}}, {"-inf", -kInf, {}},
                                      {"denormal", kDenorm, {}}, {"max", kMax, {}},  {"-max", -kMax, {}}};
    for (float scale : {1.f, 2.f}) {
        for (auto [cf, values] :
             {std::pair{ColorFormat::rgba16f_linear, f16}, std::pair{ColorFormat::rgba32f_linear, f32}}) {
            const FrameFormat f = format_of(kW, kH, cf);
            for (const Special& v : values)
                out.push_back(standard_case("colour/" + std::string(to_string(cf)) + "/" + v.name,
                                            std::string("colour channels = ") + v.name +
                                                " on a quarter of the pixels of both frames",
                                            f, scale, Poison{Plane::color, {v}, false}));
            out.push_back(standard_case("colour/" + std::string(to_string(cf)) + "/nan-everywhere",
                                        "every colour channel NaN in both frames", f, scale,
                                        Poison{Plane::color, {{"nan", kNaN, {}}}, true}));
        }
        const FrameFormat f8 = format_of(kW, kH, ColorFormat::rgba8_srgb);
        out.push_back(standard_case("colour/rgba8_srgb/extremes", "bytes 0 and 255 (the format's extremes)",
                                    f8, scale,
                                    Poison{Plane::color, {{"0", 0.f, {}}, {"255", 1.f, {}}}, false}));
    }
}

void add_depth_cases(std::vector<Case>& out) {
    struct Kind {
        const char* name;
        Conventions conv;
    };
    auto conv = [](DepthKind k, float far_plane) {
        Conventions c;
        c.depth_kind = k;
        c.near_plane = 0.1f;
        c.far_plane = far_plane;
        return c;
    };
    const std::vector<Kind> kinds = {{"linear", conv(DepthKind::linear, 1000.f)},
                                     {"device", conv(DepthKind::device, 1000.f)},
                                     {"device-infinite", conv(DepthKind::device, kInf)},
                                     {"device-far0", conv(DepthKind::device, 0.f)},
                                     {"reversed", conv(DepthKind::device_reversed, 1000.f)},
                                     {"reversed-infinite", conv(DepthKind::device_reversed, kInf)}};
    const std::vector<Special> specials = {{"nan", kNaN, {}},
                                           {"+inf", kInf, {}},
                                           {"-inf", -kInf, {}},
                                           {"denormal", kDenorm, {}},
                                           {"-denormal", -kDenorm, {}},
                                           {"0", 0.f, {}},
                                           {"-0", -0.f, {}},
                                           {"-5", -5.f, {}},
                                           {"1", 1.f, {}},
                                           {"2", 2.f, {}},
                                           {"max", kMax, {}}};
    for (float scale : {1.f, 2.f})
        for (const Kind& k : kinds) {
            const FrameFormat f = format_of(kW, kH, ColorFormat::rgba16f_linear, MvFormat::rg32f, k.conv);
            out.push_back(standard_case(std::string("depth/") + k.name + "/specials",
                                        "depth NaN, +-inf, +-denormal, 0, -0, -5, 1, 2, FLT_MAX scattered", f,
                                        scale, Poison{Plane::depth, specials, false}));
            out.push_back(
                standard_case(std::string("depth/") + k.name + "/far-everywhere",
                              "every depth on the far plane (equal depths: atomic tie-break)", f, scale,
                              Poison{Plane::depth, {{"far", far_value(k.conv.depth_kind), {}}}, true}));
        }
    // Equal (invalid or extreme) linear depth everywhere: ties everywhere.
    const std::vector<Special> uniform = {{"0", 0.f, {}},     {"-1", -1.f, {}},          {"nan", kNaN, {}},
                                          {"+inf", kInf, {}}, {"denormal", kDenorm, {}}, {"max", kMax, {}},
                                          {"5", 5.f, {}}};
    for (float scale : {1.f, 2.f})
        for (const Special& v : uniform)
            out.push_back(standard_case(std::string("depth/linear/all-") + v.name,
                                        std::string("every depth = ") + v.name + " (ties everywhere)",
                                        format_of(kW, kH), scale, Poison{Plane::depth, {v}, true}));

    // Depth ties with every frame-1 pixel splatting to one target pixel at alpha 0.5 (heavy
    // atomicMin contention, all on one depth): outputs finite and deterministic.
    for (float scale : {1.f, 2.f}) {
        const FrameFormat f = format_of(kW, kH);
        Case c;
        c.name = scale > 1.f ? "depth/ties-converging/sr" : "depth/ties-converging";
        c.checks =
            "equal depth, every vector converging on one pixel at alpha 0.5; repeated call bit-identical";
        c.format = f;
        c.params = params_of(scale);
        auto frame = [f] {
            Content ct = content(f.width, f.height, 0, {});
            const glm::vec2 centre(float(f.width) * 0.5f, float(f.height) * 0.5f);
            for (uint32_t y = 0; y < f.height; ++y)
                for (uint32_t x = 0; x < f.width; ++x) {
                    const size_t i = size_t(y) * f.width + x;
                    ct.depth[i] = 5.f;
                    ct.mv[i] = 2.f * (centre - glm::vec2(float(x) + 0.5f, float(y) + 0.5f));
                }
            return encode(f, ct);
        };
        std::vector<StepFn> s = {[=] { return submit(frame()); }, [=] { return submit(frame()); },
                                 [] {
                                     return request(Op::interpolate, {0.5f, 0.25f});
                                 },
                                 [] {
                                     Step st = request(Op::interpolate, {0.5f, 0.25f});
                                     st.same_as_previous = true;
                                     return st;
                                 },
                                 [] { return request(Op::extrapolate, {1.f}); }};
        c.step_count = s.size();
        c.step = sequence(std::move(s));
        out.push_back(std::move(c));
    }
}

void add_mv_cases(std::vector<Case>& out) {
    struct V {
        MvFormat fmt;
        Special s;
        bool everywhere;
        const char* what;
    };
    const std::vector<V> values = {
        {MvFormat::rg16f, {"nan", kNaN, {}}, false, "vectors NaN"},
        {MvFormat::rg16f, {"+inf", kInf, {}}, false, "vectors +inf"},
        {MvFormat::rg16f, {"-inf", -kInf, {}}, false, "vectors -inf"},
        {MvFormat::rg16f, {"denormal", 6e-8f, uint16_t(0x0001)}, false, "vectors a half subnormal"},
        {MvFormat::rg16f, {"65504", 65504.f, {}}, false, "vectors at the half maximum 65504"},
        {MvFormat::rg16f, {"-65504", -65504.f, {}}, true, "every vector at -65504"},
        {MvFormat::rg16f,
         {"1e6-as-half", 1.0e6f, {}},
         false,
         "1e6 pixels written as half (+inf: beyond half)"},
        {MvFormat::rg16f, {"65520-as-half", 65520.f, {}}, true, "65520 as half rounds to +inf, everywhere"},
        {MvFormat::rg32f, {"nan", kNaN, {}}, false, "vectors NaN"},
        {MvFormat::rg32f, {"+inf", kInf, {}}, false, "vectors +inf"},
        {MvFormat::rg32f, {"-inf", -kInf, {}}, false, "vectors -inf"},
        {MvFormat::rg32f, {"denormal", kDenorm, {}}, false, "vectors a float subnormal"},
        {MvFormat::rg32f, {"+1e6", 1.0e6f, {}}, false, "vectors +1e6 pixels"},
        {MvFormat::rg32f, {"-1e6", -1.0e6f, {}}, true, "every vector -1e6 pixels"},
        {MvFormat::rg32f, {"max", kMax, {}}, false, "vectors FLT_MAX"},
        {MvFormat::rg32f,
         {"off-screen", 3.f * kW, {}},
         true,
         "every vector 3 widths: everything leaves the screen"},
        {MvFormat::rg32f, {"off-screen-mixed", float(kW) + 0.5f, {}}, false, "vectors of a screen width"},
    };
    for (float scale : {1.f, 2.f}) {
        for (const V& v : values)
            out.push_back(
                standard_case("mv/" + std::string(to_string(v.fmt)) + "/" + v.s.name,
                              std::string(v.what) + (v.everywhere ? "" : " on a quarter of the pixels"),
                              format_of(kW, kH, ColorFormat::rgba16f_linear, v.fmt), scale,
                              Poison{Plane::mv, {v.s}, v.everywhere}));
        Conventions uv;
        uv.mv_units = MvUnits::uv;
        out.push_back(standard_case("mv/rg32f/uv-1e6", "uv-unit vectors of 1e6 (times the width)",
                                    format_of(kW, kH, ColorFormat::rgba16f_linear, MvFormat::rg32f, uv),
                                    scale,
                                    Poison{Plane::mv, {{"1e6", 1.0e6f, {}}, {"-1e6", -1.0e6f, {}}}, false}));
        // Large true motion: the rectangle moves 1e6 pixels per frame (off screen and back).
        out.push_back(standard_case("mv/rg32f/motion-1e6", "true motion of 1e6 pixels per frame",
                                    format_of(kW, kH), scale, {}, {1.0e6f, -1.0e6f}));
    }
}

// Every poison at once (colour NaN / inf / max, depth specials, vector specials) under each
// parameter variant, so that every shader variant (fused and separate passes, each motion model,
// blend mode, history resampling, dilation, jitter compensation) sees them.
void add_combined_cases(std::vector<Case>& out) {
    const std::vector<Poison> all = {
        Poison{Plane::color,
               {{"nan", kNaN, {}}, {"+inf", kInf, {}}, {"max", kMax, {}}, {"denormal", kDenorm, {}}},
               false},
        Poison{Plane::depth,
               {{"nan", kNaN, {}},
                {"-inf", -kInf, {}},
                {"0", 0.f, {}},
                {"denormal", kDenorm, {}},
                {"max", kMax, {}}},
               false},
        Poison{Plane::mv,
               {{"+inf", kInf, {}}, {"nan", kNaN, {}}, {"-1e6", -1.0e6f, {}}, {"denormal", kDenorm, {}}},
               false}};
    struct Variant {
        const char* name;
        float scale;
        std::function<void(Params&)> set;
    };
    const std::vector<Variant> variants = {
        {"default", 1.f, [](Params&) {}},
        {"separate-passes", 1.f, [](Params& p) { p.separate_passes = true; }},
        {"linear-motion", 1.f, [](Params& p) { p.motion = MotionModel::linear; }},
        {"select-blend", 1.f, [](Params& p) { p.blend = BlendMode::select; }},
        {"no-gap-no-hole-fill", 1.f, [](Params& p) { p.fill_gaps = p.fill_holes = false; }},
        {"thresholds-0", 1.f, [](Params& p) { p.t_depth = p.t_bright = 0.f; }},
        {"sr-lut", 2.f, [](Params&) {}},
        {"sr-bilinear", 2.f, [](Params& p) { p.resample = Resample::bilinear; }},
        {"sr-catmull-rom", 2.f, [](Params& p) { p.resample = Resample::catmull_rom; }},
        {"sr-dilate", 2.f, [](Params& p) { p.dilate_mvs = true; }},
        {"sr-jittered-vectors", 2.f, [](Params& p) { p.mvs_contain_jitter = true; }},
        {"sr-a-1-b-10", 2.f, [](Params& p) { p.sr_a = 1.f, p.sr_b = 10.f; }},
        {"sr-a-0", 2.f, [](Params& p) { p.sr_a = 0.f; }},
        {"sr-x4", 4.f, [](Params&) {}},
    };
    for (const Variant& v : variants) {
        const FrameFormat f = format_of(kW, kH);
        Case c;
        c.name = std::string("combined/") + v.name;
        c.checks = "colour, depth and vector poisons at once in both frames";
        c.format = f;
        c.params = params_of(v.scale);
        v.set(c.params);
        auto steps = standard_steps(f, v.scale, all, {2.f, 1.f}, true);
        c.step_count = steps.size();
        c.step = sequence(std::move(steps));
        out.push_back(std::move(c));
    }
}

void add_resolution_cases(std::vector<Case>& out, bool reduced) {
    struct R {
        uint32_t w, h;
        float scale;
    };
    std::vector<R> sizes = {{1, 1, 1.f},   {1, 1, 2.f},    {1, 1, 4.f},    {1, 7, 1.f},     {7, 1, 1.f},
                            {1, 7, 2.f},   {7, 1, 2.f},    {2, 2, 4.f},    {37, 23, 1.f},   {37, 23, 1.5f},
                            {37, 23, 3.f}, {8192, 8, 1.f}, {8, 8192, 1.f}, {16384, 2, 1.f}, {4096, 4, 2.f}};
    if (!reduced) sizes.push_back({1920, 1080, 1.f});
    for (const R& r : sizes) {
        const std::string size = std::to_string(r.w) + "x" + std::to_string(r.h);
        Case c = standard_case("resolution/" + size, size + " frames, every request kind",
                               format_of(r.w, r.h), r.scale, {}, {1.5f, -0.5f});
        if (r.scale > 1.f) {
            char s[16];
            std::snprintf(s, sizeof s, "%.1f", double(r.scale));
            c.name = "resolution/" + size + "/sr-x" + s;
        }
        c.cpu_reference = size_t(r.w) * r.h <= 4096;
        out.push_back(std::move(c));
    }
}

void add_alpha_cases(std::vector<Case>& out) {
    for (float scale : {1.f, 2.f}) {
        const FrameFormat f = format_of(kW, kH);
        Case c;
        c.name = scale > 1.f ? "alpha/extremes/sr" : "alpha/extremes";
        c.checks = "interpolation at 1e-40 (subnormal), FLT_MIN, 1e-6, 1-1e-6, 1-2^-24; extrapolation at "
                   "1e-40, 1e-6, 1; 64 alphas in one call";
        c.format = f;
        c.params = params_of(scale);
        std::vector<float> many(64);
        for (size_t i = 0; i < many.size(); ++i) many[i] = (float(i) + 0.5f) / 64.f;
        std::vector<StepFn> s = {
            [=] {
                return submit(encode(f, content(kW, kH, 0, {2.f, 1.f})));
            },
            [=] {
                return submit(encode(f, content(kW, kH, 1, {2.f, 1.f})));
            },
            [] {
                return request(Op::interpolate, {1e-40f, std::numeric_limits<float>::min(), 1e-6f,
                                                 1.f - 1e-6f, std::nextafter(1.f, 0.f)});
            },
            [] {
                return request(Op::extrapolate, {1e-40f, 1e-6f, 1.f});
            },
            [=] { return request(Op::interpolate, many); },
        };
        c.step_count = s.size();
        c.step = sequence(std::move(s));
        out.push_back(std::move(c));
    }
}

void add_scene_cut_cases(std::vector<Case>& out) {
    constexpr int kFrames = 6;
    for (float scale : {1.f, 2.f}) {
        const bool sr = scale > 1.f;
        const FrameFormat f = format_of(kW, kH);
        const std::string suffix = sr ? "/sr" : "";
        for (int variant = 0; variant < 3; ++variant) {
            const bool reset = variant != 1, with_mv = variant == 0;
            Case c;
            c.name = std::string("scene-cut/") +
                     (variant == 0   ? "reset-every-frame"
                      : variant == 1 ? "no-vectors-every-frame"
                                     : "reset-and-no-vectors") +
                     suffix;
            c.checks =
                reset ? "reset flag on every frame: generation is refused with a reason (no frame pair), "
                        "SR restarts; a normal frame afterwards works"
                      : "no vectors on any frame: every request works";
            c.format = f;
            c.params = params_of(scale);
            std::vector<StepFn> s;
            for (int k = 0; k < kFrames; ++k) {
                s.push_back([=] {
                    Frame fr = encode(f, content(kW, kH, k, {3.f, -1.f}), with_mv);
                    fr.reset = reset;
                    fr.jitter_x = 0.1f * float(k % 3);
                    return submit(std::move(fr));
                });
                if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
                const std::string why = reset || k == 0 ? "needs two submitted frames" : "";
                s.push_back([=] { return request(Op::interpolate, {0.5f}, why); });
                s.push_back([=] { return request(Op::extrapolate, {0.5f}, why); });
            }
            s.push_back([=] { return submit(encode(f, content(kW, kH, kFrames, {3.f, -1.f}))); });
            s.push_back([] { return request(Op::interpolate, {0.5f}); });
            if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
            c.step_count = s.size();
            c.step = sequence(std::move(s));
            out.push_back(std::move(c));
        }
    }
}

void add_rejection_cases(std::vector<Case>& out) {
    // Sessions that must be refused.
    auto session = [&](std::string name, FrameFormat f, Params p, std::string reason) {
        Case c;
        c.name = "reject/session/" + name;
        c.checks = "create_session refused, reason mentions '" + reason +
                   "'; the engine serves a good session after";
        c.format = f;
        c.params = std::move(p);
        c.reject_session = std::move(reason);
        out.push_back(std::move(c));
    };
    session("zero-width", format_of(0, 16), {}, "0x16");
    session("zero-height", format_of(16, 0), {}, "16x0");
    session("too-wide", format_of(16385, 1), {}, "exceeds");
    for (float s : {0.5f, 0.f, -2.f, 4.5f, 5.f, kNaN, kInf}) {
        char n[32];
        std::snprintf(n, sizeof n, "scale-%g", double(s));
        session(n, format_of(16, 16), params_of(s), "scale");
    }
    session("output-too-large", format_of(16384, 1), params_of(2.f), "output size");
    {
        FrameFormat f = format_of(16, 16);
        f.color_format = ColorFormat(7);
        session("colour-format-7", f, {}, "colour format");
        f = format_of(16, 16);
        f.mv_format = MvFormat(9);
        session("mv-format-9", f, {}, "motion-vector format");
        f = format_of(16, 16);
        f.conventions.depth_kind = DepthKind(5);
        session("depth-kind-5", f, {}, "depth kind");
        f = format_of(16, 16);
        f.conventions.mv_units = MvUnits(3);
        session("mv-units-3", f, {}, "units");
        for (auto [name, near_plane, far_plane] :
             {std::tuple{"near-0", 0.f, 100.f}, std::tuple{"near-negative", -1.f, 100.f},
              std::tuple{"near-nan", kNaN, 100.f}, std::tuple{"far-below-near", 10.f, 1.f},
              std::tuple{"far-nan", 0.1f, kNaN}, std::tuple{"far-negative", 0.1f, -100.f}}) {
            f = format_of(16, 16);
            f.conventions.depth_kind = DepthKind::device_reversed;
            f.conventions.near_plane = near_plane;
            f.conventions.far_plane = far_plane;
            session(name, f, {}, "near");
        }
    }
    {
        Params p = params_of(2.f);
        p.lut.assign(100, 0.f);
        session("lut-size", format_of(16, 16), p, "LUT");
        p.lut.assign(kLutSize, kNaN);
        session("lut-nan", format_of(16, 16), p, "LUT");
        p = params_of(2.f);
        p.sr_a = 1.5f;
        session("sr-a-1.5", format_of(16, 16), p, "sr_a");
        p = params_of(2.f);
        p.sr_b = kNaN;
        session("sr-b-nan", format_of(16, 16), p, "sr_b");
        p = {};
        p.t_depth = kNaN;
        session("t-depth-nan", format_of(16, 16), p, "t_depth");
        p = {};
        p.t_bright = -1.f;
        session("t-bright-negative", format_of(16, 16), p, "t_bright");
    }

    // Requests and frames that must be refused by a working session, which must keep working.
    auto steps_case = [&](std::string name, float scale, std::string checks,
                          std::function<std::vector<StepFn>(const FrameFormat&)> bad) {
        const FrameFormat f = format_of(16, 16);
        Case c;
        c.name = "reject/" + name;
        c.checks = std::move(checks) + "; the session works after";
        c.format = f;
        c.params = params_of(scale);
        std::vector<StepFn> s = {[=] {
                                     return submit(encode(f, content(16, 16, 0, {1.f, 1.f})));
                                 },
                                 [=] {
                                     return submit(encode(f, content(16, 16, 1, {1.f, 1.f})));
                                 }};
        for (StepFn& b : bad(f)) s.push_back(std::move(b));
        s.push_back([=] { return submit(encode(f, content(16, 16, 2, {1.f, 1.f}))); });
        s.push_back([] { return request(Op::interpolate, {0.5f}); });
        s.push_back([] { return request(Op::extrapolate, {0.5f}); });
        if (scale > 1.f) s.push_back([] { return request(Op::super_resolve, {}); });
        c.step_count = s.size();
        c.step = sequence(std::move(s));
        out.push_back(std::move(c));
    };
    auto good = [](const FrameFormat& f) { return encode(f, content(f.width, f.height, 1, {1.f, 1.f})); };
    steps_case("plane/colour-short", 1.f, "colour plane one byte short", [=](const FrameFormat& f) {
        return std::vector<StepFn>{[=] {
            Frame fr = good(f);
            fr.color.pop_back();
            return submit(std::move(fr), "colour plane");
        }};
    });
    steps_case("plane/colour-empty", 1.f, "colour plane empty", [=](const FrameFormat& f) {
        return std::vector<StepFn>{[=] {
            Frame fr = good(f);
            fr.color.clear();
            return submit(std::move(fr), "colour plane is empty");
        }};
    });
    steps_case("plane/depth-empty", 1.f, "depth plane empty", [=](const FrameFormat& f) {
        return std::vector<StepFn>{[=] {
            Frame fr = good(f);
            fr.depth.clear();
            return submit(std::move(fr), "depth plane is empty");
        }};
    });
    steps_case("plane/depth-double", 1.f, "depth plane twice the size", [=](const FrameFormat& f) {
        return std::vector<StepFn>{[=] {
            Frame fr = good(f);
            fr.depth.resize(fr.depth.size() * 2);
            return submit(std::move(fr), "depth plane");
        }};
    });
    steps_case("plane/mv-wrong-format", 1.f, "vector plane sized for rg16f in an rg32f session",
               [=](const FrameFormat& f) {
                   return std::vector<StepFn>{[=] {
                       Frame fr = good(f);
                       fr.mv.resize(fr.mv.size() / 2);
                       return submit(std::move(fr), "motion-vector plane");
                   }};
               });
    steps_case("plane/size-of-another-frame", 1.f, "planes of a 17x16 frame", [=](const FrameFormat& f) {
        return std::vector<StepFn>{[=] {
            FrameFormat g = f;
            g.width = 17;
            return submit(encode(g, content(17, 16, 1, {1.f, 1.f})), "expected");
        }};
    });
    steps_case("jitter", 2.f, "jitter NaN, +inf and 2 pixels", [=](const FrameFormat& f) {
        std::vector<StepFn> s;
        for (float j : {kNaN, kInf, 2.f})
            s.push_back([=] {
                Frame fr = good(f);
                fr.jitter_x = j;
                return submit(std::move(fr), "jitter");
            });
        return s;
    });
    steps_case("alpha/interpolate", 1.f, "interpolation at alpha 0, 1, NaN, -0.5, 1.5, +inf, -0",
               [](const FrameFormat&) {
                   std::vector<StepFn> s;
                   for (float a : {0.f, 1.f, kNaN, -0.5f, 1.5f, kInf, -0.f})
                       s.push_back([=] { return request(Op::interpolate, {0.5f, a}, "alpha"); });
                   return s;
               });
    steps_case("alpha/extrapolate", 1.f, "extrapolation at alpha 0, just above 1, NaN, -inf",
               [](const FrameFormat&) {
                   std::vector<StepFn> s;
                   for (float a : {0.f, std::nextafter(1.f, 2.f), kNaN, -kInf})
                       s.push_back([=] { return request(Op::extrapolate, {a}, "alpha"); });
                   return s;
               });
    steps_case("alpha/sr-interpolate", 2.f, "ISR at alpha 1 and NaN", [](const FrameFormat&) {
        return std::vector<StepFn>{[] { return request(Op::interpolate, {1.f}, "alpha"); },
                                   [] { return request(Op::interpolate, {kNaN}, "alpha"); }};
    });
    steps_case("alpha/count", 1.f, "no alpha, and 65 alphas in one call", [](const FrameFormat&) {
        return std::vector<StepFn>{
            [] { return request(Op::interpolate, {}, "no alpha"); },
            [] { return request(Op::interpolate, std::vector<float>(65, 0.5f), "65 alphas"); }};
    });
    steps_case("super-resolve-without-scale", 1.f, "SR output of a session that does not upscale",
               [](const FrameFormat&) {
                   return std::vector<StepFn>{
                       [] { return request(Op::super_resolve, {}, "does not upscale"); }};
               });
    {
        // Requests before enough frames.
        const FrameFormat f = format_of(16, 16);
        Case c;
        c.name = "reject/too-few-frames";
        c.checks = "SR output before any frame, generation with one frame; works after the second frame";
        c.format = f;
        c.params = params_of(2.f);
        std::vector<StepFn> s = {
            [] { return request(Op::super_resolve, {}, "no frame"); },
            [] { return request(Op::interpolate, {0.5f}, "needs two submitted frames"); },
            [=] {
                return submit(encode(f, content(16, 16, 0, {1.f, 0.f})));
            },
            [] { return request(Op::extrapolate, {0.5f}, "needs two submitted frames"); },
            [] { return request(Op::super_resolve, {}); },
            [=] {
                return submit(encode(f, content(16, 16, 1, {1.f, 0.f})));
            },
            [] { return request(Op::interpolate, {0.5f}); },
        };
        c.step_count = s.size();
        c.step = sequence(std::move(s));
        out.push_back(std::move(c));
    }
}

// Static scene sampled with a Halton(2,3) jitter of period 8, looped: SR history must converge and
// stay converged (no drift of the feedback loop over many frames).
Case long_sr_case(size_t frames) {
    constexpr uint32_t w = 32, h = 18;
    constexpr size_t kPeriod = 8;
    const FrameFormat f = format_of(w, h);
    auto loop = std::make_shared<std::vector<Frame>>();
    for (size_t k = 0; k < kPeriod; ++k) {
        const float jx = halton(uint32_t(k) + 1, 2) - 0.5f, jy = halton(uint32_t(k) + 1, 3) - 0.5f;
        Content c = content(w, h, 0, {});
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                // Detail finer than a pixel: fine rings and a sharp diagonal edge.
                const float px = float(x) + 0.5f + jx, py = float(y) + 0.5f + jy;
                const float r = std::hypot(px - 16.f, py - 9.f);
                const float ring = 0.5f + 0.5f * std::sin(r * 2.2f);
                const float edge = px + 0.6f * py > 20.f ? 1.f : 0.2f;
                const size_t i = size_t(y) * w + x;
                c.color[i] = glm::vec4(ring * edge, 0.6f * ring, edge * 0.7f, 1.f);
                c.depth[i] = 10.f;
            }
        Frame fr = encode(f, c);
        fr.jitter_x = jx;
        fr.jitter_y = jy;
        loop->push_back(std::move(fr));
    }
    // Reference: the outputs of one period once converged; compared: the last period.
    const size_t reference_start = std::min<size_t>(64, (frames / 2) / kPeriod * kPeriod);
    const size_t compare_start = frames >= kPeriod ? frames - kPeriod : 0;
    Case c;
    c.name = "sr-long/static-loop";
    c.checks = std::to_string(frames) +
               " frames of x2 SR on a looped static 32x18 capture (jitter period 8); "
               "drift = PSNR of the last period against the first converged one";
    c.format = f;
    c.params = params_of(2.f);
    c.cpu_reference = false;
    c.min_drift_db = 50.0;
    c.step_count = 2 * frames;
    c.step = [=](size_t i) {
        const size_t frame = i / 2;
        if (i % 2 == 0) return submit((*loop)[frame % kPeriod]);
        Step s = request(Op::super_resolve, {});
        if (frames >= 2 * kPeriod && frame >= reference_start && frame < reference_start + kPeriod)
            s.drift_reference = int(frame % kPeriod);
        else if (frames >= 2 * kPeriod && frame >= compare_start && frame >= reference_start + kPeriod)
            s.drift_compare = int(frame % kPeriod);
        return s;
    };
    return c;
}

} // namespace

std::vector<Case> make_cases(const CaseOptions& o) {
    std::vector<Case> out;
    add_color_cases(out);
    add_depth_cases(out);
    add_mv_cases(out);
    add_alpha_cases(out);
    add_combined_cases(out);
    add_resolution_cases(out, o.reduced);
    add_scene_cut_cases(out);
    add_colour_only_cases(out);
    add_rejection_cases(out);
    out.push_back(long_sr_case(o.sr_frames));
    return out;
}

} // namespace fgsr::stress
