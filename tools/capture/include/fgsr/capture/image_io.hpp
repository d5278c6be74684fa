// Image files: 8-bit PNG here; OpenEXR in fgsr/capture/exr_io.hpp (included).
//
// Every function returns errors as values (Errc::io naming the file for anything unreadable,
// unwritable or malformed); no exception escapes. Images are top row first, tightly packed.
// Writers do not create directories: the parent directory of `path` must exist.
#pragma once

#include <fgsr/capture/exr_io.hpp>
#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr::capture {

// The sRGB transfer function is the engine's: fgsr/engine/color.hpp.

// 8-bit RGBA image as stored in a PNG (no transfer function applied).
struct Image8 {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint8_t> rgba; // width*height*4, top row first
};

// Writes `img` (linear RGBA) as an 8-bit RGB PNG: each colour channel is clamped to [0,1],
// sRGB-encoded and rounded to nearest; alpha is dropped. Fails on an empty or inconsistent image.
Result<void> write_png(const std::filesystem::path& path, const ImageRGBA& img);

// Writes raw 8-bit RGBA bytes as an RGBA PNG (no conversion; used for packed-float planes).
Result<void> write_png8(const std::filesystem::path& path, const Image8& img);

// Reads a PNG of any colour type / bit depth as raw 8-bit RGBA: grey is replicated to RGB,
// palettes are expanded, 16-bit samples are reduced to their high byte, and a missing alpha
// channel reads as 255. No gamma or colour-space conversion is applied (bytes as stored).
Result<Image8> read_png(const std::filesystem::path& path);

// OpenEXR: fgsr/capture/exr_io.hpp (read_exr, write_exr), part of fgsr_capture_format.

} // namespace fgsr::capture
