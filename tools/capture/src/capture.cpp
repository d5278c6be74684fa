// Layout detection (load), colour decoding and the helpers shared by the importers.
#include "capture_internal.hpp"
#include <fgsr/engine/color.hpp>

#include <Imath/half.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace fgsr::capture {

namespace detail {

Result<std::vector<NumberedFile>> numbered_files(const fs::path& dir, const std::string& ext) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return io_error(dir, "directory not found");
    std::vector<NumberedFile> out;
    fs::directory_iterator it(dir, ec), end;
    if (ec) return io_error(dir, "cannot list directory: " + ec.message());
    for (; it != end; it.increment(ec)) {
        if (ec) return io_error(dir, "cannot list directory: " + ec.message());
        const fs::path& p = it->path();
        if (p.extension() != ext) continue;
        const std::string stem = p.stem().string();
        if (stem.empty() || stem.size() > 9 ||
            !std::all_of(stem.begin(), stem.end(), [](char ch) { return std::isdigit(uint8_t(ch)) != 0; }))
            continue;
        out.push_back(NumberedFile{std::stol(stem), stem, p});
    }
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.number < b.number; });
    return out;
}

} // namespace detail

Result<Capture> load(const std::filesystem::path& dir, bool prefer_lr, size_t max_frames) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return detail::io_error(dir, "capture directory not found");
    if (!fs::is_directory(dir, ec)) return detail::io_error(dir, "not a directory");
    if (fs::is_regular_file(dir / "capture.json", ec)) return load_blender(dir, max_frames);
    if (fs::is_regular_file(dir / "manifest.json", ec)) return load_fgsr(dir, max_frames);
    const bool has_hr = fs::is_directory(dir / "HR_Inputs", ec);
    const bool has_lr = fs::is_directory(dir / "LR_Inputs", ec);
    if (has_hr || has_lr) return load_mobfgsr(dir, has_lr && (prefer_lr || !has_hr), max_frames);
    return make_error(Errc::io, dir.string() +
                                    ": unknown capture layout (expected capture.json, manifest.json, "
                                    "HR_Inputs/ or LR_Inputs/)");
}

ImageRGBA decode_color(const FrameFormat& f, const Frame& frame) {
    ImageRGBA img;
    const size_t n = size_t(f.width) * f.height;
    size_t bpp = 0;
    switch (f.color_format) {
    case ColorFormat::rgba8_srgb:
        bpp = 4;
        break;
    case ColorFormat::rgba16f_linear:
        bpp = 8;
        break;
    case ColorFormat::rgba32f_linear:
        bpp = 16;
        break;
    }
    if (n == 0 || bpp == 0 || frame.color.size() != n * bpp) return img;
    img.width = f.width;
    img.height = f.height;
    img.rgba.resize(n * 4);
    const std::byte* src = frame.color.data();
    switch (f.color_format) {
    case ColorFormat::rgba8_srgb:
        for (size_t i = 0; i < n * 4; ++i) {
            const uint8_t b = uint8_t(src[i]);
            img.rgba[i] = (i % 4 == 3) ? float(b) / 255.f : srgb8_decode(b);
        }
        break;
    case ColorFormat::rgba16f_linear:
        for (size_t i = 0; i < n * 4; ++i) {
            uint16_t h;
            std::memcpy(&h, src + i * 2, 2);
            img.rgba[i] = detail::half_to_float(h);
        }
        break;
    case ColorFormat::rgba32f_linear:
        std::memcpy(img.rgba.data(), src, n * 16);
        break;
    }
    // As the engine's ingest: non-finite -> 0, negative light -> 0, at most the half maximum.
    for (float& v : img.rgba) v = std::isfinite(v) ? std::clamp(v, 0.f, 65504.f) : 0.f;
    return img;
}

} // namespace fgsr::capture
