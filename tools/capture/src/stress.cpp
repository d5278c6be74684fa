// The numerical stress cases and their in-process feeder (see fgsr/capture/stress.hpp).
#include <fgsr/core/halton.hpp>
#include <fgsr/engine/color.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/stress.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/reference.hpp>

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

namespace fgsr::stress {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kMax = std::numeric_limits<float>::max();
constexpr float kDenorm = 1.0e-40f; // float32 subnormal

// ---------------------------------------------------------------------------------------------
// Raw plane encoding

// IEEE half bits of a float, round to nearest; values beyond the half range become +-inf (what a
// client's float -> half conversion produces), NaN stays NaN.
uint16_t half_bits(float v) {
    if (std::isnan(v)) return 0x7e00;
    if (std::abs(v) >= 65520.f) return v > 0 ? 0x7c00 : 0xfc00;
    return glm::packHalf1x16(v);
}

void put_f32(std::vector<std::byte>& b, size_t word, float v) {
    std::memcpy(b.data() + 4 * word, &v, 4);
}
void put_u16(std::vector<std::byte>& b, size_t half, uint16_t v) {
    std::memcpy(b.data() + 2 * half, &v, 2);
}

// A value written into a float plane; `half` overrides the half encoding (exact subnormals).
struct Special {
    const char* name;
    float value;
    std::optional<uint16_t> half;
};

void put_color(std::vector<std::byte>& b, ColorFormat f, size_t pixel, int channel, const Special& s) {
    if (f == ColorFormat::rgba32f_linear)
        put_f32(b, 4 * pixel + size_t(channel), s.value);
    else if (f == ColorFormat::rgba16f_linear)
        put_u16(b, 4 * pixel + size_t(channel), s.half ? *s.half : half_bits(s.value));
    else
        b[4 * pixel + size_t(channel)] = std::byte(s.value > 0.5f ? 255 : 0);
}

void put_mv(std::vector<std::byte>& b, MvFormat f, size_t pixel, int axis, const Special& s) {
    if (f == MvFormat::rg32f)
        put_f32(b, 2 * pixel + size_t(axis), s.value);
    else
        put_u16(b, 2 * pixel + size_t(axis), s.half ? *s.half : half_bits(s.value));
}

// Device depth of a linear view depth z under the conventions (inverse of shaders/ingest.h).
float encode_depth(float z, const Conventions& c) {
    const float n = c.near_plane, f = c.far_plane;
    const bool infinite = !(f > 0.f) || std::isinf(f);
    switch (c.depth_kind) {
    case DepthKind::linear:
        return z;
    case DepthKind::device:
        return infinite ? 1.f - n / z : f * (1.f - n / z) / (f - n);
    case DepthKind::device_reversed:
        return infinite ? n / z : n * (f - z) / (z * (f - n));
    }
    return z;
}

// Depth value that means "far plane" for a depth kind.
float far_value(DepthKind k) {
    return k == DepthKind::device ? 1.f : k == DepthKind::device_reversed ? 0.f : 1.0e30f;
}

// ---------------------------------------------------------------------------------------------
// Content: a textured background (depth 40, still) and a textured rectangle (depth 8) that moves
// by `motion` pixels per frame; frame k shows the rectangle at k * motion. Vectors are exact.

struct Content {
    uint32_t w = 0, h = 0;
    std::vector<glm::vec4> color; // linear
    std::vector<float> depth;     // linear view depth
    std::vector<glm::vec2> mv;    // pixels, y down, to previous
};

Content content(uint32_t w, uint32_t h, int k, glm::vec2 motion) {
    Content c;
    c.w = w;
    c.h = h;
    const size_t n = size_t(w) * h;
    c.color.resize(n);
    c.depth.resize(n);
    c.mv.resize(n);
    const glm::vec2 origin = glm::vec2(float(w), float(h)) * 0.3f + float(k) * motion;
    const glm::vec2 half_size = glm::max(glm::vec2(float(w), float(h)) * 0.2f, glm::vec2(0.6f));
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
            const glm::vec2 local = p - origin;
            if (std::abs(local.x) <= half_size.x && std::abs(local.y) <= half_size.y) {
                const float t = 0.5f + 0.4f * std::sin(local.x * 0.9f) * std::cos(local.y * 0.7f);
                c.color[i] = glm::vec4(0.9f * t, 0.3f, 1.f - t, 1.f);
                c.depth[i] = 8.f;
                c.mv[i] = -motion;
            } else {
                const float t = ((x / 3 + y / 3) % 2 == 0) ? 0.8f : 0.15f;
                c.color[i] = glm::vec4(t, 0.5f * t + 0.2f, 0.25f, 1.f);
                c.depth[i] = 40.f + 0.01f * float(x);
                c.mv[i] = glm::vec2(0.f);
            }
        }
    return c;
}

