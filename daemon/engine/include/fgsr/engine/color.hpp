// Colour on the host side of the engine: the sRGB transfer function (IEC 61966-2-1) and the
// conversion of engine outputs (linear RGBA float) into a client's output format. The GPU side of
// the same function is shaders/ingest.h (srgb_to_linear).
#pragma once

#include <fgsr/core/types.hpp>

#include <cstddef>
#include <cstdint>
#include <span>

namespace fgsr {

// Linear [0,1] -> encoded [0,1]; inputs outside [0,1] are clamped and NaN reads as 0.
float srgb_encode(float linear);
// Encoded [0,1] -> linear [0,1], with the same clamping.
float srgb_decode(float encoded);
// An 8-bit sRGB value (0..255) to linear [0,1] through a table (exactly srgb_decode(b / 255)).
float srgb8_decode(uint8_t b);

// Writes `image` (linear RGBA) into `dst` as `format`, rows tightly packed: rgba32f_linear copied,
// rgba16f_linear rounded to half after clamping to +-65504, rgba8_srgb sRGB-encoded and rounded
// (alpha stays linear, clamped to [0, 1], non-finite alpha reads as 1). `dst` holds
// width * height * bytes_per_pixel(format) bytes.
void encode_output(const ImageRGBA& image, ColorFormat format, std::byte* dst);

// How aliased a rendered frame looks: the mean squared difference of adjacent pixels against that
// of adjacent 2x2 block means, each the average of its horizontal and vertical means, on the luma
// l = sqrt(Y / (1 + Y)) (Y: linear luminance, so that HDR highlights do not dominate). It is 1/4 on
// a linear ramp and 4 on white noise; point-sampled renders measure 2.5-3.5, antialiased ones
// 0.6-1.0 (docs/ACCURACY.md). Sums, so that frames add up: aliasing_ratio of the total.
struct AliasingSums {
    double adjacent_h = 0, adjacent_v = 0, blocks_h = 0, blocks_v = 0; // sums of squared differences
    double n_adjacent_h = 0, n_adjacent_v = 0, n_blocks_h = 0, n_blocks_v = 0;
    uint32_t frames = 0;
    AliasingSums& operator+=(const AliasingSums& o);
};
// One frame's sums over strips of 4 rows every `row_step` rows (the whole frame at 4), in any
// ColorFormat; `color` holds width * height pixels (otherwise the result is empty: frames 0).
AliasingSums aliasing_sums(uint32_t width, uint32_t height, ColorFormat format,
                           std::span<const std::byte> color, uint32_t row_step = 16);
// The measure of the sums; negative when they hold no frame or no difference at all.
float aliasing_ratio(const AliasingSums& s);
// Whether a measure (aliasing_ratio, Session::input_aliasing) says antialiased input: measured and
// below defaults::antialiased_aliasing.
bool measures_antialiased(float aliasing);

} // namespace fgsr
