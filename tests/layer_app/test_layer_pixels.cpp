// The layer's CPU format conversions (client/layer/src/pixels.hpp), without a device: swapchain
// pixels -> fgsr input -> swapchain pixels for every supported format, with padded rows.
#include "pixels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

using namespace fgsr::layer;

TEST(LayerPixels, FormatsMapToFgsrInputs) {
    EXPECT_EQ(pixel_kind(VK_FORMAT_B8G8R8A8_UNORM), PixelKind::bgra8);
    EXPECT_EQ(pixel_kind(VK_FORMAT_B8G8R8A8_SRGB), PixelKind::bgra8);
    EXPECT_EQ(pixel_kind(VK_FORMAT_R8G8B8A8_SRGB), PixelKind::rgba8);
    EXPECT_EQ(pixel_kind(VK_FORMAT_R16G16B16A16_SFLOAT), PixelKind::rgba16f);
    EXPECT_EQ(pixel_kind(VK_FORMAT_A2B10G10R10_UNORM_PACK32), PixelKind::a2b10g10r10);
    EXPECT_EQ(pixel_kind(VK_FORMAT_R5G6B5_UNORM_PACK16), PixelKind::unsupported);
    EXPECT_EQ(fgsr_format_for(PixelKind::bgra8), FGSR_COLOR_RGBA8_SRGB);
    EXPECT_EQ(fgsr_format_for(PixelKind::a2b10g10r10), FGSR_COLOR_RGBA16F_LINEAR);
    EXPECT_EQ(swapchain_bytes_per_pixel(PixelKind::rgba16f), 8u);
}

TEST(LayerPixels, HalfFloatsRoundTrip) {
    for (float f : {0.0f, 1.0f, 0.5f, 0.2140f, 1e-3f, 3e-5f, 65504.0f, -2.5f}) {
        const float back = half_to_float(float_to_half(f));
        EXPECT_NEAR(back, f, std::fabs(f) * 1e-3f + 1e-7f) << f;
    }
    EXPECT_EQ(float_to_half(1.0f), 0x3c00);
    EXPECT_TRUE(std::isinf(half_to_float(float_to_half(1e6f))));
}

TEST(LayerPixels, Bgra8SwapsToRgba8AndBack) {
    const uint32_t w = 3, h = 2, pitch = 16; // padded rows on both sides
    std::vector<uint8_t> src(pitch * h, 0), fgsr(pitch * h, 0), back(pitch * h, 0);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (uint32_t c = 0; c < 4; ++c) src[y * pitch + x * 4 + c] = uint8_t(10 * (y * w + x) + c);
    to_fgsr(PixelKind::bgra8, {src.data(), pitch}, {fgsr.data(), pitch}, w, h);
    EXPECT_EQ(fgsr[pitch + 4 + 0], src[pitch + 4 + 2]); // R from B's place
    EXPECT_EQ(fgsr[pitch + 4 + 2], src[pitch + 4 + 0]);
    EXPECT_EQ(fgsr[pitch + 4 + 3], src[pitch + 4 + 3]);
    from_fgsr(PixelKind::bgra8, {fgsr.data(), pitch}, {back.data(), pitch}, w, h);
    for (uint32_t y = 0; y < h; ++y) EXPECT_EQ(std::memcmp(&back[y * pitch], &src[y * pitch], w * 4), 0);
}

TEST(LayerPixels, A2b10g10r10RoundTripsThroughLinearHalf) {
    const uint32_t w = 1024, h = 1;
    std::vector<uint32_t> src(w), back(w);
    for (uint32_t x = 0; x < w; ++x)
        src[x] = x | ((1023 - x) << 10) | ((x * 7 % 1024) << 20) | ((x % 4) << 30);
    std::vector<uint16_t> half(w * 4);
    to_fgsr(PixelKind::a2b10g10r10, {src.data(), w * 4}, {half.data(), w * 8}, w, h);
    // Linear light: code 512 of 1023 is about 0.2148 (sRGB decoding).
    EXPECT_NEAR(half_to_float(half[512 * 4]), 0.2148f, 2e-3f);
    from_fgsr(PixelKind::a2b10g10r10, {half.data(), w * 8}, {back.data(), w * 4}, w, h);
    for (uint32_t x = 0; x < w; ++x) EXPECT_EQ(back[x], src[x]) << "code " << x;
}

TEST(LayerPixels, DumpsEncodeLinearHalfToSrgbBytes) {
    const uint16_t px[4] = {float_to_half(0.0f), float_to_half(0.2140f), float_to_half(1.0f),
                            float_to_half(1.0f)};
    uint8_t out[4];
    fgsr_to_rgba8(FGSR_COLOR_RGBA16F_LINEAR, {px, 8}, {out, 4}, 1, 1);
    EXPECT_EQ(out[0], 0);
    EXPECT_NEAR(out[1], 128, 1);
    EXPECT_EQ(out[2], 255);
    EXPECT_EQ(out[3], 255);
}