Frame encode(const FrameFormat& f, const Content& c, bool with_mv = true) {
    Frame out;
    const size_t n = size_t(f.width) * f.height;
    out.color.resize(n * bytes_per_pixel(f.color_format));
    out.depth.resize(n * 4);
    if (with_mv) out.mv.resize(n * bytes_per_pixel(f.mv_format));
    for (size_t i = 0; i < n; ++i) {
        for (int ch = 0; ch < 4; ++ch) {
            const float v = c.color[i][ch];
            if (f.color_format == ColorFormat::rgba8_srgb)
                out.color[4 * i + size_t(ch)] =
                    std::byte(uint8_t(std::lround(255.f * (ch == 3 ? v : srgb_encode(v)))));
            else
                put_color(out.color, f.color_format, i, ch, Special{"", v, {}});
        }
        put_f32(out.depth, i, encode_depth(c.depth[i], f.conventions));
        if (with_mv)
            for (int a = 0; a < 2; ++a) put_mv(out.mv, f.mv_format, i, a, Special{"", c.mv[i][a], {}});
    }
    return out;
}

// Pixels that a poisoned plane changes: about a quarter, scattered, including neighbours.
bool poisoned(uint32_t x, uint32_t y) {
    return (x * 7u + y * 3u) % 4u == 0u;
}

enum class Plane { color, depth, mv };

struct Poison {
    Plane plane = Plane::color;
    std::vector<Special> values; // pixel (x, y) takes values[(x + y) % size]
    bool everywhere = false;     // every pixel, not a scattered quarter
};

void apply(Frame& fr, const FrameFormat& f, const Poison& p) {
    if (p.values.empty()) return;
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x) {
            if (!p.everywhere && !poisoned(x, y)) continue;
            const size_t i = size_t(y) * f.width + x;
            const Special& s = p.values[(x + y) % p.values.size()];
            switch (p.plane) {
            case Plane::color:
                for (int ch = 0; ch < 4; ++ch) put_color(fr.color, f.color_format, i, ch, s);
                break;
            case Plane::depth:
                put_f32(fr.depth, i, s.value);
                break;
            case Plane::mv:
                if (!fr.mv.empty())
                    for (int a = 0; a < 2; ++a) put_mv(fr.mv, f.mv_format, i, a, s);
                break;
            }
        }
}

// ---------------------------------------------------------------------------------------------
// Case builders

using StepFn = std::function<Step()>;

std::function<Step(size_t)> sequence(std::vector<StepFn> steps) {
    auto list = std::make_shared<std::vector<StepFn>>(std::move(steps));
    return [list](size_t i) { return (*list)[i](); };
}

Step submit(Frame f, std::string reject = {}) {
    Step s;
    s.op = Op::submit;
    s.frame = std::move(f);
    s.reject = std::move(reject);
    return s;
}
Step request(Op op, std::vector<float> alphas, std::string reject = {}) {
    Step s;
    s.op = op;
    s.alphas = std::move(alphas);
    s.reject = std::move(reject);
    return s;
}

