// Helpers of fgsr_capture_format shared with the importers (declared in fgsr/capture/format_util.hpp):
// text and JSON files, plane packing, half floats.
#include <fgsr/capture/format_util.hpp>

#include <Imath/half.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fgsr::capture::detail {

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

uint32_t json_uint32(const nlohmann::json& j) {
    if (j.is_number_unsigned() && j.get<uint64_t>() <= UINT32_MAX) return uint32_t(j.get<uint64_t>());
    if (j.is_number_integer() && j.get<int64_t>() >= 0 && j.get<int64_t>() <= int64_t(UINT32_MAX))
        return uint32_t(j.get<int64_t>());
    throw std::out_of_range(j.dump() + " is not an integer in 0.." + std::to_string(UINT32_MAX));
}

float json_float(const nlohmann::json& j) {
    if (j.is_number_integer()) return float(j.get<int64_t>()); // unsigned too (get converts in range)
    if (j.is_number_float()) {
        const double d = j.get<double>();
        if (std::isfinite(d) && std::fabs(d) <= double(std::numeric_limits<float>::max())) return float(d);
    }
    throw std::out_of_range(j.dump() + " is not a number within the range of a float");
}

uint32_t json_uint32_or(const nlohmann::json& obj, const char* key, uint32_t fallback) {
    return obj.contains(key) ? json_uint32(obj.at(key)) : fallback;
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

} // namespace fgsr::capture::detail
