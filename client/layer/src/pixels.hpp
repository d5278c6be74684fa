// Swapchain formats the layer handles and their conversion, on the CPU, to and from fgsr's input
// and output formats:
//   B8G8R8A8 / R8G8B8A8, UNORM or SRGB  <-> FGSR_COLOR_RGBA8_SRGB (bytes are display-encoded in
//                                           both: UNORM swapchains hold what the app wrote)
//   R16G16B16A16_SFLOAT                 <-> FGSR_COLOR_RGBA16F_LINEAR (copied)
//   A2B10G10R10_UNORM_PACK32            <-> FGSR_COLOR_RGBA16F_LINEAR (10-bit display values,
//                                           sRGB-decoded to linear and back)
// Rows are `pitch` bytes apart on both sides; widths and heights are the caller's checked sizes.
#pragma once

#include <fgsr/protocol.h>
#include <vulkan/vulkan.h>

#include <cstdint>

namespace fgsr::layer {

enum class PixelKind { unsupported, bgra8, rgba8, rgba16f, a2b10g10r10 };

PixelKind pixel_kind(VkFormat f);
uint32_t swapchain_bytes_per_pixel(PixelKind k);
fgsr_color_format fgsr_format_for(PixelKind k);

struct Plane {
    void* data;
    uint32_t pitch;
};
struct ConstPlane {
    const void* data;
    uint32_t pitch;
};

// Swapchain pixels -> fgsr input colour (fgsr_format_for(kind)).
void to_fgsr(PixelKind kind, ConstPlane src, Plane dst, uint32_t width, uint32_t height);
// fgsr output colour (fgsr_format_for(kind)) -> swapchain pixels.
void from_fgsr(PixelKind kind, ConstPlane src, Plane dst, uint32_t width, uint32_t height);
// fgsr colour of `format` -> RGBA8 sRGB-encoded bytes (frame dumps).
void fgsr_to_rgba8(fgsr_color_format format, ConstPlane src, Plane dst, uint32_t width, uint32_t height);

float half_to_float(uint16_t h);
uint16_t float_to_half(float f);

} // namespace fgsr::layer
