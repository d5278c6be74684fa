// Layout detection (load), colour decoding and the helpers shared by the importers.
#include <fgsr/engine/color.hpp>
#include "capture_internal.hpp"
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
#include <Imath/half.h>
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
#include <algorithm>
#include <fgsr/engine/color.hpp>
#include <cctype>
#include <fgsr/engine/color.hpp>
#include <cmath>
#include <fgsr/engine/color.hpp>
#include <cstring>
#include <fgsr/engine/color.hpp>
#include <fstream>
#include <fgsr/engine/color.hpp>
#include <sstream>
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
namespace fgsr::capture {
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
namespace detail {
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
Result<std::vector<NumberedFile>> numbered_files(const fs::path& dir, const std::string& ext) {
#include <fgsr/engine/color.hpp>
    std::error_code ec;
#include <fgsr/engine/color.hpp>
    if (!fs::is_directory(dir, ec)) return io_error(dir, "directory not found");
#include <fgsr/engine/color.hpp>
    std::vector<NumberedFile> out;
#include <fgsr/engine/color.hpp>
    fs::directory_iterator it(dir, ec), end;
#include <fgsr/engine/color.hpp>
    if (ec) return io_error(dir, "cannot list directory: " + ec.message());
#include <fgsr/engine/color.hpp>
    for (; it != end; it.increment(ec)) {
#include <fgsr/engine/color.hpp>
        if (ec) return io_error(dir, "cannot list directory: " + ec.message());
#include <fgsr/engine/color.hpp>
        const fs::path& p = it->path();
#include <fgsr/engine/color.hpp>
        if (p.extension() != ext) continue;
#include <fgsr/engine/color.hpp>
        const std::string stem = p.stem().string();
#include <fgsr/engine/color.hpp>
        if (stem.empty() || stem.size() > 9 ||
#include <fgsr/engine/color.hpp>
            !std::all_of(stem.begin(), stem.end(), [](char ch) { return std::isdigit(uint8_t(ch)) != 0; }))
#include <fgsr/engine/color.hpp>
            continue;
#include <fgsr/engine/color.hpp>
        out.push_back(NumberedFile{std::stol(stem), stem, p});
#include <fgsr/engine/color.hpp>
    }
#include <fgsr/engine/color.hpp>
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.number < b.number; });
#include <fgsr/engine/color.hpp>
    return out;
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
} // namespace detail
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
Result<Capture> load(const std::filesystem::path& dir, bool prefer_lr, size_t max_frames) {
#include <fgsr/engine/color.hpp>
    namespace fs = std::filesystem;
#include <fgsr/engine/color.hpp>
    std::error_code ec;
#include <fgsr/engine/color.hpp>
    if (!fs::exists(dir, ec)) return detail::io_error(dir, "capture directory not found");
#include <fgsr/engine/color.hpp>
    if (!fs::is_directory(dir, ec)) return detail::io_error(dir, "not a directory");
#include <fgsr/engine/color.hpp>
    if (fs::is_regular_file(dir / "capture.json", ec)) return load_blender(dir, max_frames);
#include <fgsr/engine/color.hpp>
    if (fs::is_regular_file(dir / "manifest.json", ec)) return load_fgsr(dir, max_frames);
#include <fgsr/engine/color.hpp>
    const bool has_hr = fs::is_directory(dir / "HR_Inputs", ec);
#include <fgsr/engine/color.hpp>
    const bool has_lr = fs::is_directory(dir / "LR_Inputs", ec);
#include <fgsr/engine/color.hpp>
    if (has_hr || has_lr) return load_mobfgsr(dir, has_lr && (prefer_lr || !has_hr), max_frames);
#include <fgsr/engine/color.hpp>
    return make_error(Errc::io, dir.string() +
#include <fgsr/engine/color.hpp>
                                    ": unknown capture layout (expected capture.json, manifest.json, "
#include <fgsr/engine/color.hpp>
                                    "HR_Inputs/ or LR_Inputs/)");
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
ImageRGBA decode_color(const FrameFormat& f, const Frame& frame) {
#include <fgsr/engine/color.hpp>
    ImageRGBA img;
#include <fgsr/engine/color.hpp>
    const size_t n = size_t(f.width) * f.height;
#include <fgsr/engine/color.hpp>
    size_t bpp = 0;
#include <fgsr/engine/color.hpp>
    switch (f.color_format) {
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba8_srgb:
#include <fgsr/engine/color.hpp>
        bpp = 4;
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba16f_linear:
#include <fgsr/engine/color.hpp>
        bpp = 8;
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba32f_linear:
#include <fgsr/engine/color.hpp>
        bpp = 16;
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    }
#include <fgsr/engine/color.hpp>
    if (n == 0 || bpp == 0 || frame.color.size() != n * bpp) return img;
#include <fgsr/engine/color.hpp>
    img.width = f.width;
#include <fgsr/engine/color.hpp>
    img.height = f.height;
#include <fgsr/engine/color.hpp>
    img.rgba.resize(n * 4);
#include <fgsr/engine/color.hpp>
    const std::byte* src = frame.color.data();
#include <fgsr/engine/color.hpp>
    switch (f.color_format) {
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba8_srgb:
#include <fgsr/engine/color.hpp>
        for (size_t i = 0; i < n * 4; ++i) {
#include <fgsr/engine/color.hpp>
            const uint8_t b = uint8_t(src[i]);
#include <fgsr/engine/color.hpp>
            img.rgba[i] = (i % 4 == 3) ? float(b) / 255.f : srgb8_decode(b);
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba16f_linear:
#include <fgsr/engine/color.hpp>
        for (size_t i = 0; i < n * 4; ++i) {
#include <fgsr/engine/color.hpp>
            uint16_t h;
#include <fgsr/engine/color.hpp>
            std::memcpy(&h, src + i * 2, 2);
#include <fgsr/engine/color.hpp>
            img.rgba[i] = detail::half_to_float(h);
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    case ColorFormat::rgba32f_linear:
#include <fgsr/engine/color.hpp>
        std::memcpy(img.rgba.data(), src, n * 16);
#include <fgsr/engine/color.hpp>
        break;
#include <fgsr/engine/color.hpp>
    }
#include <fgsr/engine/color.hpp>
    // As the engine's ingest: non-finite -> 0, negative light -> 0, at most the half maximum.
#include <fgsr/engine/color.hpp>
    for (float& v : img.rgba) v = std::isfinite(v) ? std::clamp(v, 0.f, 65504.f) : 0.f;
#include <fgsr/engine/color.hpp>
    return img;
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
} // namespace fgsr::capture
#include <fgsr/engine/color.hpp>
