// PNG (libpng, low-level API) readers and writers (OpenEXR: ../format/exr_io.cpp). libpng reports errors
// through longjmp; every setjmp lives in a function whose only automatic state is a reference to a
// heap/caller-owned struct, so nothing indeterminate survives the jump.
#include "capture_internal.hpp"

#include <fgsr/capture/image_io.hpp>
#include <fgsr/engine/color.hpp>

#include <png.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <thread>

namespace fgsr::capture {

namespace fs = std::filesystem;

namespace {

using detail::consistent;
using detail::io_error;

// ---------------------------------------------------------------------------------------------
// PNG

struct PngState {
    FILE* file = nullptr;
    png_structp png = nullptr;
    png_infop info = nullptr;
    std::vector<uint8_t> pixels;
    std::vector<png_bytep> rows;
    uint32_t width = 0;
    uint32_t height = 0;
    int channels = 4; // for writing: 3 (RGB) or 4 (RGBA)
    char message[256] = {};
};

extern "C" void png_error_cb(png_structp png, png_const_charp msg) {
    auto* s = static_cast<PngState*>(png_get_error_ptr(png));
    std::snprintf(s->message, sizeof(s->message), "%s", msg ? msg : "libpng error");
    longjmp(png_jmpbuf(png), 1);
}

extern "C" void png_warning_cb(png_structp, png_const_charp) {}

constexpr uint32_t kMaxPngSide = 1u << 15;

// Returns false with s.message set on failure. Only `s` (a reference) is live across setjmp.
bool png_read_impl(PngState& s) {
    if (setjmp(png_jmpbuf(s.png))) return false;
    png_init_io(s.png, s.file);
    png_read_info(s.png, s.info);
    s.width = png_get_image_width(s.png, s.info);
    s.height = png_get_image_height(s.png, s.info);
    if (s.width == 0 || s.height == 0 || s.width > kMaxPngSide || s.height > kMaxPngSide) {
        std::snprintf(s.message, sizeof(s.message), "unsupported PNG size %ux%u", s.width, s.height);
        return false;
    }
    const int color_type = png_get_color_type(s.png, s.info);
    const int bit_depth = png_get_bit_depth(s.png, s.info);
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(s.png);
    if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(s.png);
    if (png_get_valid(s.png, s.info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(s.png);
    if (bit_depth == 16) png_set_strip_16(s.png);
    if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(s.png);
    if (!(color_type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(s.png, s.info, PNG_INFO_tRNS))
        png_set_filler(s.png, 0xff, PNG_FILLER_AFTER);
    png_set_interlace_handling(s.png);
    png_read_update_info(s.png, s.info);
    if (png_get_rowbytes(s.png, s.info) != size_t(s.width) * 4) {
        std::snprintf(s.message, sizeof(s.message), "unexpected PNG row layout");
        return false;
    }
    try {
        s.pixels.resize(size_t(s.width) * s.height * 4);
        s.rows.resize(s.height);
    } catch (const std::bad_alloc&) {
        std::snprintf(s.message, sizeof(s.message), "out of memory for %ux%u pixels", s.width, s.height);
        return false;
    }
    for (uint32_t y = 0; y < s.height; ++y) s.rows[y] = s.pixels.data() + size_t(y) * s.width * 4;
    png_read_image(s.png, s.rows.data());
    png_read_end(s.png, nullptr);
    return true;
}

bool png_write_impl(PngState& s) {
    if (setjmp(png_jmpbuf(s.png))) return false;
    png_init_io(s.png, s.file);
    png_set_IHDR(s.png, s.info, s.width, s.height, 8,
                 s.channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(s.png, s.info);
    png_write_image(s.png, s.rows.data());
    png_write_end(s.png, nullptr);
    return true;
}

// Writes s.pixels (s.channels bytes per pixel) to `path`.
Result<void> write_png_pixels(const fs::path& path, PngState& s) {
    s.rows.resize(s.height);
    for (uint32_t y = 0; y < s.height; ++y)
        s.rows[y] = s.pixels.data() + size_t(y) * s.width * size_t(s.channels);
    s.file = std::fopen(path.c_str(), "wb");
    if (!s.file) return io_error(path, std::string("cannot open for writing: ") + std::strerror(errno));
    s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s, png_error_cb, png_warning_cb);
    if (s.png) s.info = png_create_info_struct(s.png);
    bool ok = s.png && s.info && png_write_impl(s);
    if (s.png) png_destroy_write_struct(&s.png, s.info ? &s.info : nullptr);
    if (std::fclose(s.file) != 0) ok = false;
    s.file = nullptr;
    if (!ok)
        return io_error(path, std::string("PNG write failed: ") + (s.message[0] ? s.message : "I/O error"));
    return {};
}

} // namespace

// -------------------------------------------------------------------------------------------------

Result<void> write_png(const fs::path& path, const ImageRGBA& img) {
    if (!consistent(img))
        return make_error(Errc::invalid_argument, path.string() + ": empty or inconsistent image");
    PngState s;
    s.width = img.width;
    s.height = img.height;
    s.channels = 3;
    s.pixels.resize(size_t(img.width) * img.height * 3);
    const size_t n = size_t(img.width) * img.height;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            s.pixels[i * 3 + size_t(c)] =
                uint8_t(std::lround(srgb_encode(img.rgba[i * 4 + size_t(c)]) * 255.f));
    return write_png_pixels(path, s);
}

Result<void> write_png8(const fs::path& path, const Image8& img) {
    if (img.width == 0 || img.height == 0 || img.rgba.size() != size_t(img.width) * img.height * 4)
        return make_error(Errc::invalid_argument, path.string() + ": empty or inconsistent image");
    PngState s;
    s.width = img.width;
    s.height = img.height;
    s.channels = 4;
    s.pixels = img.rgba;
    return write_png_pixels(path, s);
}

Result<Image8> read_png(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return io_error(path, "file not found");
    auto s = std::make_unique<PngState>();
    s->file = std::fopen(path.c_str(), "rb");
    if (!s->file) return io_error(path, std::string("cannot open: ") + std::strerror(errno));
    unsigned char sig[8] = {};
    bool ok = std::fread(sig, 1, 8, s->file) == 8 && png_sig_cmp(sig, 0, 8) == 0;
    if (!ok) {
        std::fclose(s->file);
        return io_error(path, "not a PNG file");
    }
    s->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, s.get(), png_error_cb, png_warning_cb);
    if (s->png) s->info = png_create_info_struct(s->png);
    if (s->png && s->info) png_set_sig_bytes(s->png, 8);
    ok = s->png && s->info && png_read_impl(*s);
    if (s->png) png_destroy_read_struct(&s->png, s->info ? &s->info : nullptr, nullptr);
    std::fclose(s->file);
    if (!ok)
        return io_error(path,
                        std::string("PNG read failed: ") + (s->message[0] ? s->message : "out of memory"));
    Image8 img;
    img.width = s->width;
    img.height = s->height;
    img.rgba = std::move(s->pixels);
    return img;
}

} // namespace fgsr::capture
