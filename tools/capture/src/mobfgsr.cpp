// Mob-FGSR PNG capture importer (layout and conventions: shared/captures/README.md,
// "mobfgsr-bunker").
//
// Conventions. The README states: with m = 2v - 1 (UV units), the previous position of pixel
// (x, y) (x right, y down) is (x - mx*W, y + my*H). The engine's internal vector is
// p_prev - p = (-mx*W, +my*H) pixels, y down. Declared as {uv, from_previous, mv_y_up = true},
// ingest scales by (W, H), negates y (y up -> y down) and negates both (from_previous ->
// to_previous): (mx*W, my*H) -> (mx*W, -my*H) -> (-mx*W, +my*H), the same vector. (Every step is a
// sign flip or a scale per axis, so the order ingest applies them in does not matter.)
#include "capture_internal.hpp"
#include <fgsr/engine/color.hpp>

#include <cmath>

namespace fgsr::capture {

namespace {

using detail::io_error;
namespace fs = std::filesystem;

const char* const kPlanes[4] = {"view", "depth", "motion_vectors_x", "motion_vectors_y"};

// One float packed in RGBA8: v = R/255 + G/255^2 + B/255^3 + A/255^4 (evaluated in double).
inline float unpack_float(const uint8_t* p) {
    constexpr double s = 1.0 / 255.0;
    return float((((double(p[3]) * s + p[2]) * s + p[1]) * s + p[0]) * s);
}

Result<Image8> read_plane(const fs::path& p, uint32_t w, uint32_t h) {
    auto img = read_png(p);
    if (!img) return img.error();
    if (w != 0 && (img->width != w || img->height != h))
        return make_error(Errc::size_mismatch, p.string() + ": image is " + std::to_string(img->width) + "x" +
                                                   std::to_string(img->height) + ", expected " +
                                                   std::to_string(w) + "x" + std::to_string(h));
    return img;
}

} // namespace

Result<Capture> load_mobfgsr(const fs::path& dir, bool lr, size_t max_frames) {
    const fs::path base = dir / (lr ? "LR_Inputs" : "HR_Inputs");
    auto files = detail::numbered_files(base / "view", ".png");
    if (!files) return files.error();
    if (files->empty())
        return make_error(Errc::empty_input, (base / "view").string() + ": no NNNN.png frames");
    if (files->size() > max_frames) files->resize(max_frames);

    Capture c;
    c.name = dir.filename().string();
    if (c.name.empty()) c.name = dir.parent_path().filename().string();
    if (lr) c.name += "-lr";
    c.source = "mobfgsr";
    c.ground_truth_kind = GroundTruth::consecutive;

    uint32_t w = 0, h = 0;
    for (const auto& nf : *files) {
        Image8 planes[4];
        for (int p = 0; p < 4; ++p) {
            auto img = read_plane(base / kPlanes[p] / (nf.stem + ".png"), w, h);
            if (!img) return img.error();
            if (w == 0) {
                w = img->width;
                h = img->height;
            }
            planes[p] = std::move(*img);
        }
        const size_t n = size_t(w) * h;
        Frame f;
        f.color.resize(n * 4);
        for (size_t i = 0; i < n; ++i) {
            for (size_t k = 0; k < 3; ++k) f.color[i * 4 + k] = std::byte(planes[0].rgba[i * 4 + k]);
            f.color[i * 4 + 3] = std::byte(255);
        }
        std::vector<float> depth(n), mx(n), my(n);
        for (size_t i = 0; i < n; ++i) {
            depth[i] = unpack_float(&planes[1].rgba[i * 4]);
            mx[i] = 2.f * unpack_float(&planes[2].rgba[i * 4]) - 1.f;
            my[i] = 2.f * unpack_float(&planes[3].rgba[i * 4]) - 1.f;
        }
        f.depth = detail::floats_to_bytes(depth);
        // Frame 0's vectors point into a frame outside the capture but are real vectors: kept.
        f.mv = detail::pack_rg32f(mx.data(), my.data(), n);
        c.inputs.push_back(std::move(f));
    }

    c.format = FrameFormat{.width = w,
                           .height = h,
                           .color_format = ColorFormat::rgba8_srgb,
                           .mv_format = MvFormat::rg32f,
                           .conventions = Conventions{.depth_kind = DepthKind::linear,
                                                      .mv_units = MvUnits::uv,
                                                      .mv_direction = MvDirection::from_previous,
                                                      .mv_y_up = true}};

    // The HR views are the authors' reference for super resolution.
    std::error_code ec;
    if (lr && fs::is_directory(dir / "HR_Inputs" / "view", ec)) {
        uint32_t hw = 0, hh = 0;
        for (const auto& nf : *files) {
            auto img = read_plane(dir / "HR_Inputs" / "view" / (nf.stem + ".png"), hw, hh);
            if (!img) return img.error();
            hw = img->width;
            hh = img->height;
            ImageRGBA ref;
            ref.width = hw;
            ref.height = hh;
            ref.rgba.resize(size_t(hw) * hh * 4);
            for (size_t i = 0; i < ref.rgba.size(); ++i)
                ref.rgba[i] = (i % 4 == 3) ? 1.f : srgb8_decode(img->rgba[i]);
            c.hr_reference.push_back(std::move(ref));
        }
        c.hr_format = c.format;
        c.hr_format.width = hw;
        c.hr_format.height = hh;
        c.hr_format.color_format = ColorFormat::rgba32f_linear;
    }
    return c;
}

} // namespace fgsr::capture
