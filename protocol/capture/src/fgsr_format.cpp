// fgsr's own capture format: manifest.json + one multichannel EXR per frame. The specification
// is docs/CAPTURE_FORMAT.md; keep the two in step (kFormatVersion changes with any incompatible
// change).
#include <fgsr/capture/format_util.hpp>

#include <fgsr/capture/exr_io.hpp>
#include <fgsr/capture/fgsr_format.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace fgsr::capture {

namespace {

using detail::io_error;
using nlohmann::json;
using ojson = nlohmann::ordered_json; // manifests are written in a readable key order
namespace fs = std::filesystem;

constexpr int kFormatVersion = 1;
constexpr const char* kFormatName = "fgsr-capture";

// --- enum names (stable on disk; independent of the engine's to_string) -------------------------

template <class E> struct EnumName {
    E value;
    const char* name;
};

constexpr EnumName<ColorFormat> kColorNames[] = {{ColorFormat::rgba8_srgb, "rgba8_srgb"},
                                                 {ColorFormat::rgba16f_linear, "rgba16f_linear"},
                                                 {ColorFormat::rgba32f_linear, "rgba32f_linear"}};
constexpr EnumName<MvFormat> kMvNames[] = {{MvFormat::rg16f, "rg16f"}, {MvFormat::rg32f, "rg32f"}};
constexpr EnumName<DepthKind> kDepthNames[] = {{DepthKind::linear, "linear"},
                                               {DepthKind::device, "device"},
                                               {DepthKind::device_reversed, "device_reversed"}};
constexpr EnumName<MvUnits> kUnitNames[] = {{MvUnits::pixels, "pixels"}, {MvUnits::uv, "uv"}};
constexpr EnumName<MvDirection> kDirNames[] = {{MvDirection::to_previous, "to_previous"},
                                               {MvDirection::from_previous, "from_previous"}};
constexpr EnumName<GroundTruth> kGtNames[] = {{GroundTruth::halfway, "halfway"},
                                              {GroundTruth::consecutive, "consecutive"}};

template <class E, size_t N> const char* enum_name(const EnumName<E> (&table)[N], E v) {
    for (const auto& e : table)
        if (e.value == v) return e.name;
    return nullptr;
}

template <class E, size_t N> bool enum_parse(const EnumName<E> (&table)[N], const std::string& s, E& out) {
    for (const auto& e : table)
        if (s == e.name) {
            out = e.value;
            return true;
        }
    return false;
}

// Floats: JSON numbers, or the strings "inf", "-inf", "nan" for non-finite values. The number is
// the double nearest to the float's shortest decimal form (0.1f is written 0.1, not
// 0.10000000149011612) whenever that double still rounds back to the same float.
ojson float_to_json(float v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof(buf) - 1, v);
    if (r.ec == std::errc()) {
        *r.ptr = '\0';
        const double d = std::strtod(buf, nullptr);
        if (float(d) == v && std::signbit(float(d)) == std::signbit(v)) return d;
    }
    return double(v);
}

float json_to_float(const json& j) {
    if (j.is_number()) return detail::json_float(j);
    const std::string s = j.get<std::string>(); // throws type_error on anything else
    if (s == "inf") return std::numeric_limits<float>::infinity();
    if (s == "-inf") return -std::numeric_limits<float>::infinity();
    if (s == "nan") return std::numeric_limits<float>::quiet_NaN();
    throw std::runtime_error("not a float: '" + s + "'");
}

std::vector<std::string> color_channel_names(ColorFormat f) {
    if (f == ColorFormat::rgba8_srgb) return {"sRGB.R", "sRGB.G", "sRGB.B", "sRGB.A"};
    return {"R", "G", "B", "A"};
}

// --- frame planes <-> EXR channels ----------------------------------------------------------------