FrameFormat format_of(uint32_t w, uint32_t h, ColorFormat cf = ColorFormat::rgba16f_linear,
                      MvFormat mf = MvFormat::rg32f, Conventions conv = {}) {
    FrameFormat f;
    f.width = w;
    f.height = h;
    f.color_format = cf;
    f.mv_format = mf;
    f.conventions = conv;
    return f;
}

Params params_of(float scale) {
    Params p;
    p.scale = scale;
    return p;
}

const std::vector<float> kInterpAlphas = {1e-6f, 0.5f, 1.f - 1e-6f};
const std::vector<float> kExtrapAlphas = {1e-6f, 0.5f, 1.f};

// The standard scenario: two frames (both poisoned), every request kind at the extreme alphas,
// then a clean frame and one more interpolation (the session recovers from poisoned history).
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
    s.push_back([=] { return submit(encode(f, content(f.width, f.height, 2, motion))); });
    if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
    s.push_back([] { return request(Op::interpolate, {0.5f}); });
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

// ---------------------------------------------------------------------------------------------
// The in-process feeder

bool contains_nocase(const std::string& hay, const std::string& needle) {
    auto lower = [](std::string s) {
        for (char& ch : s)
            if (ch >= 'A' && ch <= 'Z') ch = char(ch - 'A' + 'a');
        return s;
    };
    return lower(hay).find(lower(needle)) != std::string::npos;
}

// Number of non-finite values.
size_t count_non_finite(std::span<const float> v) {
    size_t bad = 0;
    for (float x : v) bad += std::isfinite(x) ? 0 : 1;
    return bad;
}

struct CpuState {
    ref::InternalFrame f0, f1;
    size_t frames = 0; // submitted since the last reset
    std::vector<glm::vec4> hr_prev, hr_new;
    bool hr_valid = false;
    float jitter_x = 0, jitter_y = 0;
};

class Runner {
  public:
    Runner(Engine& e, const Case& c, CaseResult& r) : engine_(e), c_(c), r_(r) {}

    bool fail(std::string why) {
        r_.pass = false;
        if (r_.failure.empty()) r_.failure = std::move(why);
        return false;
    }

    bool check_values(std::span<const float> v, const std::string& what) {
        ++r_.outputs_checked;
        r_.values_checked += v.size();
        const size_t bad = count_non_finite(v);
        if (bad) return fail(what + ": " + std::to_string(bad) + " non-finite values");
        return true;
    }
    bool check_image(const ImageRGBA& img, const std::string& what) { return check_values(img.rgba, what); }
    bool check_cpu(const std::vector<glm::vec4>& v, const std::string& what) {
        return check_values(std::span<const float>(&v[0][0], v.size() * 4), what + " (CPU reference)");
    }

    bool session_rejected() {
        auto s = engine_.create_session(c_.format, c_.params);
        if (s)
            return fail("create_session accepted; expected a rejection mentioning '" + c_.reject_session +
                        "'");
        const Error& e = s.error();
        r_.rejections.push_back(std::string(errc_name(e.code)) + ": " + e.message);
        if (!contains_nocase(e.message, c_.reject_session))
            return fail("rejection reason '" + e.message + "' does not mention '" + c_.reject_session + "'");
        // The engine keeps serving: a good session, two frames, one interpolation.
        auto good = engine_.create_session(format_of(16, 16));
        if (!good) return fail("a good session after the rejection failed: " + good.error().message);
        for (int k = 0; k < 2; ++k) {
            Frame fr = encode((*good)->format(), content(16, 16, k, {1.f, 1.f}));
            auto sub = (*good)->submit(fr.view());
            if (!sub) return fail("a good frame after the rejection failed: " + sub.error().message);
        }
        const float a = 0.5f;
        auto g = (*good)->interpolate(std::span<const float>(&a, 1));
        if (!g) return fail("interpolation after the rejection failed: " + g.error().message);
        return check_image((*g)[0].color, "interpolation after the rejection");
    }

