// Layout detection (load), colour decoding and the helpers shared by the importers.
#include "capture_internal.hpp"

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

Result<std::string> read_text(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return io_error(path, "file not found");
    std::ifstream in(path, std::ios::binary);
    if (!in) return io_error(path, "cannot open");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) return io_error(path, "read error");
    return ss.str();
}

Result<nlohmann::json> read_json(const fs::path& path) {
    auto text = read_text(path);
    if (!text) return text.error();
    nlohmann::json j = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return io_error(path, "invalid JSON");
    if (!j.is_object()) return io_error(path, "JSON root is not an object");
    return j;
}

std::vector<std::byte> floats_to_bytes(std::span<const float> v) {
    std::vector<std::byte> out(v.size() * sizeof(float));
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

std::vector<float> bytes_to_floats(std::span<const std::byte> b) {
    std::vector<float> out(b.size() / sizeof(float));
    if (!out.empty()) std::memcpy(out.data(), b.data(), out.size() * sizeof(float));
    return out;
}

float half_to_float(uint16_t bits) {
    Imath::half h;
    h.setBits(bits);
    return float(h);
}

uint16_t float_to_half(float f) {
    return Imath::half(f).bits();
}

std::vector<std::byte> pack_rgba16f(const float* r, const float* g, const float* b, const float* a,
                                    size_t n) {
    std::vector<std::byte> out(n * 8);
    const float* planes[4] = {r, g, b, a};
    for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < 4; ++c) {
            const uint16_t h = float_to_half(planes[c] ? planes[c][i] : (c == 3 ? 1.f : 0.f));
            std::memcpy(out.data() + i * 8 + c * 2, &h, 2);
        }
    return out;
}

std::vector<std::byte> pack_rg32f(const float* x, const float* y, size_t n) {
    std::vector<std::byte> out(n * 8);
    for (size_t i = 0; i < n; ++i) {
        std::memcpy(out.data() + i * 8, x + i, 4);
        std::memcpy(out.data() + i * 8 + 4, y + i, 4);
    }
    return out;
}

ImageRGBA make_image(uint32_t w, uint32_t h, const float* r, const float* g, const float* b, const float* a) {
    ImageRGBA img;
    img.width = w;
    img.height = h;
    const size_t n = size_t(w) * h;
    img.rgba.resize(n * 4);
    for (size_t i = 0; i < n; ++i) {
        img.rgba[i * 4 + 0] = r[i];
        img.rgba[i * 4 + 1] = g[i];
        img.rgba[i * 4 + 2] = b[i];
        img.rgba[i * 4 + 3] = a ? a[i] : 1.f;
    }
    return img;
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
