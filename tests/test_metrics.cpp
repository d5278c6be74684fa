// Display-referred PSNR / SSIM / diff images (tools/capture metrics).
#include <fgsr/capture/metrics.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using fgsr::Errc;
using fgsr::ImageRGBA;
using namespace fgsr::capture;

namespace {

// Independent sRGB transfer functions (the metrics' own are private).
double oetf(double v) {
    v = std::clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}
double eotf(double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

ImageRGBA make_image(uint32_t w, uint32_t h) {
    ImageRGBA im;
    im.width = w;
    im.height = h;
    im.rgba.assign(size_t(w) * h * 4, 1.0f);
    return im;
}

// A textured image given by display values in [0.15, 0.85] (stored linear).
ImageRGBA textured(uint32_t w, uint32_t h, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    ImageRGBA im = make_image(w, h);
    const double f1 = 0.05 + 0.1 * u(rng), f2 = 0.2 + 0.2 * u(rng);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = 0.5 + 0.2 * std::sin(f1 * x + 0.7 * c) * std::cos(f2 * y) +
                                 0.1 * std::sin(f2 * (x + y) + c) + 0.04 * (u(rng) - 0.5);
                im.rgba[(size_t(y) * w + x) * 4 + c] = float(eotf(d));
            }
    return im;
}

// Brute-force SSIM (2-D 11x11 window in double, no separability), for cross-checking.
double ssim_reference(const ImageRGBA& a, const ImageRGBA& b) {
    double g[11], gs = 0;
    for (int i = 0; i < 11; ++i) gs += g[i] = std::exp(-0.5 * (i - 5) * (i - 5) / (1.5 * 1.5));
    for (double& v : g) v /= gs;
    const double C1 = 1e-4, C2 = 9e-4;
    const uint32_t w = a.width, h = a.height;
    double total = 0;
    size_t n = 0;
    for (int c = 0; c < 3; ++c)
        for (uint32_t y = 0; y + 10 < h; ++y)
            for (uint32_t x = 0; x + 10 < w; ++x) {
                double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
                for (int j = 0; j < 11; ++j)
                    for (int i = 0; i < 11; ++i) {
                        const size_t k = (size_t(y + j) * w + x + i) * 4 + c;
                        const double wt = g[i] * g[j];
                        const double p = oetf(a.rgba[k]), q = oetf(b.rgba[k]);
                        mx += wt * p;
                        my += wt * q;
                        xx += wt * p * p;
                        yy += wt * q * q;
                        xy += wt * p * q;
                    }
                const double vx = xx - mx * mx, vy = yy - my * my, cxy = xy - mx * my;
                total += (2 * mx * my + C1) * (2 * cxy + C2) / ((mx * mx + my * my + C1) * (vx + vy + C2));
                ++n;
            }
    return total / double(n);
}

} // namespace

TEST(Metrics, IdenticalImages) {
    const ImageRGBA a = textured(64, 48, 1);
    auto p = psnr(a, a);
    ASSERT_TRUE(p.ok());
    EXPECT_EQ(*p, kPsnrIdentical);
    auto s = ssim(a, a);
    ASSERT_TRUE(s.ok());
    EXPECT_NEAR(*s, 1.0, 1e-9);
}

TEST(Metrics, PsnrConstantDisplayOffsetMatchesClosedForm) {
    // Display values d in [0.2, 0.7] vs d + delta: MSE = delta^2 exactly, PSNR = 10 log10(1/delta^2).
    for (double delta : {0.01, 0.05, 0.2}) {
        ImageRGBA ref = make_image(37, 23), a = make_image(37, 23);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(0.2, 0.7);
        for (size_t i = 0; i < ref.rgba.size(); ++i) {
            if (i % 4 == 3) { // alpha differs wildly and must be ignored
                a.rgba[i] = 123.0f;
                continue;
            }
            const double d = u(rng);
            ref.rgba[i] = float(eotf(d));
            a.rgba[i] = float(eotf(d + delta));
        }
        auto p = psnr(a, ref);
        ASSERT_TRUE(p.ok());
        EXPECT_NEAR(*p, 10.0 * std::log10(1.0 / (delta * delta)), 2e-3) << "delta " << delta;
    }
}

