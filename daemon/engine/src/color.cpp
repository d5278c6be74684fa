// sRGB and the output formats (fgsr/engine/color.hpp).
#include <fgsr/engine/color.hpp>

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

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