ExrImage frame_to_exr(const FrameFormat& fmt, const FrameView& f) {
    ExrImage img;
    img.width = fmt.width;
    img.height = fmt.height;
    const size_t n = size_t(fmt.width) * fmt.height;
    const auto names = color_channel_names(fmt.color_format);
    for (size_t c = 0; c < 4; ++c) {
        ExrChannel ch;
        ch.name = names[c];
        ch.data.resize(n);
        switch (fmt.color_format) {
        case ColorFormat::rgba8_srgb:
            ch.type = ExrPixel::float32;
            for (size_t i = 0; i < n; ++i) ch.data[i] = float(uint8_t(f.color[i * 4 + c])) / 255.f;
            break;
        case ColorFormat::rgba16f_linear:
            ch.type = ExrPixel::half;
            for (size_t i = 0; i < n; ++i) {
                uint16_t h;
                std::memcpy(&h, f.color.data() + i * 8 + c * 2, 2);
                ch.data[i] = detail::half_to_float(h);
            }
            break;
        case ColorFormat::rgba32f_linear:
            ch.type = ExrPixel::float32;
            for (size_t i = 0; i < n; ++i) std::memcpy(&ch.data[i], f.color.data() + i * 16 + c * 4, 4);
            break;
        }
        img.channels.push_back(std::move(ch));
    }
    img.channels.push_back(ExrChannel{"Z", ExrPixel::float32, detail::bytes_to_floats(f.depth)});
    if (!f.mv.empty()) {
        for (size_t c = 0; c < 2; ++c) {
            ExrChannel ch;
            ch.name = c == 0 ? "MV.X" : "MV.Y";
            ch.data.resize(n);
            if (fmt.mv_format == MvFormat::rg16f) {
                ch.type = ExrPixel::half;
                for (size_t i = 0; i < n; ++i) {
                    uint16_t h;
                    std::memcpy(&h, f.mv.data() + i * 4 + c * 2, 2);
                    ch.data[i] = detail::half_to_float(h);
                }
            } else {
                ch.type = ExrPixel::float32;
                for (size_t i = 0; i < n; ++i) std::memcpy(&ch.data[i], f.mv.data() + i * 8 + c * 4, 4);
            }
            img.channels.push_back(std::move(ch));
        }
    }
    return img;
}

Result<Frame> exr_to_frame(const FrameFormat& fmt, const fs::path& p, bool has_mv) {
    std::vector<std::string> names = color_channel_names(fmt.color_format);
    names.push_back("Z");
    if (has_mv) {
        names.push_back("MV.X");
        names.push_back("MV.Y");
    }
    auto img = read_exr(p, names);
    if (!img) return img.error();
    if (img->width != fmt.width || img->height != fmt.height)
        return make_error(Errc::size_mismatch, p.string() + ": image is " + std::to_string(img->width) + "x" +
                                                   std::to_string(img->height) + ", manifest says " +
                                                   std::to_string(fmt.width) + "x" +
                                                   std::to_string(fmt.height));
    const size_t n = size_t(fmt.width) * fmt.height;
    const auto& ch = img->channels;
    Frame f;
    f.color.resize(n * bytes_per_pixel(fmt.color_format));
    for (size_t c = 0; c < 4; ++c) {
        const float* src = ch[c].data.data();
        switch (fmt.color_format) {
        case ColorFormat::rgba8_srgb:
            for (size_t i = 0; i < n; ++i) {
                const float v = std::isnan(src[i]) ? 0.f : std::clamp(src[i], 0.f, 1.f);
                f.color[i * 4 + c] = std::byte(uint8_t(std::lround(v * 255.f)));
            }
            break;
        case ColorFormat::rgba16f_linear:
            for (size_t i = 0; i < n; ++i) {
                const uint16_t h = detail::float_to_half(src[i]);
                std::memcpy(f.color.data() + i * 8 + c * 2, &h, 2);
            }
            break;
        case ColorFormat::rgba32f_linear:
            for (size_t i = 0; i < n; ++i) std::memcpy(f.color.data() + i * 16 + c * 4, &src[i], 4);
            break;
        }
    }
    f.depth = detail::floats_to_bytes(ch[4].data);
    if (has_mv) {
        if (fmt.mv_format == MvFormat::rg16f) {
            f.mv.resize(n * 4);
            for (size_t i = 0; i < n; ++i)
                for (size_t c = 0; c < 2; ++c) {
                    const uint16_t h = detail::float_to_half(ch[5 + c].data[i]);
                    std::memcpy(f.mv.data() + i * 4 + c * 2, &h, 2);
                }
        } else {
            f.mv = detail::pack_rg32f(ch[5].data.data(), ch[6].data.data(), n);
        }
    }
    return f;
}

