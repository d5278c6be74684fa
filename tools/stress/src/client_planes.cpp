// Plane copies to and from libfgsr_client's slots (fgsr/stress/client_planes.hpp).
#include <fgsr/stress/client_planes.hpp>

#include <cstring>
#include <vector>

namespace fgsr::stress {

ImageRGBA output_image(const fgsr_output& out) {
    ImageRGBA img{out.width, out.height, std::vector<float>(size_t(out.width) * out.height * 4)};
    const size_t row = size_t(out.width) * 16;
    for (uint32_t y = 0; y < out.height; ++y)
        std::memcpy(img.rgba.data() + size_t(y) * out.width * 4,
                    static_cast<const std::byte*>(out.pixels) + size_t(y) * out.row_pitch, row);
    return img;
}

void copy_plane(void* dst, uint32_t pitch, std::span<const std::byte> src, size_t row_bytes, uint32_t rows) {
    if (rows == 0 || src.empty()) return;
    for (uint32_t y = 0; y < rows; ++y)
        std::memcpy(static_cast<std::byte*>(dst) + size_t(y) * pitch, src.data() + size_t(y) * row_bytes,
                    row_bytes);
}

} // namespace fgsr::stress
