// OpenEXR image files of fgsr_capture_format: multichannel read/write and RGBA images.
//
// Every function returns errors as values (Errc::io naming the file for anything unreadable,
// unwritable or malformed); no exception escapes. Images are top row first, tightly packed.
// Writers do not create directories: the parent directory of `path` must exist.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr::capture {

enum class ExrPixel { half, float32 };

struct ExrChannel {
    std::string name;                  // full channel name, e.g. "ViewLayer.Combined.R"
    ExrPixel type = ExrPixel::float32; // storage type in the file
    std::vector<float> data;           // width*height values, top row first (half values widened exactly)
};

struct ExrImage {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<ExrChannel> channels;

    // The channel named `name`, or nullptr.
    const ExrChannel* find(std::string_view name) const;
};

// Reads every channel of an EXR as float. UINT channels are rejected (Errc::unsupported).
Result<ExrImage> read_exr(const std::filesystem::path& path);

// Reads only the named channels (in the given order); a missing channel is an Errc::io error
// naming the file and the channel.
Result<ExrImage> read_exr(const std::filesystem::path& path, const std::vector<std::string>& names);

// Writes all channels of `img` (ZIP compression); each channel is stored with its `type`
// (float32 bit-exact; half rounds to nearest, exact for values that came from a half).
Result<void> write_exr(const std::filesystem::path& path, const ExrImage& img);

// Writes `img` as an RGBA OpenEXR (ZIP compression), half floats by default (values that do not
// fit a half become +-inf, as the half conversion does) or 32-bit floats (exact).
Result<void> write_exr(const std::filesystem::path& path, const ImageRGBA& img,
                       ExrPixel type = ExrPixel::half);

} // namespace fgsr::capture
