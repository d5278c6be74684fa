// Middlebury .flo optical-flow files (the format of OpenCV's writeOpticalFlow and of the DIS
// reference script): the float 202021.25 ("PIEH" in little-endian bytes), int32 width, int32
// height, then width*height pairs of float32 (x, y), row-major, top row first; all little-endian.
// fgsr reads them as pixel vectors, x right, y down, from a frame to the frame before it (the
// engine's internal convention, fgsr/core/types.hpp): `fgsr eval --vectors-from`.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <filesystem>
#include <vector>

namespace fgsr::capture {

inline constexpr float kFloMagic = 202021.25f;

struct FlowField {
    uint32_t width = 0, height = 0;
    std::vector<float> xy; // 2 per pixel: width*height*2
};

// Reads a .flo file. Every size is checked: the magic, width and height in [1, kMaxFrameSide], the
// file holding exactly 12 + width*height*8 bytes (truncated or with trailing bytes: an error).
// Errors: io naming the file and what is wrong with it.
Result<FlowField> read_flo(const std::filesystem::path& path);

// The same, for a file that must hold a width x height field.
// Errors: as read_flo, plus size_mismatch naming both sizes.
Result<FlowField> read_flo(const std::filesystem::path& path, uint32_t width, uint32_t height);

// Writes a .flo file. Errors: invalid_argument (a zero size, or xy not width*height*2 floats), io.
Result<void> write_flo(const std::filesystem::path& path, const FlowField& flow);

} // namespace fgsr::capture