TEST(Metrics, PsnrClampsAndPunishesNan) {
    // Linear values above 1 display as 1: HDR 5.0 vs 1.0 is no error.
    ImageRGBA a = make_image(10, 10), ref = make_image(10, 10);
    for (size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = 5.0f;
    EXPECT_EQ(*psnr(a, ref), kPsnrIdentical);
    // One NaN channel among 300 RGB values: MSE = 1/300.
    a = ref;
    a.rgba[17 * 4 + 1] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NEAR(*psnr(a, ref), 10.0 * std::log10(300.0), 1e-9);
    // NaN in the reference counts too.
    EXPECT_NEAR(*psnr(ref, a), 10.0 * std::log10(300.0), 1e-9);
    // And SSIM drops below 1 rather than becoming NaN.
    ImageRGBA big = textured(32, 32, 3), bad = big;
    bad.rgba[(16 * 32 + 16) * 4] = std::numeric_limits<float>::quiet_NaN();
    auto s = ssim(bad, big);
    ASSERT_TRUE(s.ok());
    EXPECT_TRUE(std::isfinite(*s));
    EXPECT_LT(*s, 0.999);
}

TEST(Metrics, PsnrMasked) {
    ImageRGBA ref = make_image(8, 4), a = make_image(8, 4);
    std::vector<uint8_t> mask(32, 0);
    for (int i = 0; i < 16; ++i) mask[i] = 1;
    // Unmasked half is badly wrong, masked half is off by exactly 0.1 in display value.
    for (size_t p = 0; p < 32; ++p)
        for (int c = 0; c < 3; ++c) {
            ref.rgba[p * 4 + c] = float(eotf(0.5));
            a.rgba[p * 4 + c] = p < 16 ? float(eotf(0.6)) : 0.0f;
        }
    auto p = psnr_masked(a, ref, mask);
    ASSERT_TRUE(p.ok());
    EXPECT_NEAR(*p, 20.0, 1e-3);
    std::vector<uint8_t> none(32, 0);
    EXPECT_EQ(psnr_masked(a, ref, none).error().code, Errc::empty_input);
    std::vector<uint8_t> small(31, 1);
    EXPECT_EQ(psnr_masked(a, ref, small).error().code, Errc::size_mismatch);
}

TEST(Metrics, SsimMatchesBruteForce) {
    const ImageRGBA ref = textured(29, 21, 11);
    ImageRGBA a = textured(29, 21, 12);
    auto s = ssim(a, ref);
    ASSERT_TRUE(s.ok());
    const double expect = ssim_reference(a, ref);
    EXPECT_NEAR(*s, expect, 1e-6);
    EXPECT_LT(*s, 0.99);
}

TEST(Metrics, SsimDecreasesWithNoise) {
    const ImageRGBA ref = textured(96, 64, 5);
    double prev = 1.0;
    for (double sigma : {0.005, 0.02, 0.05, 0.1, 0.2}) {
        ImageRGBA a = ref;
        std::mt19937 rng(99);
        std::normal_distribution<double> n(0.0, sigma);
        for (size_t i = 0; i < a.rgba.size(); ++i)
            if (i % 4 != 3) a.rgba[i] = float(eotf(std::clamp(oetf(ref.rgba[i]) + n(rng), 0.0, 1.0)));
        auto s = ssim(a, ref);
        ASSERT_TRUE(s.ok());
        EXPECT_LT(*s, prev) << "sigma " << sigma;
        prev = *s;
    }
    EXPECT_LT(prev, 0.6);
}

TEST(Metrics, SsimConstantLuminanceShift) {
    // Constant images: variances and covariance are 0, so SSIM per channel is the luminance term
    // (2ab + C1) / (a^2 + b^2 + C1) of the display values a, b.
    const double da[3] = {0.4, 0.1, 0.9}, db[3] = {0.6, 0.15, 0.3};
    ImageRGBA a = make_image(13, 12), b = make_image(13, 12);
    for (size_t p = 0; p < 13 * 12; ++p)
        for (int c = 0; c < 3; ++c) {
            a.rgba[p * 4 + c] = float(eotf(da[c]));
            b.rgba[p * 4 + c] = float(eotf(db[c]));
        }
    const double C1 = 1e-4;
    double expect = 0;
    for (int c = 0; c < 3; ++c)
        expect += (2 * da[c] * db[c] + C1) / (da[c] * da[c] + db[c] * db[c] + C1) / 3.0;
    auto s = ssim(a, b);
    ASSERT_TRUE(s.ok());
    EXPECT_NEAR(*s, expect, 1e-6);

    // A textured image shifted by a constant display offset keeps contrast and structure (both 1),
    // so SSIM stays at the luminance term; it is below 1 and grows as the offset shrinks.
    const ImageRGBA ref = textured(40, 40, 8);
    double prev = 0.0;
    for (double off : {0.2, 0.1, 0.05}) {
        ImageRGBA sh = ref;
        for (size_t i = 0; i < sh.rgba.size(); ++i)
            if (i % 4 != 3) sh.rgba[i] = float(eotf(oetf(ref.rgba[i]) + off));
        const double v = *ssim(sh, ref);
        EXPECT_NEAR(v, ssim_reference(sh, ref), 1e-6);
        EXPECT_GT(v, prev);
        EXPECT_LT(v, 1.0);
        prev = v;
    }
}

TEST(Metrics, SizeErrorsAreValues) {
    const ImageRGBA a = make_image(16, 16), b = make_image(16, 15);
    EXPECT_EQ(psnr(a, b).error().code, Errc::size_mismatch);
    EXPECT_EQ(ssim(a, b).error().code, Errc::size_mismatch);
    EXPECT_EQ(abs_diff_image(a, b).error().code, Errc::size_mismatch);
    ImageRGBA broken = a;
    broken.rgba.pop_back();
    EXPECT_EQ(psnr(broken, a).error().code, Errc::size_mismatch);
    EXPECT_EQ(psnr(ImageRGBA{}, ImageRGBA{}).error().code, Errc::empty_input);
    const ImageRGBA tiny = make_image(10, 40);
    EXPECT_EQ(ssim(tiny, tiny).error().code, Errc::invalid_argument);
    EXPECT_TRUE(psnr(tiny, tiny).ok());
}

TEST(Metrics, AbsDiffImage) {
    ImageRGBA a = make_image(2, 1), b = make_image(2, 1);
    // Pixel 0: display 0.5 vs 0.3 (diff 0.2); pixel 1: NaN vs anything.
    for (int c = 0; c < 3; ++c) {
        a.rgba[c] = float(eotf(0.5));
        b.rgba[c] = float(eotf(0.3));
        a.rgba[4 + c] = std::numeric_limits<float>::quiet_NaN();
    }
    auto d = abs_diff_image(a, b, 2.0f);
    ASSERT_TRUE(d.ok());
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(oetf(d->rgba[c]), 0.4, 1e-5);
        EXPECT_NEAR(d->rgba[4 + c], 1.0, 1e-6);
    }
    EXPECT_EQ(d->rgba[3], 1.0f);
    auto sat = abs_diff_image(a, b, 10.0f);
    EXPECT_NEAR(sat->rgba[0], 1.0, 1e-6);
    EXPECT_EQ(abs_diff_image(a, b, -1.0f).error().code, Errc::invalid_argument);
}

namespace fgsr::capture {
namespace {

TEST(Metrics, TemporalStdClosedForm) {
    // Two pixels: one constant, one alternating between linear 0 and 1 (display 0 and 1): per
    // channel std 0 and 0.5, so the mean over pixels and channels is 0.25.
    TemporalStd t;
    EXPECT_EQ(t.mean_std(), 0.0);
    for (int k = 0; k < 6; ++k) {
        const float v = k % 2 ? 1.f : 0.f;
        ASSERT_TRUE(t.add(ImageRGBA{2, 1, {0.2f, 0.2f, 0.2f, 1.f, v, v, v, 1.f}}));
    }
    EXPECT_EQ(t.frames(), 6u);
    EXPECT_NEAR(t.mean_std(), 0.25, 1e-6);                            // display(1) is 1 within float rounding
    EXPECT_FALSE(t.add(ImageRGBA{1, 2, std::vector<float>(8, 0.f)})); // other size
    EXPECT_FALSE(t.add(ImageRGBA{2, 1, std::vector<float>(4, 0.f)})); // malformed
    EXPECT_FALSE(TemporalStd{}.add(ImageRGBA{}));                     // empty
}

} // namespace
} // namespace fgsr::capture
