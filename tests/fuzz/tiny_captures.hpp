// Tiny captures of each importer's layout (fgsr's format, Blender fg, Mob-FGSR PNG), 4x3 pixels and
// two frames, written with the project's own writers. fuzz_capture replaces one file of them with
// its input; make_seeds writes the same files as seeds. Header-only; errors abort (the folder is
// the fuzzer's own).
#pragma once

#include "fuzz_support.hpp"

#include <fgsr/capture/exr_io.hpp>
#include <fgsr/capture/fgsr_format.hpp>
#include <fgsr/capture/image_io.hpp>

#include <cstddef>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace fgsr::fuzz {

inline constexpr uint32_t kTinyWidth = 4, kTinyHeight = 3;

// Deterministic values in [0, 1) for pixel i of plane p.
inline float tiny_value(size_t i, size_t p) {
    return float((i * 7 + p * 13) % 17) / 17.f;
}

inline ImageRGBA tiny_rgba() {
    ImageRGBA img;
    img.width = kTinyWidth;
    img.height = kTinyHeight;
    img.rgba.resize(size_t(kTinyWidth) * kTinyHeight * 4);
    for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = tiny_value(i, 0);
    return img;
}

// dir/manifest.json, dir/frames/0000.exr, 0001.exr, dir/gt/0000.exr (fgsr's own format).
inline void write_tiny_fgsr(const std::filesystem::path& dir) {
    capture::Capture c;
    c.name = "tiny";
    c.format.width = kTinyWidth;
    c.format.height = kTinyHeight;
    c.format.color_format = ColorFormat::rgba16f_linear;
    c.format.mv_format = MvFormat::rg32f;
    c.ground_truth_kind = capture::GroundTruth::halfway;
    const size_t n = size_t(kTinyWidth) * kTinyHeight;
    for (int k = 0; k < 2; ++k) {
        capture::Frame f;
        f.color.assign(n * 8, std::byte(0x3c));
        std::vector<float> depth(n, 1.f + float(k));
        f.depth.resize(n * 4);
        std::memcpy(f.depth.data(), depth.data(), f.depth.size());
        if (k > 0) f.mv.assign(n * 8, std::byte(0));
        f.jitter_x = 0.25f * float(k);
        c.inputs.push_back(std::move(f));
    }
    c.ground_truth.push_back(tiny_rgba());
    auto r = capture::save_fgsr(c, dir);
    FGSR_FUZZ_CHECK(r.ok());
}

// A multichannel EXR with Blender's channel names (`color`: Combined RGBA, `aux`: Depth.Z and
// Vector.XY).
inline capture::ExrImage tiny_blender_exr(bool color, bool aux) {
    capture::ExrImage img;
    img.width = kTinyWidth;
    img.height = kTinyHeight;
    std::vector<std::string> names;
    if (color)
        names = {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                 "ViewLayer.Combined.A"};
    if (aux)
        for (const char* a : {"ViewLayer.Depth.Z", "ViewLayer.Vector.X", "ViewLayer.Vector.Y"})
            names.push_back(a);
    for (size_t p = 0; p < names.size(); ++p) {
        capture::ExrChannel ch;
        ch.name = names[p];
        ch.type = color && p < 4 ? capture::ExrPixel::half : capture::ExrPixel::float32;
        ch.data.resize(size_t(kTinyWidth) * kTinyHeight);
        for (size_t i = 0; i < ch.data.size(); ++i) ch.data[i] = tiny_value(i, p);
        img.channels.push_back(std::move(ch));
    }
    return img;
}

// dir/capture.json (kind fg), dir/in/0001.exr, 0002.exr, dir/in_aux/ the same, dir/gt/0001.exr.
inline void write_tiny_blender(const std::filesystem::path& dir) {
    for (const char* sub : {"in", "in_aux", "gt"}) std::filesystem::create_directories(dir / sub);
    const std::string meta = R"({"kind": "fg", "width": 4, "height": 3})";
    write_file(dir / "capture.json", {reinterpret_cast<const uint8_t*>(meta.data()), meta.size()});
    for (const char* name : {"0001.exr", "0002.exr"}) {
        FGSR_FUZZ_CHECK(capture::write_exr(dir / "in" / name, tiny_blender_exr(true, false)).ok());
        FGSR_FUZZ_CHECK(capture::write_exr(dir / "in_aux" / name, tiny_blender_exr(false, true)).ok());
    }
    FGSR_FUZZ_CHECK(capture::write_exr(dir / "gt" / "0001.exr", tiny_blender_exr(true, false)).ok());
}

// dir/HR_Inputs/{view,depth,motion_vectors_x,motion_vectors_y}/0000.png, 0001.png (Mob-FGSR).
inline void write_tiny_mobfgsr(const std::filesystem::path& dir) {
    capture::Image8 img;
    img.width = kTinyWidth;
    img.height = kTinyHeight;
    img.rgba.resize(size_t(kTinyWidth) * kTinyHeight * 4);
    for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = uint8_t(i * 37);
    for (const char* plane : {"view", "depth", "motion_vectors_x", "motion_vectors_y"}) {
        const auto sub = dir / "HR_Inputs" / plane;
        std::filesystem::create_directories(sub);
        for (const char* name : {"0000.png", "0001.png"})
            FGSR_FUZZ_CHECK(capture::write_png8(sub / name, img).ok());
    }
}

} // namespace fgsr::fuzz
