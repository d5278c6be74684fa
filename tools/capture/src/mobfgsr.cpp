// Mob-FGSR PNG capture importer (layout and conventions: shared/captures/README.md,
#include <fgsr/engine/color.hpp>
// "mobfgsr-bunker").
#include <fgsr/engine/color.hpp>
//
#include <fgsr/engine/color.hpp>
// Conventions. The README states: with m = 2v - 1 (UV units), the previous position of pixel
#include <fgsr/engine/color.hpp>
// (x, y) (x right, y down) is (x - mx*W, y + my*H). The engine's internal vector is
#include <fgsr/engine/color.hpp>
// p_prev - p = (-mx*W, +my*H) pixels, y down. Declared as {uv, from_previous, mv_y_up = true},
#include <fgsr/engine/color.hpp>
// ingest scales by (W, H), negates y (y up -> y down) and negates both (from_previous ->
#include <fgsr/engine/color.hpp>
// to_previous): (mx*W, my*H) -> (mx*W, -my*H) -> (-mx*W, +my*H), the same vector. (Every step is a
#include <fgsr/engine/color.hpp>
// sign flip or a scale per axis, so the order ingest applies them in does not matter.)
#include <fgsr/engine/color.hpp>
#include "capture_internal.hpp"
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
#include <cmath>
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
namespace fgsr::capture {
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
namespace {
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
using detail::io_error;
#include <fgsr/engine/color.hpp>
namespace fs = std::filesystem;
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
const char* const kPlanes[4] = {"view", "depth", "motion_vectors_x", "motion_vectors_y"};
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
// One float packed in RGBA8: v = R/255 + G/255^2 + B/255^3 + A/255^4 (evaluated in double).
#include <fgsr/engine/color.hpp>
inline float unpack_float(const uint8_t* p) {
#include <fgsr/engine/color.hpp>
    constexpr double s = 1.0 / 255.0;
#include <fgsr/engine/color.hpp>
    return float((((double(p[3]) * s + p[2]) * s + p[1]) * s + p[0]) * s);
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
Result<Image8> read_plane(const fs::path& p, uint32_t w, uint32_t h) {
#include <fgsr/engine/color.hpp>
    auto img = read_png(p);
#include <fgsr/engine/color.hpp>
    if (!img) return img.error();
#include <fgsr/engine/color.hpp>
    if (w != 0 && (img->width != w || img->height != h))
#include <fgsr/engine/color.hpp>
        return make_error(Errc::size_mismatch, p.string() + ": image is " + std::to_string(img->width) + "x" +
#include <fgsr/engine/color.hpp>
                                                   std::to_string(img->height) + ", expected " +
#include <fgsr/engine/color.hpp>
                                                   std::to_string(w) + "x" + std::to_string(h));
#include <fgsr/engine/color.hpp>
    return img;
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
} // namespace
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
Result<Capture> load_mobfgsr(const fs::path& dir, bool lr, size_t max_frames) {
#include <fgsr/engine/color.hpp>
    const fs::path base = dir / (lr ? "LR_Inputs" : "HR_Inputs");
#include <fgsr/engine/color.hpp>
    auto files = detail::numbered_files(base / "view", ".png");
#include <fgsr/engine/color.hpp>
    if (!files) return files.error();
#include <fgsr/engine/color.hpp>
    if (files->empty())
#include <fgsr/engine/color.hpp>
        return make_error(Errc::empty_input, (base / "view").string() + ": no NNNN.png frames");
#include <fgsr/engine/color.hpp>
    if (files->size() > max_frames) files->resize(max_frames);
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
    Capture c;
#include <fgsr/engine/color.hpp>
    c.name = dir.filename().string();
#include <fgsr/engine/color.hpp>
    if (c.name.empty()) c.name = dir.parent_path().filename().string();
#include <fgsr/engine/color.hpp>
    if (lr) c.name += "-lr";
#include <fgsr/engine/color.hpp>
    c.source = "mobfgsr";
#include <fgsr/engine/color.hpp>
    c.ground_truth_kind = GroundTruth::consecutive;
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
    uint32_t w = 0, h = 0;
#include <fgsr/engine/color.hpp>
    for (const auto& nf : *files) {
#include <fgsr/engine/color.hpp>
        Image8 planes[4];
#include <fgsr/engine/color.hpp>
        for (int p = 0; p < 4; ++p) {
#include <fgsr/engine/color.hpp>
            auto img = read_plane(base / kPlanes[p] / (nf.stem + ".png"), w, h);
#include <fgsr/engine/color.hpp>
            if (!img) return img.error();
#include <fgsr/engine/color.hpp>
            if (w == 0) {
#include <fgsr/engine/color.hpp>
                w = img->width;
#include <fgsr/engine/color.hpp>
                h = img->height;
#include <fgsr/engine/color.hpp>
            }
#include <fgsr/engine/color.hpp>
            planes[p] = std::move(*img);
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        const size_t n = size_t(w) * h;
#include <fgsr/engine/color.hpp>
        Frame f;
#include <fgsr/engine/color.hpp>
        f.color.resize(n * 4);
#include <fgsr/engine/color.hpp>
        for (size_t i = 0; i < n; ++i) {
#include <fgsr/engine/color.hpp>
            for (size_t k = 0; k < 3; ++k) f.color[i * 4 + k] = std::byte(planes[0].rgba[i * 4 + k]);
#include <fgsr/engine/color.hpp>
            f.color[i * 4 + 3] = std::byte(255);
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        std::vector<float> depth(n), mx(n), my(n);
#include <fgsr/engine/color.hpp>
        for (size_t i = 0; i < n; ++i) {
#include <fgsr/engine/color.hpp>
            depth[i] = unpack_float(&planes[1].rgba[i * 4]);
#include <fgsr/engine/color.hpp>
            mx[i] = 2.f * unpack_float(&planes[2].rgba[i * 4]) - 1.f;
#include <fgsr/engine/color.hpp>
            my[i] = 2.f * unpack_float(&planes[3].rgba[i * 4]) - 1.f;
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        f.depth = detail::floats_to_bytes(depth);
#include <fgsr/engine/color.hpp>
        // Frame 0's vectors point into a frame outside the capture but are real vectors: kept.
#include <fgsr/engine/color.hpp>
        f.mv = detail::pack_rg32f(mx.data(), my.data(), n);
#include <fgsr/engine/color.hpp>
        c.inputs.push_back(std::move(f));
#include <fgsr/engine/color.hpp>
    }
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
    c.format = FrameFormat{.width = w,
#include <fgsr/engine/color.hpp>
                           .height = h,
#include <fgsr/engine/color.hpp>
                           .color_format = ColorFormat::rgba8_srgb,
#include <fgsr/engine/color.hpp>
                           .mv_format = MvFormat::rg32f,
#include <fgsr/engine/color.hpp>
                           .conventions = Conventions{.depth_kind = DepthKind::linear,
#include <fgsr/engine/color.hpp>
                                                      .mv_units = MvUnits::uv,
#include <fgsr/engine/color.hpp>
                                                      .mv_direction = MvDirection::from_previous,
#include <fgsr/engine/color.hpp>
                                                      .mv_y_up = true}};
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
    // The HR views are the authors' reference for super resolution.
#include <fgsr/engine/color.hpp>
    std::error_code ec;
#include <fgsr/engine/color.hpp>
    if (lr && fs::is_directory(dir / "HR_Inputs" / "view", ec)) {
#include <fgsr/engine/color.hpp>
        uint32_t hw = 0, hh = 0;
#include <fgsr/engine/color.hpp>
        for (const auto& nf : *files) {
#include <fgsr/engine/color.hpp>
            auto img = read_plane(dir / "HR_Inputs" / "view" / (nf.stem + ".png"), hw, hh);
#include <fgsr/engine/color.hpp>
            if (!img) return img.error();
#include <fgsr/engine/color.hpp>
            hw = img->width;
#include <fgsr/engine/color.hpp>
            hh = img->height;
#include <fgsr/engine/color.hpp>
            ImageRGBA ref;
#include <fgsr/engine/color.hpp>
            ref.width = hw;
#include <fgsr/engine/color.hpp>
            ref.height = hh;
#include <fgsr/engine/color.hpp>
            ref.rgba.resize(size_t(hw) * hh * 4);
#include <fgsr/engine/color.hpp>
            for (size_t i = 0; i < ref.rgba.size(); ++i)
#include <fgsr/engine/color.hpp>
                ref.rgba[i] = (i % 4 == 3) ? 1.f : srgb8_decode(img->rgba[i]);
#include <fgsr/engine/color.hpp>
            c.hr_reference.push_back(std::move(ref));
#include <fgsr/engine/color.hpp>
        }
#include <fgsr/engine/color.hpp>
        c.hr_format = c.format;
#include <fgsr/engine/color.hpp>
        c.hr_format.width = hw;
#include <fgsr/engine/color.hpp>
        c.hr_format.height = hh;
#include <fgsr/engine/color.hpp>
        c.hr_format.color_format = ColorFormat::rgba32f_linear;
#include <fgsr/engine/color.hpp>
    }
#include <fgsr/engine/color.hpp>
    return c;
#include <fgsr/engine/color.hpp>
}
#include <fgsr/engine/color.hpp>

#include <fgsr/engine/color.hpp>
} // namespace fgsr::capture
#include <fgsr/engine/color.hpp>
