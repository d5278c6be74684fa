// The colour-only reference tools end to end: `fgsr convert --colour-png` (the input colour that
// external flow tools read) and tools/reference/dis_vectors.py (OpenCV DIS, the reference of issue
// 12), on the built-in capture against its analytic colour and motion, and on the Mob-FGSR capture
// (half rate) where ../shared/captures exists. The DIS test skips only when python3-opencv is missing.
#include "run_process.hpp"

#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/color.hpp>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using fgsr::test::run_process;

fs::path scratch_dir(const char* what) {
    const fs::path p =
        fs::temp_directory_path() / (std::string("fgsr-test-") + what + "-" + std::to_string(::getpid()));
    fs::remove_all(p);
    return p;
}

std::string numbered(const fs::path& dir, size_t k, const char* ext) {
    char name[32];
    std::snprintf(name, sizeof name, "%04zu.%s", k, ext);
    return (dir / name).string();
}

// A Middlebury .flo file as the contract states it (tools/reference/dis_vectors.py).
struct Flo {
    bool ok = false;
    std::string error;
    int32_t width = 0, height = 0;
    std::vector<glm::vec2> flow; // width*height, top row first
};

Flo read_flo(const std::string& path) {
    Flo f;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        f.error = "cannot open " + path;
        return f;
    }
    float magic = 0.f;
    in.read(reinterpret_cast<char*>(&magic), 4);
    in.read(reinterpret_cast<char*>(&f.width), 4);
    in.read(reinterpret_cast<char*>(&f.height), 4);
    if (!in || magic != 202021.25f || f.width <= 0 || f.height <= 0 || f.width > 16384 || f.height > 16384) {
        f.error = path + ": bad header";
        return f;
    }
    f.flow.resize(size_t(f.width) * size_t(f.height));
    in.read(reinterpret_cast<char*>(f.flow.data()), std::streamsize(f.flow.size() * sizeof(glm::vec2)));
    if (!in || in.peek() != std::ifstream::traits_type::eof()) {
        f.error = path + ": size is not 12 + width*height*8 bytes";
        return f;
    }
    f.ok = true;
    return f;
}

