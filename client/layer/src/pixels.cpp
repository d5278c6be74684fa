// CPU conversion between swapchain formats and fgsr's colour formats (pixels.hpp).
#include "pixels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace fgsr::layer {
namespace {

float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linear_to_srgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

template <class T> T* row(void* base, uint32_t pitch, uint32_t y) {
    return reinterpret_cast<T*>(static_cast<uint8_t*>(base) + size_t(pitch) * y);
}
template <class T> const T* row(const void* base, uint32_t pitch, uint32_t y) {
    return reinterpret_cast<const T*>(static_cast<const uint8_t*>(base) + size_t(pitch) * y);
}

void copy_rows(ConstPlane src, Plane dst, uint32_t row_bytes, uint32_t height) {
    for (uint32_t y = 0; y < height; ++y)
        std::memcpy(row<uint8_t>(dst.data, dst.pitch, y), row<uint8_t>(src.data, src.pitch, y), row_bytes);
}

void swap_rb(ConstPlane src, Plane dst, uint32_t width, uint32_t height) {
    for (uint32_t y = 0; y < height; ++y) {
        const uint8_t* s = row<uint8_t>(src.data, src.pitch, y);
        uint8_t* d = row<uint8_t>(dst.data, dst.pitch, y);
        for (uint32_t x = 0; x < width; ++x, s += 4, d += 4) {
            d[0] = s[2];
            d[1] = s[1];
            d[2] = s[0];
            d[3] = s[3];
        }
    }
}

} // namespace

float half_to_float(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16;
    const uint32_t exp = (h >> 10) & 0x1fu;
    uint32_t mant = h & 0x3ffu;
    uint32_t bits;
    if (exp == 0) {
        if (mant == 0) {
            bits = sign;
        } else { // subnormal
            int e = -1;
            do {
                ++e;
                mant <<= 1;
            } while ((mant & 0x400u) == 0);
            bits = sign | uint32_t(127 - 15 - e) << 23 | (mant & 0x3ffu) << 13;
        }
    } else if (exp == 31) {
        bits = sign | 0x7f800000u | mant << 13;
    } else {
        bits = sign | (exp + 112u) << 23 | mant << 13;
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

uint16_t float_to_half(float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    const uint16_t sign = uint16_t((bits >> 16) & 0x8000u);
    if (std::isnan(f)) return uint16_t(sign | 0x7e00u);
    const float a = std::fabs(f);
    if (a >= 65520.0f) return uint16_t(sign | 0x7c00u);
    if (a < 6.103515625e-05f) return uint16_t(sign | uint16_t(std::lround(a / 5.9604644775390625e-08f)));
    const int32_t exp = int32_t((bits >> 23) & 0xffu) - 127 + 15;
    uint32_t mant = bits & 0x7fffffu;
    uint32_t h = uint32_t(exp) << 10 | mant >> 13;
    const uint32_t rest = mant & 0x1fffu; // round to nearest even
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
    return uint16_t(sign | h);
}

PixelKind pixel_kind(VkFormat f) {
    switch (f) {
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
        return PixelKind::bgra8;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
        return PixelKind::rgba8;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
        return PixelKind::rgba16f;
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
        return PixelKind::a2b10g10r10;
    default:
        return PixelKind::unsupported;
    }
}

uint32_t swapchain_bytes_per_pixel(PixelKind k) {
    return k == PixelKind::rgba16f ? 8u : k == PixelKind::unsupported ? 0u : 4u;
}

fgsr_color_format fgsr_format_for(PixelKind k) {
    return k == PixelKind::bgra8 || k == PixelKind::rgba8 ? FGSR_COLOR_RGBA8_SRGB : FGSR_COLOR_RGBA16F_LINEAR;
}

void to_fgsr(PixelKind kind, ConstPlane src, Plane dst, uint32_t width, uint32_t height) {
    switch (kind) {
    case PixelKind::bgra8:
        swap_rb(src, dst, width, height);
        return;
    case PixelKind::rgba8:
        copy_rows(src, dst, width * 4, height);
        return;
    case PixelKind::rgba16f:
        copy_rows(src, dst, width * 8, height);
        return;
    case PixelKind::a2b10g10r10: {
        uint16_t lut[1024];
        for (uint32_t i = 0; i < 1024; ++i) lut[i] = float_to_half(srgb_to_linear(float(i) / 1023.0f));
        const uint16_t alpha[4] = {float_to_half(0.0f), float_to_half(1.0f / 3), float_to_half(2.0f / 3),
                                   float_to_half(1.0f)};
        for (uint32_t y = 0; y < height; ++y) {
            const uint32_t* s = row<uint32_t>(src.data, src.pitch, y);
            uint16_t* d = row<uint16_t>(dst.data, dst.pitch, y);
            for (uint32_t x = 0; x < width; ++x, d += 4) {
                const uint32_t p = s[x];
                d[0] = lut[p & 0x3ffu];
                d[1] = lut[(p >> 10) & 0x3ffu];
                d[2] = lut[(p >> 20) & 0x3ffu];
                d[3] = alpha[p >> 30];
            }
        }
        return;
    }
    case PixelKind::unsupported:
        return;
    }
}

void from_fgsr(PixelKind kind, ConstPlane src, Plane dst, uint32_t width, uint32_t height) {
    switch (kind) {
    case PixelKind::bgra8:
        swap_rb(src, dst, width, height);
        return;
    case PixelKind::rgba8:
        copy_rows(src, dst, width * 4, height);
        return;
    case PixelKind::rgba16f:
        copy_rows(src, dst, width * 8, height);
        return;
    case PixelKind::a2b10g10r10:
        for (uint32_t y = 0; y < height; ++y) {
            const uint16_t* s = row<uint16_t>(src.data, src.pitch, y);
            uint32_t* d = row<uint32_t>(dst.data, dst.pitch, y);
            for (uint32_t x = 0; x < width; ++x, s += 4) {
                uint32_t c[3];
                for (int i = 0; i < 3; ++i)
                    c[i] = uint32_t(std::lround(linear_to_srgb(half_to_float(s[i])) * 1023.0f));
                const uint32_t a = uint32_t(std::lround(std::clamp(half_to_float(s[3]), 0.0f, 1.0f) * 3.0f));
                d[x] = c[0] | c[1] << 10 | c[2] << 20 | a << 30;
            }
        }
        return;
    case PixelKind::unsupported:
        return;
    }
}

void fgsr_to_rgba8(fgsr_color_format format, ConstPlane src, Plane dst, uint32_t width, uint32_t height) {
    if (format == FGSR_COLOR_RGBA8_SRGB) {
        copy_rows(src, dst, width * 4, height);
        return;
    }
    for (uint32_t y = 0; y < height; ++y) {
        uint8_t* d = row<uint8_t>(dst.data, dst.pitch, y);
        for (uint32_t x = 0; x < width; ++x) {
            float c[4];
            if (format == FGSR_COLOR_RGBA16F_LINEAR) {
                const uint16_t* s = row<uint16_t>(src.data, src.pitch, y) + 4 * x;
                for (int i = 0; i < 4; ++i) c[i] = half_to_float(s[i]);
            } else {
                std::memcpy(c, row<float>(src.data, src.pitch, y) + 4 * x, sizeof(c));
            }
            for (int i = 0; i < 3; ++i) d[4 * x + i] = uint8_t(std::lround(linear_to_srgb(c[i]) * 255.0f));
            d[4 * x + 3] = uint8_t(std::lround(std::clamp(c[3], 0.0f, 1.0f) * 255.0f));
        }
    }
}

} // namespace fgsr::layer
