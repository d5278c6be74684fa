// Frame formats, conventions and the engine's single internal convention.
//
// Internal convention (what every pass after `ingest` sees):
//   colour : linear scene-referred RGBA in [0, 65504], stored as 16-bit half float per channel
//            (shaders/common.h pack_color; passes compute in float; NaN/Inf replaced by 0).
//   depth  : linear view depth, positive, larger is farther, in the session's scene units.
//            Non-finite or non-positive depths are replaced by kFarDepth.
//   motion : pixels of the session's resolution, x right, y down, pointing from the pixel centre in
//            this frame to the position of the same surface point in the previous frame
//            (p_prev = p + mv). Non-finite vectors become 0 and the pixel is flagged as unknown.
// Pixel (x, y) has its centre at (x + 0.5, y + 0.5); row 0 is the top row.
#pragma once

#include <fgsr/protocol.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace fgsr {

inline constexpr float kFarDepth = 1.0e30f;

// Largest width or height of any frame, input or output (protocol.h FGSR_MAX_FRAME_SIDE).
inline constexpr uint32_t kMaxFrameSide = FGSR_MAX_FRAME_SIDE;

enum class ColorFormat : uint32_t {
    rgba8_srgb = 0,     // 4 bytes/pixel, sRGB-encoded, alpha ignored
    rgba16f_linear = 1, // 8 bytes/pixel, linear (HDR allowed)
    rgba32f_linear = 2, // 16 bytes/pixel, linear (HDR allowed)
};

enum class DepthKind : uint32_t {
    linear = 0,          // view depth, larger is farther, any positive unit
    device = 1,          // device depth in [0,1], 0 at near, 1 at far (needs near/far)
    device_reversed = 2, // device depth in [0,1], 1 at near, 0 at far (needs near; far may be infinite)
};

enum class MvFormat : uint32_t {
    rg16f = 0, // 4 bytes/pixel
    rg32f = 1, // 8 bytes/pixel
};

enum class MvUnits : uint32_t { pixels = 0, uv = 1 };

enum class MvDirection : uint32_t {
    to_previous = 0,   // vector points from the current pixel to its previous position
    from_previous = 1, // vector points from the previous position to the current pixel
};

struct Conventions {
    DepthKind depth_kind = DepthKind::linear;
    float near_plane = 0.1f;   // device depth only
    float far_plane = 1000.0f; // device depth only; 0 or +inf means an infinite far plane
    MvUnits mv_units = MvUnits::pixels;
    MvDirection mv_direction = MvDirection::to_previous;
    bool mv_y_up = false; // true when +y of the vector points up on screen
};

struct FrameFormat {
    uint32_t width = 0;
    uint32_t height = 0;
    ColorFormat color_format = ColorFormat::rgba16f_linear;
    MvFormat mv_format = MvFormat::rg32f;
    Conventions conventions{};
    // Colour-only input (FGSR_SESSION_NO_MVS / NO_DEPTH): without vectors the engine estimates
    // them from colour at submit (FrameView::mv is ignored); without depth it orders surfaces by a
    // depth proxy derived from the motion (FrameView::depth may be empty and is ignored).
    bool has_vectors = true;
    bool has_depth = true;
};

// The values of these enums are the protocol's (protocol.h "Formats and conventions").
static_assert(uint32_t(ColorFormat::rgba8_srgb) == FGSR_COLOR_RGBA8_SRGB);
static_assert(uint32_t(ColorFormat::rgba16f_linear) == FGSR_COLOR_RGBA16F_LINEAR);
static_assert(uint32_t(ColorFormat::rgba32f_linear) == FGSR_COLOR_RGBA32F_LINEAR);
static_assert(uint32_t(MvFormat::rg16f) == FGSR_MV_RG16F && uint32_t(MvFormat::rg32f) == FGSR_MV_RG32F);
static_assert(uint32_t(DepthKind::linear) == FGSR_DEPTH_LINEAR &&
              uint32_t(DepthKind::device) == FGSR_DEPTH_DEVICE &&
              uint32_t(DepthKind::device_reversed) == FGSR_DEPTH_DEVICE_REVERSED);
static_assert(uint32_t(MvUnits::pixels) == FGSR_MV_PIXELS && uint32_t(MvUnits::uv) == FGSR_MV_UV);
static_assert(uint32_t(MvDirection::to_previous) == FGSR_MV_TO_PREVIOUS &&
              uint32_t(MvDirection::from_previous) == FGSR_MV_FROM_PREVIOUS);

// Bytes per pixel of a plane (0 for a value outside the enum): the protocol's table.
constexpr size_t bytes_per_pixel(ColorFormat f) {
    return FGSR_COLOR_FORMAT_BYTES(uint32_t(f));
}
constexpr size_t bytes_per_pixel(MvFormat f) {
    return FGSR_MV_FORMAT_BYTES(uint32_t(f));
}
std::string_view to_string(ColorFormat f);
std::string_view to_string(DepthKind k);
std::string_view to_string(MvFormat f);

// One rendered frame as the client hands it over. Planes are tightly packed rows, top row first.
// The engine copies what it needs during submit; the spans need only live for the call.
struct FrameView {
    std::span<const std::byte> color; // width*height*bytes_per_pixel(color_format)
    std::span<const std::byte> depth; // width*height*4 (32-bit float); empty without depth
    std::span<const std::byte> mv;    // width*height*bytes_per_pixel(mv_format), or empty = unknown
    // Camera jitter of this frame: where, relative to each pixel centre, the frame sampled the
    // scene, in pixels (x right, y down), e.g. a Halton(2,3) sequence in [-0.5, 0.5).
    float jitter_x = 0.f;
    float jitter_y = 0.f;
    // Start afresh with this frame (scene cut, camera teleport): no frame is generated from the
    // frames before it, the super-resolution history restarts, and the frame's vectors, which
    // point into the shot before it, are not used as the next pair's frame-0 motion.
    bool reset = false;
};

// A linear RGBA float image on the host (engine outputs, ground truth, metrics).
struct ImageRGBA {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgba; // width*height*4, top row first
};

} // namespace fgsr