TEST(ColourPng, BuiltinWritesEachInputAsItsSrgbBytes) {
    const fs::path out = scratch_dir("colour-png");
    const auto r = run_process(std::string(FGSR_BIN_DIR) +
                               "/fgsr convert --capture builtin --colour-png --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.out;
    auto cap = fgsr::capture::make_synthetic_capture(fgsr::capture::SceneOptions{}, 11);
    ASSERT_TRUE(cap);
    const uint32_t w = cap->format.width, h = cap->format.height;
    for (size_t k = 0; k < cap->inputs.size(); ++k) {
        auto png = fgsr::capture::read_png(numbered(out, k, "png"));
        ASSERT_TRUE(png) << png.error().message;
        ASSERT_EQ(png->width, w);
        ASSERT_EQ(png->height, h);
        // The displayed colour: the capture's linear colour sRGB-encoded and rounded, alpha opaque.
        const fgsr::ImageRGBA lin = fgsr::capture::decode_color(cap->format, cap->inputs[k]);
        size_t wrong = 0;
        for (size_t i = 0; i < size_t(w) * h; ++i) {
            for (size_t c = 0; c < 3; ++c)
                wrong += png->rgba[i * 4 + c] !=
                         uint8_t(std::lround(fgsr::srgb_encode(lin.rgba[i * 4 + c]) * 255.f));
            wrong += png->rgba[i * 4 + 3] != 255;
        }
        EXPECT_EQ(wrong, 0u) << "frame " << k;
    }
    EXPECT_FALSE(fs::exists(numbered(out, cap->inputs.size(), "png")));
    fs::remove_all(out);
}

TEST(ColourPng, ConsecutiveCaptureIsWrittenAtHalfRate) {
    const fs::path bunker = fs::path(FGSR_SHARED_CAPTURES) / "mobfgsr-bunker";
    if (!fs::exists(bunker)) GTEST_SKIP() << bunker << " not found (captures exist in CI only)";
    const fs::path out = scratch_dir("colour-png-half");
    const auto r = run_process(std::string(FGSR_BIN_DIR) + "/fgsr convert --capture " + bunker.string() +
                               " --lr --colour-png --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.out;
    // Frames 0010 .. 0019: fgsr eval's inputs are 0010, 0012, ..., 0018, and PNG j holds the
    // bytes of view/00(10 + 2j).png (8-bit sRGB in, 8-bit sRGB out).
    for (size_t j = 0; j < 5; ++j) {
        auto got = fgsr::capture::read_png(numbered(out, j, "png"));
        ASSERT_TRUE(got) << got.error().message;
        auto view = fgsr::capture::read_png(numbered(bunker / "LR_Inputs" / "view", 10 + 2 * j, "png"));
        ASSERT_TRUE(view) << view.error().message;
        ASSERT_EQ(got->width, view->width);
        ASSERT_EQ(got->height, view->height);
        size_t wrong = 0;
        for (size_t i = 0; i < size_t(got->width) * got->height; ++i)
            for (size_t c = 0; c < 3; ++c) wrong += got->rgba[i * 4 + c] != view->rgba[i * 4 + c];
        EXPECT_EQ(wrong, 0u) << "half-rate input " << j;
    }
    EXPECT_FALSE(fs::exists(numbered(out, 5, "png")));
    fs::remove_all(out);
}

TEST(DisReference, BuiltinFlowFollowsTheSceneMotion) {
    if (run_process("/usr/bin/python3 -c 'import cv2' 2>/dev/null").status != 0)
        GTEST_SKIP() << "python3-opencv is not installed (/usr/bin/python3 cannot import cv2)";
    const fs::path out = scratch_dir("dis");
    const auto r =
        run_process("/usr/bin/python3 " FGSR_SOURCE_DIR "/tools/reference/dis_vectors.py --capture builtin "
                    "--fgsr " FGSR_BIN_DIR "/fgsr --out " +
                    out.string());
    ASSERT_EQ(r.status, 0) << r.out;

    const fgsr::capture::SceneOptions opt;
    const fgsr::capture::SyntheticScene scene(opt);
    auto cap = fgsr::capture::make_synthetic_capture(opt, 11);
    ASSERT_TRUE(cap);
    const uint32_t w = opt.width, h = opt.height;
    EXPECT_FALSE(fs::exists(numbered(out, 0, "flo"))) << "input 0 has no previous frame";
    EXPECT_FALSE(fs::exists(numbered(out, cap->inputs.size(), "flo")));
    double epe = 0.0, epe_zero = 0.0, epe_negated = 0.0;
    std::vector<float> errs;
    size_t n = 0;
    for (size_t k = 1; k < cap->inputs.size(); ++k) {
        const Flo f = read_flo(numbered(out, k, "flo"));
        ASSERT_TRUE(f.ok) << f.error;
        ASSERT_EQ(uint32_t(f.width), w);
        ASSERT_EQ(uint32_t(f.height), h);
        // The exact motion to the previous input (pixels, y down) of the point at each pixel centre,
        // scored where that point is visible in both frames (same frontmost layer at both ends).
        std::vector<glm::vec2> truth(size_t(w) * h);
        std::memcpy(truth.data(), cap->inputs[k].mv.data(), truth.size() * sizeof(glm::vec2));
        const std::vector<uint8_t> layer = scene.layer_map(double(k));
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const size_t i = size_t(y) * w + x;
                const glm::dvec2 prev = glm::dvec2(x + 0.5, y + 0.5) + glm::dvec2(truth[i]);
                if (prev.x < 0 || prev.y < 0 || prev.x >= w || prev.y >= h) continue;
                if (scene.visible_layer(prev.x, prev.y, double(k) - 1.0) != layer[i]) continue;
                ASSERT_TRUE(std::isfinite(f.flow[i].x) && std::isfinite(f.flow[i].y)) << "frame " << k;
                epe += glm::length(f.flow[i] - truth[i]);
                errs.push_back(glm::length(f.flow[i] - truth[i]));
                epe_zero += glm::length(truth[i]);
                epe_negated += glm::length(f.flow[i] + truth[i]);
                ++n;
            }
    }
    ASSERT_GT(n, size_t(w) * h * 5); // most pixels of the 10 pairs are visible in both frames
    epe /= double(n);
    epe_zero /= double(n);
    epe_negated /= double(n);
    std::sort(errs.begin(), errs.end());
    const float median = errs[errs.size() / 2], p75 = errs[errs.size() * 3 / 4];
    std::printf(
        "DIS on builtin: end-point error median %.3f px, 75th percentile %.3f px, mean %.3f px (zero flow "
        "%.3f, flow against the negated motion %.3f) over %zu pixels\n",
        double(median), double(p75), epe, epe_zero, epe_negated, n);
    // The flow follows the motion to the previous input (sign, axes, units, pixel grid): sub-pixel on
    // most visible pixels (measured: median 0.03 px, 75th percentile 0.1 px); the mean carries the
    // fast thin bars and motion boundaries that DIS smooths over (measured: 1.7 px against 4.1 for
    // zero flow and 6.8 against the negated motion).
    EXPECT_LT(median, 0.25f);
    EXPECT_LT(p75, 0.5f);
    EXPECT_LT(epe, 0.5 * epe_zero);
    EXPECT_LT(epe, 0.3 * epe_negated);
    fs::remove_all(out);
}

} // namespace