    bool run(const RunOptions& options) {
        if (!c_.reject_session.empty()) return session_rejected();
        auto created = engine_.create_session(c_.format, c_.params);
        if (!created) return fail("create_session failed: " + created.error().message);
        Session& s = **created;
        const FrameFormat& f = c_.format;
        const bool sr = s.output_width() != f.width || s.output_height() != f.height;
        const bool cpu = c_.cpu_reference && size_t(f.width) * f.height <= (1u << 14);
        std::vector<float> lut;
        if (cpu && sr) {
            Lut l = c_.params.lut.size() == kLutSize ? Lut{c_.params.scale, c_.params.lut}
                                                     : default_lut(c_.params.scale);
            force_identity_phase(l);
            lut = std::move(l.weights);
        }
        std::vector<ImageRGBA> previous_outputs;
        std::vector<std::optional<ImageRGBA>> drift_refs;

        for (size_t i = 0; i < c_.step_count; ++i) {
            if (options.progress && c_.step_count > options.progress_every && i % options.progress_every == 0)
                options.progress(c_.name + ": step " + std::to_string(i) + "/" +
                                 std::to_string(c_.step_count));
            const Step st = c_.step(i);
            const std::string where = "step " + std::to_string(i) + " (" +
                                      (st.op == Op::submit        ? "submit"
                                       : st.op == Op::interpolate ? "interpolate"
                                       : st.op == Op::extrapolate ? "extrapolate"
                                                                  : "super_resolve") +
                                      ")";
            ++r_.steps_run;
            std::optional<Error> err;
            std::vector<ImageRGBA> images;
            switch (st.op) {
            case Op::submit: {
                auto rs = s.submit(st.frame.view());
                if (!rs) err = rs.error();
                break;
            }
            case Op::interpolate:
            case Op::extrapolate: {
                auto rg = st.op == Op::interpolate ? s.interpolate(st.alphas) : s.extrapolate(st.alphas);
                if (!rg)
                    err = rg.error();
                else
                    for (GeneratedFrame& g : *rg) images.push_back(std::move(g.color));
                break;
            }
            case Op::super_resolve: {
                auto rs = s.super_resolved();
                if (!rs)
                    err = rs.error();
                else
                    images.push_back(std::move(rs->color));
                break;
            }
            }
            if (!st.reject.empty()) {
                if (!err)
                    return fail(where + " was accepted; expected a rejection mentioning '" + st.reject + "'");
                r_.rejections.push_back(std::string(errc_name(err->code)) + ": " + err->message);
                if (!contains_nocase(err->message, st.reject))
                    return fail(where + ": rejection reason '" + err->message + "' does not mention '" +
                                st.reject + "'");
                continue;
            }
            if (err) return fail(where + " failed: " + errc_name(err->code) + ": " + err->message);
            for (size_t k = 0; k < images.size(); ++k)
                if (!check_image(images[k], where + " output " + std::to_string(k))) return false;

            if (st.same_as_previous) {
                bool same = previous_outputs.size() == images.size();
                for (size_t k = 0; same && k < images.size(); ++k)
                    same = previous_outputs[k].rgba.size() == images[k].rgba.size() &&
                           std::memcmp(previous_outputs[k].rgba.data(), images[k].rgba.data(),
                                       images[k].rgba.size() * 4) == 0;
                if (!same) return fail(where + ": outputs differ from the identical previous request");
            }
            if (st.op == Op::interpolate || st.op == Op::extrapolate) previous_outputs = images;
            if (st.drift_reference >= 0 && !images.empty()) {
                if (drift_refs.size() <= size_t(st.drift_reference))
                    drift_refs.resize(size_t(st.drift_reference) + 1);
                drift_refs[size_t(st.drift_reference)] = images[0];
            }
            if (st.drift_compare >= 0 && !images.empty()) {
                if (size_t(st.drift_compare) >= drift_refs.size() || !drift_refs[size_t(st.drift_compare)])
                    return fail(where + ": no drift reference " + std::to_string(st.drift_compare));
                auto p = capture::psnr(images[0], *drift_refs[size_t(st.drift_compare)]);
                if (!p) return fail(where + ": " + p.error().message);
                r_.drift_db = r_.drift_db ? std::min(*r_.drift_db, *p) : *p;
            }

            if (st.op == Op::submit && cpu && !step_cpu_submit(s, st.frame, sr, lut, where)) return false;
            if ((st.op == Op::interpolate || st.op == Op::extrapolate) && cpu &&
                !step_cpu_generate(s, st, images, sr, lut, where))
                return false;
        }
        if (r_.drift_db && *r_.drift_db < c_.min_drift_db) {
            char b[128];
            std::snprintf(b, sizeof b, "drift %.2f dB is below %.1f dB", *r_.drift_db, c_.min_drift_db);
            return fail(b);
        }
        return true;
    }