Result<ImageRGBA> read_rgba(const fs::path& p, uint32_t w, uint32_t h) {
    auto img = read_exr(p, {"R", "G", "B", "A"});
    if (!img) return img.error();
    if (img->width != w || img->height != h)
        return make_error(Errc::size_mismatch, p.string() + ": image is " + std::to_string(img->width) + "x" +
                                                   std::to_string(img->height) + ", manifest says " +
                                                   std::to_string(w) + "x" + std::to_string(h));
    const auto& ch = img->channels;
    return detail::make_image(w, h, ch[0].data.data(), ch[1].data.data(), ch[2].data.data(),
                              ch[3].data.data());
}

Result<void> check_image(const ImageRGBA& img, uint32_t w, uint32_t h, const std::string& what) {
    if (img.width != w || img.height != h || img.rgba.size() != size_t(w) * h * 4)
        return make_error(Errc::size_mismatch, what + " is " + std::to_string(img.width) + "x" +
                                                   std::to_string(img.height) + " with " +
                                                   std::to_string(img.rgba.size()) + " floats, expected " +
                                                   std::to_string(w) + "x" + std::to_string(h));
    return {};
}

Result<void> ensure_dir(const fs::path& d) {
    std::error_code ec;
    fs::create_directories(d, ec);
    if (ec || !fs::is_directory(d, ec)) return io_error(d, "cannot create directory: " + ec.message());
    return {};
}

} // namespace

std::string fgsr_file_name(size_t index) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%04zu.exr", index);
    return buf;
}

Result<void> write_fgsr_frame(const fs::path& file, const FrameFormat& fmt, const FrameView& f) {
    const size_t cb = bytes_per_pixel(fmt.color_format), mb = bytes_per_pixel(fmt.mv_format);
    if (cb == 0) return make_error(Errc::unsupported, file.string() + ": unknown colour format");
    if (mb == 0) return make_error(Errc::unsupported, file.string() + ": unknown vector format");
    if (fmt.width == 0 || fmt.height == 0)
        return make_error(Errc::empty_input, file.string() + ": empty frame");
    const size_t n = size_t(fmt.width) * fmt.height;
    if (f.color.size() != n * cb)
        return make_error(Errc::size_mismatch,
                          file.string() + ": colour has " + std::to_string(f.color.size()) + " bytes");
    if (f.depth.size() != n * 4)
        return make_error(Errc::size_mismatch,
                          file.string() + ": depth has " + std::to_string(f.depth.size()) + " bytes");
    if (!f.mv.empty() && f.mv.size() != n * mb)
        return make_error(Errc::size_mismatch,
                          file.string() + ": vectors have " + std::to_string(f.mv.size()) + " bytes");
    return write_exr(file, frame_to_exr(fmt, f));
}

