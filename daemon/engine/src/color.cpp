// sRGB and the output formats (fgsr/engine/color.hpp).
#include <fgsr/engine/color.hpp>
#include <fgsr/engine/defaults.hpp>

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

namespace fgsr {

float srgb_encode(float linear) {
    float v = std::isnan(linear) ? 0.f : std::clamp(linear, 0.f, 1.f);
    return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

float srgb_decode(float encoded) {
    float v = std::isnan(encoded) ? 0.f : std::clamp(encoded, 0.f, 1.f);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float srgb8_decode(uint8_t b) {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_decode(float(i) / 255.f);
        return t;
    }();
    return table[b];
}

AliasingSums& AliasingSums::operator+=(const AliasingSums& o) {
    adjacent_h += o.adjacent_h;
    adjacent_v += o.adjacent_v;
    blocks_h += o.blocks_h;
    blocks_v += o.blocks_v;
    n_adjacent_h += o.n_adjacent_h;
    n_adjacent_v += o.n_adjacent_v;
    n_blocks_h += o.n_blocks_h;
    n_blocks_v += o.n_blocks_v;
    frames += o.frames;
    return *this;
}

namespace {

// Luma of pixel i for the aliasing measure (non-finite or negative luminance reads as 0).
float aliasing_luma(ColorFormat format, const std::byte* color, size_t i) {
    float rgb[3] = {0.f, 0.f, 0.f};
    switch (format) {
    case ColorFormat::rgba8_srgb:
        for (int c = 0; c < 3; ++c) rgb[c] = srgb8_decode(uint8_t(color[4 * i + size_t(c)]));
        break;
    case ColorFormat::rgba16f_linear:
        for (int c = 0; c < 3; ++c) {
            uint16_t h;
            std::memcpy(&h, color + 8 * i + 2 * size_t(c), 2);
            rgb[c] = glm::unpackHalf1x16(h);
        }
        break;
    case ColorFormat::rgba32f_linear:
        std::memcpy(rgb, color + 16 * i, 12);
        break;
    }
    const float y = 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
    return std::isfinite(y) && y > 0.f ? std::sqrt(y / (1.f + y)) : 0.f;
}

} // namespace

AliasingSums aliasing_sums(uint32_t width, uint32_t height, ColorFormat format,
                           std::span<const std::byte> color, uint32_t row_step) {
    AliasingSums s;
    if (width < 4 || height < 4 || color.size() != size_t(width) * height * bytes_per_pixel(format)) return s;
    row_step = std::max(row_step, 4u);
    const uint32_t bw = width / 2; // 2x2 blocks per strip row
    std::vector<float> l(size_t(width) * 4);
    std::vector<float> m(size_t(bw) * 2);
    for (uint32_t y0 = 0; y0 + 4 <= height; y0 += row_step) {
        for (uint32_t r = 0; r < 4; ++r)
            for (uint32_t x = 0; x < width; ++x)
                l[size_t(r) * width + x] = aliasing_luma(format, color.data(), size_t(y0 + r) * width + x);
        for (uint32_t r = 0; r < 4; ++r)
            for (uint32_t x = 0; x + 1 < width; ++x) {
                const double d = l[size_t(r) * width + x + 1] - l[size_t(r) * width + x];
                s.adjacent_h += d * d;
                s.n_adjacent_h += 1;
            }
        for (uint32_t r = 0; r < 3; ++r)
            for (uint32_t x = 0; x < width; ++x) {
                const double d = l[size_t(r + 1) * width + x] - l[size_t(r) * width + x];
                s.adjacent_v += d * d;
                s.n_adjacent_v += 1;
            }
        for (uint32_t by = 0; by < 2; ++by)
            for (uint32_t bx = 0; bx < bw; ++bx) {
                const size_t a = size_t(2 * by) * width + 2 * bx;
                m[size_t(by) * bw + bx] = 0.25f * (l[a] + l[a + 1] + l[a + width] + l[a + width + 1]);
            }
        for (uint32_t by = 0; by < 2; ++by)
            for (uint32_t bx = 0; bx + 1 < bw; ++bx) {
                const double d = m[size_t(by) * bw + bx + 1] - m[size_t(by) * bw + bx];
                s.blocks_h += d * d;
                s.n_blocks_h += 1;
            }
        for (uint32_t bx = 0; bx < bw; ++bx) {
            const double d = m[size_t(bw) + bx] - m[bx];
            s.blocks_v += d * d;
            s.n_blocks_v += 1;
        }
    }
    s.frames = s.n_adjacent_h > 0 ? 1u : 0u;
    return s;
}

float aliasing_ratio(const AliasingSums& s) {
    if (s.frames == 0 || s.n_adjacent_h == 0 || s.n_adjacent_v == 0 || s.n_blocks_h == 0 || s.n_blocks_v == 0)
        return -1.f;
    const double adjacent = 0.5 * (s.adjacent_h / s.n_adjacent_h + s.adjacent_v / s.n_adjacent_v);
    const double blocks = 0.5 * (s.blocks_h / s.n_blocks_h + s.blocks_v / s.n_blocks_v);
    return blocks > 0 ? float(adjacent / blocks) : -1.f;
}

bool measures_antialiased(float aliasing) {
    return aliasing >= 0.f && aliasing < defaults::antialiased_aliasing;
}

void encode_output(const ImageRGBA& image, ColorFormat format, std::byte* dst) {
    const size_t n = size_t(image.width) * image.height;
    const float* src = image.rgba.data();
    switch (format) {
    case ColorFormat::rgba32f_linear:
        std::memcpy(dst, src, n * 16);
        break;
    case ColorFormat::rgba16f_linear:
        for (size_t i = 0; i < n * 4; ++i) {
            const uint16_t h = glm::packHalf1x16(std::clamp(src[i], -65504.f, 65504.f));
            std::memcpy(dst + i * 2, &h, 2);
        }
        break;
    case ColorFormat::rgba8_srgb: {
        auto* d = reinterpret_cast<uint8_t*>(dst);
        for (size_t i = 0; i < n; ++i) {
            for (int c = 0; c < 3; ++c)
                d[4 * i + size_t(c)] = uint8_t(std::lround(srgb_encode(src[4 * i + size_t(c)]) * 255.f));
            const float a = std::isfinite(src[4 * i + 3]) ? std::clamp(src[4 * i + 3], 0.f, 1.f) : 1.f;
            d[4 * i + 3] = uint8_t(std::lround(a * 255.f));
        }
        break;
    }
    }
}

} // namespace fgsr