    // The ingested frame (GPU) is finite with positive depth; the CPU reference runs ingest and
    // SR on the same frame and its outputs must be finite too.
    bool step_cpu_submit(Session& s, const Frame& fr, bool sr, const std::vector<float>& lut,
                         const std::string& where) {
        auto in = s.read_frame(1);
        if (!in) return fail(where + ": read_frame: " + in.error().message);
        if (!check_values(in->color, where + " ingested colour") ||
            !check_values(in->depth, where + " ingested depth") ||
            !check_values(in->mv, where + " ingested vectors"))
            return false;
        for (float d : in->depth)
            if (!(d > 0.f)) return fail(where + ": ingested depth " + std::to_string(d) + " is not positive");
        const FrameFormat& f = c_.format;
        const bool restart = fr.reset || cs_.frames == 0;
        // The engine removes the jitter from vectors that contain it (Session::submit).
        const glm::vec2 offset = c_.params.mvs_contain_jitter && !restart
                                     ? glm::vec2(cs_.jitter_x - fr.jitter_x, cs_.jitter_y - fr.jitter_y)
                                     : glm::vec2(0.f);
        ref::InternalFrame cur = ref::ingest(f, fr.view(), offset);
        if (sr && c_.params.denoise) {
            // The pre-filter with the GPU's range; its estimate must agree with the CPU's up to a
            // histogram bin (log2 rounding at bin edges).
            const ref::DenoiseParams dp = params::denoise_params(f, c_.params);
            const NoiseEstimate cpu = ref::noise_level(cur, dp), gpu = s.last_noise_estimate();
            if (!(std::isfinite(gpu.sigma) && std::isfinite(gpu.range)))
                return fail(where + ": noise estimate is not finite");
            if (cpu.sigma > 0.f && !(std::abs(std::log2(gpu.sigma / cpu.sigma)) <= 0.126f))
                return fail(where + ": noise estimate " + std::to_string(gpu.sigma) + " (GPU) against " +
                            std::to_string(cpu.sigma) + " (CPU)");
            cur.color = ref::denoise(cur, dp, gpu.range);
        }
        if (sr) {
            const ref::SrParams p =
                params::sr_params(f, c_.params, s.output_width(), s.output_height(), fr.jitter_x, fr.jitter_y,
                                  !restart && cs_.hr_valid && cur.has_mv);
            if (cs_.hr_new.empty()) cs_.hr_new.assign(size_t(p.hr_width) * p.hr_height, glm::vec4(0.f));
            const std::vector<float>& prev_depth = cs_.frames > 0 ? cs_.f1.depth : cur.depth;
            std::vector<glm::vec4> out = ref::super_resolve(cur, prev_depth, cs_.hr_new, p, lut);
            if (!check_cpu(out, where + " SR")) return false;
            auto gpu = s.super_resolved();
            if (!gpu) return fail(where + ": super_resolved: " + gpu.error().message);
            compare(gpu->color, out);
            cs_.hr_prev = std::move(cs_.hr_new);
            cs_.hr_new = std::move(out);
            cs_.hr_valid = true;
        }
        cs_.f0 = std::move(cs_.f1);
        cs_.f1 = std::move(cur);
        cs_.frames = restart ? 1 : cs_.frames + 1;
        cs_.jitter_x = fr.jitter_x;
        cs_.jitter_y = fr.jitter_y;
        return true;
    }

