// Colour on the host side of the engine: the sRGB transfer function (IEC 61966-2-1) and the
// conversion of engine outputs (linear RGBA float) into a client's output format. The GPU side of
// the same function is shaders/ingest.h (srgb_to_linear).
#pragma once

#include <fgsr/core/types.hpp>

#include <cstddef>
#include <cstdint>

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

} // namespace fgsr