Result<void> write_fgsr_manifest(const fs::path& dir, const FgsrManifest& mf) {
    const FrameFormat& fmt = mf.format;
    if (!enum_name(kColorNames, fmt.color_format) || !enum_name(kMvNames, fmt.mv_format) ||
        !enum_name(kDepthNames, fmt.conventions.depth_kind) ||
        !enum_name(kUnitNames, fmt.conventions.mv_units) ||
        !enum_name(kDirNames, fmt.conventions.mv_direction) || !enum_name(kGtNames, mf.ground_truth_kind))
        return make_error(Errc::unsupported, "fgsr capture manifest: unknown format or convention value");
    ojson m;
    m["format"] = kFormatName;
    m["version"] = kFormatVersion;
    m["name"] = mf.name;
    m["source"] = mf.source;
    m["width"] = fmt.width;
    m["height"] = fmt.height;
    m["color_format"] = enum_name(kColorNames, fmt.color_format);
    m["mv_format"] = enum_name(kMvNames, fmt.mv_format);
    m["conventions"] = ojson{{"depth_kind", enum_name(kDepthNames, fmt.conventions.depth_kind)},
                             {"near_plane", float_to_json(fmt.conventions.near_plane)},
                             {"far_plane", float_to_json(fmt.conventions.far_plane)},
                             {"mv_units", enum_name(kUnitNames, fmt.conventions.mv_units)},
                             {"mv_direction", enum_name(kDirNames, fmt.conventions.mv_direction)},
                             {"mv_y_up", fmt.conventions.mv_y_up}};
    m["ground_truth_kind"] = enum_name(kGtNames, mf.ground_truth_kind);
    m["composed_vectors"] = mf.composed_vectors;
    ojson frames = ojson::array();
    for (const auto& f : mf.frames) {
        ojson e{{"file", f.file},
                {"mv", f.mv},
                {"jitter", ojson::array({float_to_json(f.jitter_x), float_to_json(f.jitter_y)})}};
        if (f.reset) e["reset"] = true; // written only where set: readers of v1 without it see no cuts
        frames.push_back(std::move(e));
    }
    m["frames"] = std::move(frames);
    m["ground_truth"] = mf.ground_truth;
    if (mf.hr)
        m["hr"] = ojson{{"width", mf.hr->width},
                        {"height", mf.hr->height},
                        {"reference", mf.hr->reference},
                        {"ground_truth", mf.hr->ground_truth}};

    const fs::path tmp = dir / "manifest.json.tmp";
    std::string text;
    try {
        text = m.dump(1);
    } catch (const std::exception& e) { // name or source that is not valid UTF-8
        return make_error(Errc::invalid_argument,
                          "fgsr capture manifest: cannot encode: " + std::string(e.what()));
    }
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return io_error(tmp, "cannot open for writing");
        out << text << '\n';
        out.flush();
        if (!out) return io_error(tmp, "write failed");
    }
    std::error_code ec;
    fs::rename(tmp, dir / "manifest.json", ec);
    if (ec) return io_error(dir / "manifest.json", "cannot write: " + ec.message());
    return {};
}