    bool step_cpu_generate(Session& s, const Step& st, const std::vector<ImageRGBA>& images, bool sr,
                           const std::vector<float>& lut, const std::string& where) {
        if (cs_.frames < 2 || images.size() != st.alphas.size()) return true;
        size_t k = 0;
        const bool extrap = st.op == Op::extrapolate;
        for (float a : st.alphas) {
            const ref::GenParams g =
                params::gen_params(c_.format, c_.params, a, extrap, cs_.f0.has_mv, cs_.f1.has_mv);
            std::vector<glm::vec4> out;
            if (sr) {
                const ref::Splat sp = ref::splat(cs_.f0, cs_.f1, g);
                const ref::SrParams p =
                    params::sr_params(c_.format, c_.params, s.output_width(), s.output_height(), cs_.jitter_x,
                                      cs_.jitter_y, true);
                out = ref::generate_sr(cs_.f0, cs_.f1, sp, extrap ? cs_.hr_new : cs_.hr_prev, g, p, lut);
            } else {
                out = ref::generate(cs_.f0, cs_.f1, g);
            }
            if (!check_cpu(out, where + " alpha " + std::to_string(a))) return false;
            compare(images[k++], out);
        }
        return true;
    }

    // Largest difference between a GPU output and the CPU reference, relative to max(1, |ref|).
    void compare(const ImageRGBA& gpu, const std::vector<glm::vec4>& cpu) {
        if (gpu.rgba.size() != cpu.size() * 4) return;
        double worst = r_.max_cpu_difference.value_or(0.0);
        for (size_t i = 0; i < cpu.size(); ++i)
            for (int ch = 0; ch < 4; ++ch) {
                const double ref = cpu[i][ch], got = gpu.rgba[4 * i + size_t(ch)];
                worst = std::max(worst, std::abs(got - ref) / std::max(1.0, std::abs(ref)));
            }
        r_.max_cpu_difference = worst;
    }

  private:
    Engine& engine_;
    const Case& c_;
    CaseResult& r_;
    CpuState cs_;
};

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
    add_rejection_cases(out);
    out.push_back(long_sr_case(o.sr_frames));
    return out;
}

CaseResult run_on_engine(Engine& engine, const Case& c, const RunOptions& options) {
    CaseResult r;
    r.name = c.name;
    r.checks = c.checks;
    r.pass = true;
    const uint64_t validation_before = engine.validation_errors();
    const auto t0 = std::chrono::steady_clock::now();
    Runner(engine, c, r).run(options);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // On CPU devices (lavapipe) the GPU passes and the reference run the same code on the same
    // inputs: any difference beyond float rounding means the sanitisation diverged.
    constexpr double kCpuTolerance = 1e-3;
    if (engine.is_cpu_device() && r.pass && r.max_cpu_difference && *r.max_cpu_difference > kCpuTolerance) {
        r.pass = false;
        r.failure = "GPU output and CPU reference differ by " + std::to_string(*r.max_cpu_difference) +
                    " (relative), above " + std::to_string(kCpuTolerance);
    }
    const uint64_t validation = engine.validation_errors() - validation_before;
    if (validation && r.pass) {
        r.pass = false;
        r.failure = std::to_string(validation) + " Vulkan validation errors (see stderr)";
    }
    return r;
}

} // namespace fgsr::stress
