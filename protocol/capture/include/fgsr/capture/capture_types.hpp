// The plain capture types of fgsr_capture_format: a capture is a sequence of rendered frames plus
// ground truth, in one of the engine's accepted input formats (fgsr/core/types.hpp). The loaders
// (fgsr/capture/capture.hpp, in the tools) and fgsr's own format (fgsr_format.hpp) produce them.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace fgsr::capture {

struct Frame {
    std::vector<std::byte> color; // format.color_format
    std::vector<std::byte> depth; // 32-bit float per pixel, format.conventions.depth_kind
    std::vector<std::byte> mv;    // format.mv_format; empty when the vectors are unknown
    float jitter_x = 0.f;         // camera jitter of this frame in pixels (x right, y down); 0 if none
    float jitter_y = 0.f;
    bool reset = false; // scene cut: the engine forgets the earlier frames (FrameView::reset)

    // The frame as the engine takes it, jitter and scene cut included.
    FrameView view() const { return FrameView{color, depth, mv, jitter_x, jitter_y, reset}; }
};

enum class GroundTruth {
    halfway,     // ground_truth[k] is the instant halfway between inputs k and k+1 (Blender fg)
    consecutive, // inputs are consecutive rendered frames; evaluation uses every other one as input
};

struct Capture {
    std::string name;          // short name for reports ("toss-fg", "mobfgsr-bunker", ...)
    std::string source;        // "blender", "mobfgsr", "fgsr", "synthetic"
    FrameFormat format;        // of every input frame
    std::vector<Frame> inputs; // rendered frames in time order
    GroundTruth ground_truth_kind = GroundTruth::consecutive;
    std::vector<ImageRGBA> ground_truth; // halfway only: linear RGBA
    bool composed_vectors = false;       // set by make_half_rate()

    // Optional high-resolution reference (super resolution captures), one per input.
    FrameFormat hr_format{};
    std::vector<ImageRGBA> hr_reference;
    // High-resolution references of the halfway instants (make_half_rate of a capture with
    // hr_reference): hr_ground_truth[k] lies between inputs k and k+1, like ground_truth[k].
    std::vector<ImageRGBA> hr_ground_truth;
};

// Frame limit for loaders: load at most this many frames (the first ones, in time order).
inline constexpr size_t kAllFrames = static_cast<size_t>(-1);

} // namespace fgsr::capture