Result<void> save_fgsr(const Capture& c, const fs::path& dir) {
    const FrameFormat& fmt = c.format;
    if (fmt.width == 0 || fmt.height == 0 || c.inputs.empty())
        return make_error(Errc::empty_input, "save_fgsr: capture '" + c.name + "' has no frames");
    for (size_t i = 0; i < c.ground_truth.size(); ++i)
        FGSR_TRY(check_image(c.ground_truth[i], fmt.width, fmt.height,
                             "save_fgsr: ground truth " + std::to_string(i)));
    const bool has_hr = c.hr_format.width > 0 || !c.hr_reference.empty() || !c.hr_ground_truth.empty();
    for (size_t i = 0; i < c.hr_reference.size(); ++i)
        FGSR_TRY(check_image(c.hr_reference[i], c.hr_format.width, c.hr_format.height,
                             "save_fgsr: hr reference " + std::to_string(i)));
    for (size_t i = 0; i < c.hr_ground_truth.size(); ++i)
        FGSR_TRY(check_image(c.hr_ground_truth[i], c.hr_format.width, c.hr_format.height,
                             "save_fgsr: hr ground truth " + std::to_string(i)));

    FgsrManifest mf;
    mf.name = c.name;
    mf.source = c.source;
    mf.format = fmt;
    mf.ground_truth_kind = c.ground_truth_kind;
    mf.composed_vectors = c.composed_vectors;
    // Names first: unknown enum values fail before any file is written.
    if (!enum_name(kDepthNames, fmt.conventions.depth_kind) ||
        !enum_name(kUnitNames, fmt.conventions.mv_units) ||
        !enum_name(kDirNames, fmt.conventions.mv_direction) || !enum_name(kGtNames, c.ground_truth_kind) ||
        bytes_per_pixel(fmt.color_format) == 0 || bytes_per_pixel(fmt.mv_format) == 0)
        return make_error(Errc::unsupported, "save_fgsr: unknown format or convention value");
    FGSR_TRY(ensure_dir(dir / "frames"));
    for (size_t i = 0; i < c.inputs.size(); ++i) {
        const std::string rel = "frames/" + fgsr_file_name(i);
        const FrameView view = c.inputs[i].view();
        auto w = write_fgsr_frame(dir / rel, fmt, view);
        if (!w)
            return make_error(w.error().code,
                              "save_fgsr: frame " + std::to_string(i) + ": " + w.error().message);
        mf.frames.push_back(
            {rel, !c.inputs[i].mv.empty(), c.inputs[i].jitter_x, c.inputs[i].jitter_y, c.inputs[i].reset});
    }
    auto write_list = [&](const std::vector<ImageRGBA>& imgs,
                          const std::string& sub) -> Result<std::vector<std::string>> {
        std::vector<std::string> list;
        if (imgs.empty()) return list;
        FGSR_TRY(ensure_dir(dir / sub));
        for (size_t i = 0; i < imgs.size(); ++i) {
            const std::string rel = sub + "/" + fgsr_file_name(i);
            FGSR_TRY(write_exr(dir / rel, imgs[i], ExrPixel::float32));
            list.push_back(rel);
        }
        return list;
    };
    auto gt = write_list(c.ground_truth, "gt");
    if (!gt) return gt.error();
    mf.ground_truth = std::move(*gt);
    if (has_hr) {
        auto ref = write_list(c.hr_reference, "hr");
        if (!ref) return ref.error();
        auto hgt = write_list(c.hr_ground_truth, "hr_gt");
        if (!hgt) return hgt.error();
        mf.hr = FgsrManifest::Hr{c.hr_format.width, c.hr_format.height, std::move(*ref), std::move(*hgt)};
    }
    return write_fgsr_manifest(dir, mf);
}

