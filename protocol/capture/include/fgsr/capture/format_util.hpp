// Helpers of fgsr_capture_format (implemented in format_util.cpp) that the capture importers of the
// tools share: errors naming a file, text and JSON files, plane packing, half floats.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace fgsr::capture::detail {

namespace fs = std::filesystem;

inline Error io_error(const fs::path& p, const std::string& what) {
    return make_error(Errc::io, p.string() + ": " + what);
}

// A non-empty image whose pixel vector holds exactly width * height RGBA values.
inline bool consistent(const ImageRGBA& img) {
    return img.width > 0 && img.height > 0 && img.rgba.size() == size_t(img.width) * img.height * 4;
}

// Whole file as text; Errc::io naming the file on failure.
Result<std::string> read_text(const fs::path& path);

// Parses JSON without exceptions; Errc::io naming the file on a syntax error.
Result<nlohmann::json> read_json(const fs::path& path);

// Plane packing. Sizes in pixels; all planes are tightly packed rows, top row first.
std::vector<std::byte> floats_to_bytes(std::span<const float> v);
std::vector<float> bytes_to_floats(std::span<const std::byte> b);

// Interleaves up to 4 float planes (each n values) into rgba16f bytes (half, round to nearest).
std::vector<std::byte> pack_rgba16f(const float* r, const float* g, const float* b, const float* a, size_t n);
// Interleaves 2 float planes into rg32f bytes.
std::vector<std::byte> pack_rg32f(const float* x, const float* y, size_t n);

// Half <-> float (IEEE binary16 bits).
float half_to_float(uint16_t bits);
uint16_t float_to_half(float f);

// JSON numbers without undefined behaviour: nlohmann's get<uint32_t>() / get<float>() convert a
// double with a plain cast, undefined outside the target's range (found by
// tests/fuzz/fuzz_capture: "width": 4.8e65). Both throw std::out_of_range naming the value (the
// importers catch std::exception): json_uint32 takes an integer in 0..UINT32_MAX, json_float a
// number within +-FLT_MAX.
uint32_t json_uint32(const nlohmann::json& j);
float json_float(const nlohmann::json& j);
// obj[key] through json_uint32, or `fallback` when obj has no such key.
uint32_t json_uint32_or(const nlohmann::json& obj, const char* key, uint32_t fallback);

// Linear RGBA image from four float planes.
ImageRGBA make_image(uint32_t w, uint32_t h, const float* r, const float* g, const float* b, const float* a);

} // namespace fgsr::capture::detail
