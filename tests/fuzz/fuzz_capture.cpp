// Fuzz target: the capture importers (fgsr's format, Blender, Mob-FGSR) on a tiny valid capture of
// each layout with one of its files replaced by the input. The first byte picks the file:
//   0 fgsr manifest.json   1 fgsr frames/0001.exr   2 fgsr gt/0000.exr
//   3 Blender capture.json 4 Blender in_aux/0002.exr 5 Blender in/0001.exr
//   6 Mob-FGSR HR_Inputs/depth/0001.png
// A capture that loads must be consistent: every plane holds width*height pixels of its format,
// ground truth and references match their declared sizes.
#include "fuzz_support.hpp"
#include "tiny_captures.hpp"

#include <fgsr/capture/capture.hpp>

#include <array>
#include <vector>

namespace {

namespace fs = std::filesystem;
using fgsr::capture::Capture;

struct Target {
    const char* file;
    int layout; // 0 fgsr, 1 blender, 2 mobfgsr
};
constexpr std::array<Target, 7> kTargets = {{{"fgsr/manifest.json", 0},
                                             {"fgsr/frames/0001.exr", 0},
                                             {"fgsr/gt/0000.exr", 0},
                                             {"blender/capture.json", 1},
                                             {"blender/in_aux/0002.exr", 1},
                                             {"blender/in/0001.exr", 1},
                                             {"mobfgsr/HR_Inputs/depth/0001.png", 2}}};

std::vector<uint8_t> read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

std::array<std::vector<uint8_t>, kTargets.size()> g_originals;

void check_image(const fgsr::ImageRGBA& img, uint32_t w, uint32_t h) {
    FGSR_FUZZ_CHECK(img.width == w && img.height == h);
    FGSR_FUZZ_CHECK(img.rgba.size() == size_t(w) * h * 4);
}

void check_consistent(const Capture& c) {
    const auto& f = c.format;
    const size_t n = size_t(f.width) * f.height;
    FGSR_FUZZ_CHECK(n > 0);
    FGSR_FUZZ_CHECK(!c.inputs.empty());
    for (const auto& in : c.inputs) {
        FGSR_FUZZ_CHECK(in.color.size() == n * fgsr::bytes_per_pixel(f.color_format));
        FGSR_FUZZ_CHECK(in.depth.size() == n * 4 || (!f.has_depth && in.depth.empty()));
        FGSR_FUZZ_CHECK(in.mv.empty() || in.mv.size() == n * fgsr::bytes_per_pixel(f.mv_format));
    }
    for (const auto& g : c.ground_truth) check_image(g, f.width, f.height);
    for (const auto& r : c.hr_reference) check_image(r, c.hr_format.width, c.hr_format.height);
    for (const auto& r : c.hr_ground_truth) check_image(r, c.hr_format.width, c.hr_format.height);
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    const fs::path& dir = fgsr::fuzz::scratch_dir();
    fgsr::fuzz::write_tiny_fgsr(dir / "fgsr");
    fgsr::fuzz::write_tiny_blender(dir / "blender");
    fgsr::fuzz::write_tiny_mobfgsr(dir / "mobfgsr");
    for (size_t i = 0; i < kTargets.size(); ++i) {
        g_originals[i] = read_all(dir / kTargets[i].file);
        FGSR_FUZZ_CHECK(!g_originals[i].empty());
    }
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const size_t pick = data[0] % kTargets.size();
    const Target& t = kTargets[pick];
    const fs::path& dir = fgsr::fuzz::scratch_dir();
    fgsr::fuzz::write_file(dir / t.file, {data + 1, size - 1});
    fgsr::Result<Capture> c = t.layout == 0   ? fgsr::capture::load_fgsr(dir / "fgsr")
                              : t.layout == 1 ? fgsr::capture::load_blender(dir / "blender")
                                              : fgsr::capture::load_mobfgsr(dir / "mobfgsr", false);
    if (c) check_consistent(*c);
    // The same capture through the detecting loader, with a frame limit.
    auto limited = fgsr::capture::load(dir / (t.layout == 0   ? "fgsr"
                                              : t.layout == 1 ? "blender"
                                                              : "mobfgsr"),
                                       false, 1);
    if (limited) {
        check_consistent(*limited);
        FGSR_FUZZ_CHECK(limited->inputs.size() == 1);
    }
    fgsr::fuzz::write_file(dir / t.file, g_originals[pick]);
    return 0;
}