Result<Capture> load_fgsr(const fs::path& dir, size_t max_frames) {
    const fs::path mfile = dir / "manifest.json";
    auto mj = detail::read_json(mfile);
    if (!mj) return mj.error();
    const json& m = *mj;
    Capture c;
    struct FrameEntry {
        std::string file;
        bool mv = false;
        float jx = 0.f, jy = 0.f;
        bool reset = false;
    };
    std::vector<FrameEntry> entries;
    std::vector<std::string> gt_files, hr_files, hr_gt_files;
    try {
        if (m.value("format", std::string()) != kFormatName)
            return io_error(mfile,
                            std::string("not an fgsr capture manifest (format != \"") + kFormatName + "\")");
        const uint32_t version = detail::json_uint32(m.at("version"));
        if (version != uint32_t(kFormatVersion))
            return make_error(Errc::unsupported,
                              mfile.string() + ": unsupported format version " + std::to_string(version));
        c.name = m.value("name", std::string());
        c.source = m.value("source", std::string("fgsr"));
        c.format.width = detail::json_uint32(m.at("width"));
        c.format.height = detail::json_uint32(m.at("height"));
        const json& cv = m.at("conventions");
        bool ok =
            enum_parse(kColorNames, m.at("color_format").get<std::string>(), c.format.color_format) &&
            enum_parse(kMvNames, m.at("mv_format").get<std::string>(), c.format.mv_format) &&
            enum_parse(kDepthNames, cv.at("depth_kind").get<std::string>(),
                       c.format.conventions.depth_kind) &&
            enum_parse(kUnitNames, cv.at("mv_units").get<std::string>(), c.format.conventions.mv_units) &&
            enum_parse(kDirNames, cv.at("mv_direction").get<std::string>(),
                       c.format.conventions.mv_direction) &&
            enum_parse(kGtNames, m.at("ground_truth_kind").get<std::string>(), c.ground_truth_kind);
        if (!ok) return make_error(Errc::unsupported, mfile.string() + ": unknown format or convention name");
        c.format.conventions.near_plane = json_to_float(cv.at("near_plane"));
        c.format.conventions.far_plane = json_to_float(cv.at("far_plane"));
        c.format.conventions.mv_y_up = cv.at("mv_y_up").get<bool>();
        c.composed_vectors = m.value("composed_vectors", false);
        for (const auto& fe : m.at("frames")) {
            FrameEntry e;
            e.file = fe.at("file").get<std::string>();
            e.mv = fe.at("mv").get<bool>();
            if (fe.contains("jitter")) {
                e.jx = json_to_float(fe.at("jitter").at(0));
                e.jy = json_to_float(fe.at("jitter").at(1));
            }
            e.reset = fe.value("reset", false);
            entries.push_back(std::move(e));
        }
        if (m.contains("ground_truth")) gt_files = m.at("ground_truth").get<std::vector<std::string>>();
        if (m.contains("hr")) {
            const json& hr = m.at("hr");
            c.hr_format = c.format;
            c.hr_format.width = detail::json_uint32(hr.at("width"));
            c.hr_format.height = detail::json_uint32(hr.at("height"));
            c.hr_format.color_format = ColorFormat::rgba32f_linear;
            if (hr.contains("reference")) hr_files = hr.at("reference").get<std::vector<std::string>>();
            if (hr.contains("ground_truth"))
                hr_gt_files = hr.at("ground_truth").get<std::vector<std::string>>();
        }
    } catch (const std::exception& e) {
        return io_error(mfile, std::string("malformed manifest: ") + e.what());
    }
    if (c.format.width == 0 || c.format.height == 0 || c.format.width > 65536 || c.format.height > 65536)
        return io_error(mfile, "invalid size " + std::to_string(c.format.width) + "x" +
                                   std::to_string(c.format.height));
    if (entries.empty()) return make_error(Errc::empty_input, mfile.string() + ": no frames");

    const size_t keep = std::min(entries.size(), max_frames);
    const size_t keep_between = keep > 0 ? keep - 1 : 0; // halfway lists sit between inputs
    for (size_t i = 0; i < keep; ++i) {
        auto f = exr_to_frame(c.format, dir / entries[i].file, entries[i].mv);
        if (!f) return f.error();
        f->jitter_x = entries[i].jx;
        f->jitter_y = entries[i].jy;
        f->reset = entries[i].reset;
        c.inputs.push_back(std::move(*f));
    }
    auto read_list = [&](const std::vector<std::string>& files, size_t limit, uint32_t w, uint32_t h,
                         std::vector<ImageRGBA>& out) -> Result<void> {
        for (size_t i = 0; i < std::min(files.size(), limit); ++i) {
            auto img = read_rgba(dir / files[i], w, h);
            if (!img) return img.error();
            out.push_back(std::move(*img));
        }
        return {};
    };
    const size_t gt_limit = max_frames == kAllFrames                      ? kAllFrames
                            : c.ground_truth_kind == GroundTruth::halfway ? keep_between
                                                                          : keep;
    FGSR_TRY(read_list(gt_files, gt_limit, c.format.width, c.format.height, c.ground_truth));
    FGSR_TRY(read_list(hr_files, max_frames == kAllFrames ? kAllFrames : keep, c.hr_format.width,
                       c.hr_format.height, c.hr_reference));
    FGSR_TRY(read_list(hr_gt_files, max_frames == kAllFrames ? kAllFrames : keep_between, c.hr_format.width,
                       c.hr_format.height, c.hr_ground_truth));
    return c;
}

} // namespace fgsr::capture
