// The raw material of the numerical stress cases (stress_internal.hpp): client planes encoded from
// linear content in every accepted format, the moving-rectangle content, poisons (special values
// written into a plane) and the small format/params constructors.
#include "stress_internal.hpp"

#include <fgsr/engine/color.hpp>

#include <glm/gtc/packing.hpp>

#include <cmath>
#include <cstring>

namespace fgsr::stress::detail {

namespace {

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

// Pixels that a poisoned plane changes: about a quarter, scattered, including neighbours.
bool poisoned(uint32_t x, uint32_t y) {
    return (x * 7u + y * 3u) % 4u == 0u;
}

} // namespace

// Depth value that means "far plane" for a depth kind.
float far_value(DepthKind k) {
    return k == DepthKind::device ? 1.f : k == DepthKind::device_reversed ? 0.f : 1.0e30f;
}

// ---------------------------------------------------------------------------------------------
// Content: a textured background (depth 40, still) and a textured rectangle (depth 8) that moves
// by `motion` pixels per frame; frame k shows the rectangle at k * motion. Vectors are exact.

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

Frame encode(const FrameFormat& f, const Content& c, bool with_mv) {
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

FrameFormat format_of(uint32_t w, uint32_t h, ColorFormat cf, MvFormat mf, Conventions conv) {
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
    // The agreeing/* cases run the agree pass (Params::colour_agree, on by default); the others keep
    // the given field's path, which fgsrd's sessions take unless a client asks for agreement.
    p.colour_agree = false;
    return p;
}

} // namespace fgsr::stress::detail
