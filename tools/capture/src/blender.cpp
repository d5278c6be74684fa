// Blender capture importer (layout and conventions: shared/captures/README.md, "blender/").
//
// Channels: ViewLayer.Combined.{R,G,B,A} (half, linear), ViewLayer.Depth.Z (float, linear view
// depth), ViewLayer.Vector.{X,Y} (float, pixels; the previous position of pixel (x, y) is
// (x + X, y - Y), i.e. to_previous with +y up). Frames keep these values untouched and declare the
// matching conventions; the engine's ingest converts.
#include "capture_internal.hpp"

#include <cmath>
#include <exception>

namespace fgsr::capture {

namespace {

using detail::io_error;
namespace fs = std::filesystem;

const std::vector<std::string> kColorChannels = {"ViewLayer.Combined.R", "ViewLayer.Combined.G",
                                                 "ViewLayer.Combined.B", "ViewLayer.Combined.A"};
const std::vector<std::string> kAuxChannels = {"ViewLayer.Depth.Z", "ViewLayer.Vector.X",
                                               "ViewLayer.Vector.Y"};

Result<void> check_size(const fs::path& p, const ExrImage& img, uint32_t w, uint32_t h) {
    if (img.width != w || img.height != h)
        return make_error(Errc::size_mismatch, p.string() + ": image is " + std::to_string(img.width) + "x" +
                                                   std::to_string(img.height) + ", expected " +
                                                   std::to_string(w) + "x" + std::to_string(h));
    return {};
}

// Reads `path`'s Combined channels as linear RGBA.
Result<ImageRGBA> read_combined(const fs::path& path, uint32_t w, uint32_t h) {
    auto img = read_exr(path, kColorChannels);
    if (!img) return img.error();
    FGSR_TRY(check_size(path, *img, w, h));
    const auto& ch = img->channels;
    return detail::make_image(w, h, ch[0].data.data(), ch[1].data.data(), ch[2].data.data(),
                              ch[3].data.data());
}

struct BlenderMeta {
    std::string kind;
    uint32_t width = 0, height = 0, hr_width = 0, hr_height = 0;
    std::vector<std::pair<float, float>> jitter; // Blender camera shift, LR pixels, +y up
};

Result<BlenderMeta> parse_meta(const fs::path& file) {
    auto j = detail::read_json(file);
    if (!j) return j.error();
    BlenderMeta m;
    try {
        m.kind = j->value("kind", std::string());
        m.width = detail::json_uint32_or(*j, "width", 0);
        m.height = detail::json_uint32_or(*j, "height", 0);
        m.hr_width = detail::json_uint32_or(*j, "hr_width", 0);
        m.hr_height = detail::json_uint32_or(*j, "hr_height", 0);
        if (j->contains("jitter_camera_shift_px")) {
            for (const auto& e : j->at("jitter_camera_shift_px")) {
                if (!e.is_array() || e.size() != 2)
                    return io_error(file, "jitter_camera_shift_px entry is not [x, y]");
                m.jitter.emplace_back(detail::json_float(e.at(0)), detail::json_float(e.at(1)));
            }
        }
    } catch (const std::exception& e) {
        return io_error(file, std::string("malformed field: ") + e.what());
    }
    if (m.kind != "fg" && m.kind != "sr")
        return make_error(Errc::unsupported,
                          file.string() + ": unknown kind '" + m.kind + "' (expected fg or sr)");
    return m;
}

} // namespace

Result<Capture> load_blender(const fs::path& dir, size_t max_frames) {
    const fs::path meta_file = dir / "capture.json";
    auto meta = parse_meta(meta_file);
    if (!meta) return meta.error();
    const bool fg = meta->kind == "fg";

    const fs::path color_dir = dir / (fg ? "in" : "lr");
    auto files = detail::numbered_files(color_dir, ".exr");
    if (!files) return files.error();
    if (files->empty()) return make_error(Errc::empty_input, color_dir.string() + ": no NNNN.exr frames");
    if (files->size() > max_frames) files->resize(max_frames);

    Capture c;
    c.name = dir.filename().string();
    if (c.name.empty()) c.name = dir.parent_path().filename().string();
    c.source = "blender";
    c.ground_truth_kind = fg ? GroundTruth::halfway : GroundTruth::consecutive;

    uint32_t w = meta->width, h = meta->height;
    for (size_t i = 0; i < files->size(); ++i) {
        const auto& nf = (*files)[i];
        const fs::path aux_path = fg ? dir / "in_aux" / nf.path.filename() : nf.path;
        // One read per file: the sr layout holds all planes in lr/NNNN.exr.
        std::vector<std::string> wanted = kAuxChannels;
        if (!fg) wanted.insert(wanted.begin(), kColorChannels.begin(), kColorChannels.end());
        auto aux = read_exr(aux_path, wanted);
        if (!aux) return aux.error();
        if (w == 0 || h == 0) {
            w = aux->width;
            h = aux->height;
        }
        FGSR_TRY(check_size(aux_path, *aux, w, h));
        const size_t n = size_t(w) * h;
        const size_t base = fg ? 0 : 4; // index of Depth.Z in aux->channels
        Frame f;
        if (fg) {
            auto col = read_exr(nf.path, kColorChannels);
            if (!col) return col.error();
            FGSR_TRY(check_size(nf.path, *col, w, h));
            const auto& ch = col->channels;
            f.color = detail::pack_rgba16f(ch[0].data.data(), ch[1].data.data(), ch[2].data.data(),
                                           ch[3].data.data(), n);
        } else {
            const auto& ch = aux->channels;
            f.color = detail::pack_rgba16f(ch[0].data.data(), ch[1].data.data(), ch[2].data.data(),
                                           ch[3].data.data(), n);
        }
        f.depth = detail::floats_to_bytes(aux->channels[base].data);
        // The first frame's vectors are all zero (no earlier frame was rendered): unknown.
        if (i > 0)
            f.mv = detail::pack_rg32f(aux->channels[base + 1].data.data(),
                                      aux->channels[base + 2].data.data(), n);
        if (!fg && !meta->jitter.empty()) {
            // lr/N was rendered with camera shift jitter[N-1] (LR pixels, +y up). A camera shifted by
            // s samples the unshifted image at pixel centre + s, so the sample offset is (sx, -sy)
            // in x-right / y-down pixels.
            const long idx = nf.number - 1;
            if (idx < 0 || size_t(idx) >= meta->jitter.size())
                return io_error(meta_file,
                                "no jitter_camera_shift_px entry for " + nf.path.filename().string());
            f.jitter_x = meta->jitter[size_t(idx)].first;
            f.jitter_y = -meta->jitter[size_t(idx)].second;
        }
        c.inputs.push_back(std::move(f));
    }

    c.format = FrameFormat{.width = w,
                           .height = h,
                           .color_format = ColorFormat::rgba16f_linear,
                           .mv_format = MvFormat::rg32f,
                           .conventions = Conventions{.depth_kind = DepthKind::linear,
                                                      .mv_units = MvUnits::pixels,
                                                      .mv_direction = MvDirection::to_previous,
                                                      .mv_y_up = true}};

    if (fg) {
        // gt/N lies halfway between in/N and the next input: one per input except the last.
        for (size_t i = 0; i + 1 < files->size(); ++i) {
            const fs::path p = dir / "gt" / (*files)[i].path.filename();
            auto img = read_combined(p, w, h);
            if (!img) return img.error();
            c.ground_truth.push_back(std::move(*img));
        }
    } else {
        std::error_code ec;
        if (fs::is_directory(dir / "hr", ec)) {
            uint32_t hw = meta->hr_width, hh = meta->hr_height;
            for (const auto& nf : *files) {
                const fs::path p = dir / "hr" / nf.path.filename();
                if (hw == 0 || hh == 0) {
                    auto probe = read_exr(p, kColorChannels);
                    if (!probe) return probe.error();
                    hw = probe->width;
                    hh = probe->height;
                }
                auto img = read_combined(p, hw, hh);
                if (!img) return img.error();
                c.hr_reference.push_back(std::move(*img));
            }
            c.hr_format = c.format;
            c.hr_format.width = hw;
            c.hr_format.height = hh;
            c.hr_format.color_format = ColorFormat::rgba32f_linear;
        }
    }
    return c;
}

} // namespace fgsr::capture
