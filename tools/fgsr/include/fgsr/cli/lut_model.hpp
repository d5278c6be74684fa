// The model `fgsr lut-train` optimises, header-only so that tests/test_lut.cpp checks exactly what
// the trainer runs:
//   - lut_resample(): the engine's LUT resampling (shaders/resample.h, RESAMPLE_LUT) of a whole
//     image at a global shift, bit-for-bit the arithmetic of fgsr::ref::resample_image, plus its
//     adjoint (gradients with respect to the LUT weights and the source image);
//   - ssim_with_grad(): mean SSIM as fgsr::capture::ssim defines it (11x11 Gaussian, sigma 1.5,
//     valid windows only) of one channel, with its analytic gradient;
//   - history images: the training / evaluation images (see make_history_image);
//   - shift sequences: six sub-pixel shifts whose sum is a whole-pixel vector, so the exact result
//     of the repeated resampling is the first image translated by whole pixels;
//   - SR loops: the history resampling inside the engine's `sr` pass (ref::super_resolve) over a
//     few frames of a translating camera with jittered, point-sampled low-resolution input, with
//     the gradient of the outputs with respect to the LUT (sr_loop_forward / sr_loop_backward).
#pragma once

#include <fgsr/core/halton.hpp>
#include <fgsr/core/types.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/reference.hpp>

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

namespace fgsr::cli::lutmodel {

// Linear RGB image, 3 floats per pixel, top row first.
struct RgbImage {
    uint32_t width = 0, height = 0;
    std::vector<float> rgb; // width * height * 3
};

// Per-axis sampling geometry of one resampling step at a global shift, computed with the exact
// float operations of shaders/resample.h (RESAMPLE_LUT): pos = (x + 0.5) + shift; t = pos - 0.5;
// k = floor(t * L + 0.5); base = floor(k / L); bin = k - base * L (the phase rounded to the
// nearest 1/L, phase of the bin = bin / L); taps base - 1 .. base + 2 clamped to [0, n - 1].
struct AxisTaps {
    std::vector<int> bin;                // per output coordinate
    std::vector<std::array<int, 4>> tap; // per output coordinate, clamped source coordinates
};

inline AxisTaps axis_taps(uint32_t n, float shift) {
    AxisTaps a;
    a.bin.resize(n);
    a.tap.resize(n);
    const int hi = int(n) - 1;
    const float levels = float(kLutLevels);
    for (uint32_t x = 0; x < n; ++x) {
        const float pos = (float(x) + 0.5f) + shift;
        const float t = pos - 0.5f;
        const int k = int(std::floor(t * levels + 0.5f));
        const int base = int(std::floor(float(k) / levels));
        a.bin[x] = k - base * int(kLutLevels);
        for (int i = 0; i < 4; ++i) a.tap[x][size_t(i)] = std::clamp(base + i - 1, 0, hi);
    }
    return a;
}

// out(x, y) = sum_{j,i} lut[bin(y, x) * 16 + j * 4 + i] * src(tap_x[i], tap_y[j]), accumulated in
// float in the order j, i, as resample.h does (so the result equals ref::resample_image with
// Resample::lut on the same RGB channels). Precondition: lut.size() == kLutSize.
inline RgbImage lut_resample(const RgbImage& src, glm::vec2 shift, std::span<const float> lut) {
    RgbImage out{src.width, src.height, std::vector<float>(src.rgb.size())};
    const AxisTaps ax = axis_taps(src.width, shift.x), ay = axis_taps(src.height, shift.y);
    const size_t w = src.width;
    for (uint32_t y = 0; y < src.height; ++y)
        for (uint32_t x = 0; x < src.width; ++x) {
            const float* wt = &lut[(size_t(ay.bin[y]) * kLutLevels + size_t(ax.bin[x])) * kLutTaps];
            float s0 = 0.f, s1 = 0.f, s2 = 0.f;
            for (int j = 0; j < 4; ++j) {
                const float* row = &src.rgb[size_t(ay.tap[y][size_t(j)]) * w * 3];
                for (int i = 0; i < 4; ++i) {
                    const float wk = wt[j * 4 + i];
                    const float* p = row + size_t(ax.tap[x][size_t(i)]) * 3;
                    s0 += wk * p[0];
                    s1 += wk * p[1];
                    s2 += wk * p[2];
                }
            }
            float* o = &out.rgb[(size_t(y) * w + x) * 3];
            o[0] = s0;
            o[1] = s1;
            o[2] = s2;
        }
    return out;
}

// Adjoint of lut_resample: given dL/d(out), adds dL/d(lut) to grad_lut (kLutSize values) and, when
// grad_src is non-null, dL/d(src) to *grad_src (src.rgb.size() values, pre-sized by the caller).
inline void lut_resample_backward(const RgbImage& src, glm::vec2 shift, std::span<const float> lut,
                                  std::span<const float> grad_out, std::span<double> grad_lut,
                                  std::vector<float>* grad_src) {
    const AxisTaps ax = axis_taps(src.width, shift.x), ay = axis_taps(src.height, shift.y);
    const size_t w = src.width;
    for (uint32_t y = 0; y < src.height; ++y)
        for (uint32_t x = 0; x < src.width; ++x) {
            const float* g = &grad_out[(size_t(y) * w + x) * 3];
            if (g[0] == 0.f && g[1] == 0.f && g[2] == 0.f) continue;
            const size_t wbase = (size_t(ay.bin[y]) * kLutLevels + size_t(ax.bin[x])) * kLutTaps;
            for (int j = 0; j < 4; ++j) {
                const size_t row = size_t(ay.tap[y][size_t(j)]) * w * 3;
                for (int i = 0; i < 4; ++i) {
                    const size_t p = row + size_t(ax.tap[x][size_t(i)]) * 3;
                    const size_t k = wbase + size_t(j * 4 + i);
                    grad_lut[k] += double(g[0]) * src.rgb[p] + double(g[1]) * src.rgb[p + 1] +
                                   double(g[2]) * src.rgb[p + 2];
                    if (grad_src) {
                        const float wk = lut[k];
                        (*grad_src)[p] += wk * g[0];
                        (*grad_src)[p + 1] += wk * g[1];
                        (*grad_src)[p + 2] += wk * g[2];
                    }
                }
            }
        }
}

// ---- SSIM (one channel) with gradient ------------------------------------------------------------

inline std::array<double, 11> ssim_window() {
    std::array<double, 11> g{};
    double s = 0;
    for (int i = 0; i < 11; ++i) s += g[size_t(i)] = std::exp(-double((i - 5) * (i - 5)) / (2 * 1.5 * 1.5));
    for (double& v : g) v /= s;
    return g;
}

// Valid separable correlation with the 11-tap window: (w-10) x (h-10) result.
inline std::vector<double> filter_valid(const std::vector<double>& in, uint32_t w, uint32_t h) {
    const auto g = ssim_window();
    const uint32_t ow = w - 10, oh = h - 10;
    std::vector<double> tmp(size_t(ow) * h), out(size_t(ow) * oh);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            double s = 0;
            for (int t = 0; t < 11; ++t) s += g[size_t(t)] * in[size_t(y) * w + x + size_t(t)];
            tmp[size_t(y) * ow + x] = s;
        }
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            double s = 0;
            for (int t = 0; t < 11; ++t) s += g[size_t(t)] * tmp[(size_t(y) + size_t(t)) * ow + x];
            out[size_t(y) * ow + x] = s;
        }
    return out;
}

// Transpose of filter_valid: spreads a (w-10) x (h-10) map back onto w x h.
inline std::vector<double> filter_valid_adjoint(const std::vector<double>& in, uint32_t w, uint32_t h) {
    const auto g = ssim_window();
    const uint32_t ow = w - 10, oh = h - 10;
    std::vector<double> tmp(size_t(ow) * h, 0.0), out(size_t(w) * h, 0.0);
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < ow; ++x)
            for (int t = 0; t < 11; ++t)
                tmp[(size_t(y) + size_t(t)) * ow + x] += g[size_t(t)] * in[size_t(y) * ow + x];
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < ow; ++x)
            for (int t = 0; t < 11; ++t)
                out[size_t(y) * w + x + size_t(t)] += g[size_t(t)] * tmp[size_t(y) * ow + x];
    return out;
}

// Mean SSIM of `a` against `ref` (w x h, w, h >= 11; values in display units, data range 1),
// as capture::ssim computes it per channel; *grad (if non-null) receives d(mean SSIM)/d(a).
inline double ssim_with_grad(const std::vector<double>& a, const std::vector<double>& ref, uint32_t w,
                             uint32_t h, std::vector<double>* grad) {
    constexpr double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
    std::vector<double> aa(a.size()), rr(a.size()), ar(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
        aa[i] = a[i] * a[i];
        rr[i] = ref[i] * ref[i];
        ar[i] = a[i] * ref[i];
    }
    const auto mx = filter_valid(a, w, h), my = filter_valid(ref, w, h), exx = filter_valid(aa, w, h),
               eyy = filter_valid(rr, w, h), exy = filter_valid(ar, w, h);
    const size_t n = mx.size();
    std::vector<double> dmu, dxx, dxy;
    if (grad) dmu.resize(n), dxx.resize(n), dxy.resize(n);
    double sum = 0;
    for (size_t q = 0; q < n; ++q) {
        const double ux = mx[q], uy = my[q];
        const double vx = exx[q] - ux * ux, vy = eyy[q] - uy * uy, cxy = exy[q] - ux * uy;
        const double A1 = 2 * ux * uy + C1, A2 = 2 * cxy + C2, B1 = ux * ux + uy * uy + C1, B2 = vx + vy + C2;
        const double s = (A1 * A2) / (B1 * B2);
        sum += s;
        if (grad) {
            dmu[q] = s * (2 * uy / A1 - 2 * uy / A2 - 2 * ux / B1 + 2 * ux / B2);
            dxx[q] = -s / B2;
            dxy[q] = 2 * s / A2;
        }
    }
    const double mean = sum / double(n);
    if (grad) {
        const auto gmu = filter_valid_adjoint(dmu, w, h), gxx = filter_valid_adjoint(dxx, w, h),
                   gxy = filter_valid_adjoint(dxy, w, h);
        grad->resize(a.size());
        for (size_t i = 0; i < a.size(); ++i)
            (*grad)[i] = (gmu[i] + 2 * a[i] * gxx[i] + ref[i] * gxy[i]) / double(n);
    }
    return mean;
}

// Display value the metrics use (clamp to [0,1], sRGB OETF) and its derivative (0 where clamped).
inline double display_value(double v) {
    if (!(v > 0)) return 0;
    if (v >= 1) return 1;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}
inline double display_slope(double v) {
    if (!(v > 0) || v >= 1) return 0;
    return v <= 0.0031308 ? 12.92 : 1.055 / 2.4 * std::pow(v, 1 / 2.4 - 1);
}

// ---- history images ------------------------------------------------------------------------------

// A history image for scale factor S models what the SR history holds at output resolution: the
// scene integrated over a centred box of `footprint` output pixels (1 = the fully converged
// high-resolution image, S = one low-resolution pixel, i.e. nothing accumulated yet).
// `hi` is a source at k x the output resolution (k >= 1 integer); the output is
// floor(hi.width / k) x floor(hi.height / k) and pixel x integrates hi over
// [(x + 0.5) k - footprint k / 2, (x + 0.5) k + footprint k / 2), with fractional coverage of the
// end pixels and clamping at the borders. Separable; exact for any real footprint >= 1/k.
inline RgbImage make_history_image(const RgbImage& hi, uint32_t k, double footprint) {
    const uint32_t ow = hi.width / k, oh = hi.height / k;
    auto weights = [&](uint32_t n_out, uint32_t n_in) {
        // Per output coordinate: first source index and weights (normalised).
        std::vector<std::pair<int, std::vector<double>>> out(n_out);
        const double half = footprint * k / 2;
        for (uint32_t x = 0; x < n_out; ++x) {
            const double c = (x + 0.5) * k, lo = c - half, hi_ = c + half;
            const int first = int(std::floor(lo)), last = int(std::ceil(hi_)) - 1;
            std::vector<double> wv;
            double s = 0;
            for (int i = first; i <= last; ++i) {
                const double cov = std::min(hi_, double(i + 1)) - std::max(lo, double(i));
                wv.push_back(std::max(cov, 0.0));
                s += wv.back();
            }
            for (double& v : wv) v /= s;
            out[x] = {first, std::move(wv)};
            (void)n_in;
        }
        return out;
    };
    const auto wx = weights(ow, hi.width), wy = weights(oh, hi.height);
    std::vector<double> tmp(size_t(ow) * hi.height * 3, 0.0);
    for (uint32_t y = 0; y < hi.height; ++y)
        for (uint32_t x = 0; x < ow; ++x)
            for (size_t t = 0; t < wx[x].second.size(); ++t) {
                const int sx = std::clamp(wx[x].first + int(t), 0, int(hi.width) - 1);
                for (int c = 0; c < 3; ++c)
                    tmp[(size_t(y) * ow + x) * 3 + size_t(c)] +=
                        wx[x].second[t] * hi.rgb[(size_t(y) * hi.width + size_t(sx)) * 3 + size_t(c)];
            }
    RgbImage out{ow, oh, std::vector<float>(size_t(ow) * oh * 3)};
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < ow; ++x)
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                for (size_t t = 0; t < wy[y].second.size(); ++t) {
                    const int sy = std::clamp(wy[y].first + int(t), 0, int(hi.height) - 1);
                    s += wy[y].second[t] * tmp[(size_t(sy) * ow + x) * 3 + size_t(c)];
                }
                out.rgb[(size_t(y) * ow + x) * 3 + size_t(c)] = float(s);
            }
    return out;
}

// ---- shift sequences ----------------------------------------------------------------------------

inline constexpr int kSteps = 6; // six-fold repeated resampling (paper, supplement 5)

struct ShiftSequence {
    std::array<glm::vec2, kSteps> shift{};
    glm::ivec2 total{0, 0}; // exact sum of the shifts (whole pixels)
    int margin = 0;         // border (pixels) whose results depend on clamped taps; excluded
};

// Border whose final results may have read clamped taps: each step reads offsets
// floor(s) - 1 .. floor(s) + 3 (the phase may round up to the next base; +1 spare); the reach
// accumulates.
inline int sequence_margin(const std::array<glm::vec2, kSteps>& s) {
    glm::dvec2 lo(0.0), hi(0.0);
    double reach = 0;
    for (const glm::vec2& v : s) {
        lo += glm::dvec2(std::floor(v.x) - 2, std::floor(v.y) - 2);
        hi += glm::dvec2(std::floor(v.x) + 3, std::floor(v.y) + 3);
        reach = std::max({reach, -lo.x, -lo.y, hi.x, hi.y});
    }
    return int(reach) + 1;
}

// The paper's protocol (supplement Fig. 4): six shifts of +1/2 pixel on both axes (total (3, 3)).
inline ShiftSequence half_pixel_sequence() {
    ShiftSequence q;
    q.shift.fill(glm::vec2(0.5f));
    q.total = glm::ivec2(3);
    q.margin = sequence_margin(q.shift);
    return q;
}

// Random sequence: with probability `half_prob` six shifts of +-1/2 per axis (random signs),
// otherwise five shifts uniform in [-1, 1]^2 and a sixth that brings the sum to the nearest whole
// pixel vector. Every shift is a multiple of 2^-12 so that the sum is exact in float.
template <class Rng> ShiftSequence random_sequence(Rng& rng, double half_prob) {
    ShiftSequence q;
    std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
    auto quant = [](double v) { return float(std::round(v * 4096.0) / 4096.0); };
    if (p(rng) < half_prob) {
        glm::vec2 sum(0.f);
        for (auto& s : q.shift) {
            s = glm::vec2(p(rng) < 0.5 ? -0.5f : 0.5f, p(rng) < 0.5 ? -0.5f : 0.5f);
            sum += s;
        }
        q.total = glm::ivec2(sum);
    } else {
        glm::dvec2 sum(0.0);
        for (int k = 0; k < kSteps - 1; ++k) {
            q.shift[size_t(k)] = glm::vec2(quant(u(rng)), quant(u(rng)));
            sum += glm::dvec2(q.shift[size_t(k)]);
        }
        q.total = glm::ivec2(int(std::round(sum.x)), int(std::round(sum.y)));
        q.shift[kSteps - 1] = glm::vec2(float(q.total.x - sum.x), float(q.total.y - sum.y));
    }
    q.margin = sequence_margin(q.shift);
    return q;
}

// The exact result of the sequence on the interior: src translated by `total` whole pixels,
// cropped to [m, w - m) x [m, h - m) with m = margin (callers crop their result the same way).
inline RgbImage crop(const RgbImage& src, int m, glm::ivec2 offset = glm::ivec2(0)) {
    RgbImage out;
    if (int(src.width) <= 2 * m || int(src.height) <= 2 * m) return out;
    out.width = src.width - uint32_t(2 * m);
    out.height = src.height - uint32_t(2 * m);
    out.rgb.resize(size_t(out.width) * out.height * 3);
    for (uint32_t y = 0; y < out.height; ++y)
        for (uint32_t x = 0; x < out.width; ++x) {
            const int sx = int(x) + m + offset.x, sy = int(y) + m + offset.y;
            for (int c = 0; c < 3; ++c)
                out.rgb[(size_t(y) * out.width + x) * 3 + size_t(c)] =
                    src.rgb[(size_t(sy) * src.width + size_t(sx)) * 3 + size_t(c)];
        }
    return out;
}

// Conversions to the engine's / metrics' types.
inline std::vector<glm::vec4> to_vec4(const RgbImage& im) {
    std::vector<glm::vec4> v(size_t(im.width) * im.height);
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = glm::vec4(im.rgb[i * 3], im.rgb[i * 3 + 1], im.rgb[i * 3 + 2], 1.f);
    return v;
}
inline RgbImage from_vec4(const std::vector<glm::vec4>& v, uint32_t w, uint32_t h) {
    RgbImage im{w, h, std::vector<float>(size_t(w) * h * 3)};
    for (size_t i = 0; i < v.size(); ++i)
        for (int c = 0; c < 3; ++c) im.rgb[i * 3 + size_t(c)] = v[i][c];
    return im;
}
inline ImageRGBA to_rgba(const RgbImage& im) {
    ImageRGBA o{im.width, im.height, std::vector<float>(size_t(im.width) * im.height * 4)};
    for (size_t i = 0; i < size_t(im.width) * im.height; ++i) {
        for (int c = 0; c < 3; ++c) o.rgba[i * 4 + size_t(c)] = im.rgb[i * 3 + size_t(c)];
        o.rgba[i * 4 + 3] = 1.f;
    }
    return o;
}
inline RgbImage from_rgba(const ImageRGBA& im) {
    RgbImage o{im.width, im.height, std::vector<float>(size_t(im.width) * im.height * 3)};
    for (size_t i = 0; i < size_t(im.width) * im.height; ++i)
        for (int c = 0; c < 3; ++c) o.rgb[i * 3 + size_t(c)] = im.rgba[i * 4 + size_t(c)];
    return o;
}

// ---- SR loops ------------------------------------------------------------------------------------
//
// A scene is a high-resolution image `hi` at k x the output resolution, read bilinearly at
// continuous positions (a stand-in for the renderer's continuous scene). The camera translates by
// `velocity` output pixels per frame: output coordinate X of frame t shows the scene at
// hi coordinate (X + origin + t * velocity) * k, so a point at X in frame t was at X + velocity in
// frame t - 1 (the engine's history position h = q + mv * scale with mv = velocity / scale).
// Frame t's input sampled LR pixel (i, j) at its centre plus jitter_t (one sample, aliased: a
// rasteriser), optionally with multiplicative noise (stochastic rendering: sample = c (1 + noise n),
// n standard normal from noise_seed, clamped at 0); its target is the noise-free scene
// box-filtered over each output pixel (4 x 4 samples), an antialiased high-resolution reference.

inline constexpr int kSrFrames = 8; // frames of one SR loop

struct SrLoop {
    float scale = 2.f;
    uint32_t lr_w = 0, lr_h = 0, out_w = 0, out_h = 0;
    glm::vec2 velocity{0.f};                   // output pixels per frame (the history shift)
    std::array<glm::vec2, kSrFrames> jitter{}; // LR pixels, y down, in [-0.5, 0.5)
    std::array<RgbImage, kSrFrames> lr, target;
    int margin = 0; // border (output pixels) excluded from the loss
};

// Bilinear read of hi at continuous position (x, y) in hi pixels (centres at +0.5), clamped.
inline glm::vec3 scene_at(const RgbImage& hi, double x, double y) {
    const double fx = std::clamp(x - 0.5, 0.0, double(hi.width - 1)),
                 fy = std::clamp(y - 0.5, 0.0, double(hi.height - 1));
    const int x0 = std::min(int(fx), int(hi.width) - 2), y0 = std::min(int(fy), int(hi.height) - 2);
    const double tx = fx - x0, ty = fy - y0;
    auto px = [&](int xx, int yy) {
        const float* p = &hi.rgb[(size_t(yy) * hi.width + size_t(xx)) * 3];
        return glm::dvec3(p[0], p[1], p[2]);
    };
    const glm::dvec3 v = (px(x0, y0) * (1 - tx) + px(x0 + 1, y0) * tx) * (1 - ty) +
                         (px(x0, y0 + 1) * (1 - tx) + px(x0 + 1, y0 + 1) * tx) * ty;
    return glm::vec3(v);
}

// One SR loop over a crop of out_size x out_size output pixels of `hi` (k x output resolution)
// whose top-left corner is `origin` (output pixels; the crop and its motion must stay inside hi).
// out_size / scale must be a whole number of LR pixels. Jitter: Halton(2,3) - 1/2, 16-long cycle,
// starting at index `jitter_start`.
inline SrLoop make_sr_loop(const RgbImage& hi, uint32_t k, float scale, uint32_t out_size, glm::dvec2 origin,
                           glm::vec2 velocity, uint32_t jitter_start, float noise = 0.f,
                           uint64_t noise_seed = 0) {
    std::mt19937_64 rng(noise_seed);
    std::normal_distribution<float> normal(0.f, 1.f);
    SrLoop l;
    l.scale = scale;
    l.out_w = l.out_h = out_size;
    l.lr_w = l.lr_h = uint32_t(std::lround(double(out_size) / scale));
    l.velocity = velocity;
    const double kd = double(k), s = double(out_size) / double(l.lr_w);
    for (int t = 0; t < kSrFrames; ++t) {
        const glm::dvec2 o = origin + double(t) * glm::dvec2(velocity);
        const uint32_t ji = (jitter_start + uint32_t(t)) % 16 + 1;
        const glm::vec2 j(halton(ji, 2) - 0.5f, halton(ji, 3) - 0.5f);
        l.jitter[size_t(t)] = j;
        RgbImage& lr = l.lr[size_t(t)];
        lr = RgbImage{l.lr_w, l.lr_h, std::vector<float>(size_t(l.lr_w) * l.lr_h * 3)};
        for (uint32_t y = 0; y < l.lr_h; ++y)
            for (uint32_t x = 0; x < l.lr_w; ++x) {
                glm::vec3 c =
                    scene_at(hi, ((x + 0.5 + j.x) * s + o.x) * kd, ((y + 0.5 + j.y) * s + o.y) * kd);
                if (noise > 0.f) c *= std::max(1.f + noise * normal(rng), 0.f);
                for (int ch = 0; ch < 3; ++ch) lr.rgb[(size_t(y) * l.lr_w + x) * 3 + size_t(ch)] = c[ch];
            }
        RgbImage& tg = l.target[size_t(t)];
        tg = RgbImage{out_size, out_size, std::vector<float>(size_t(out_size) * out_size * 3)};
        for (uint32_t y = 0; y < out_size; ++y)
            for (uint32_t x = 0; x < out_size; ++x) {
                glm::vec3 c(0.f);
                for (int sy = 0; sy < 4; ++sy)
                    for (int sx = 0; sx < 4; ++sx)
                        c += scene_at(hi, (x + (sx + 0.5) / 4 + o.x) * kd, (y + (sy + 0.5) / 4 + o.y) * kd);
                for (int ch = 0; ch < 3; ++ch)
                    tg.rgb[(size_t(y) * out_size + x) * 3 + size_t(ch)] = c[ch] / 16.f;
            }
    }
    const double reach = std::ceil(std::max(std::abs(velocity.x), std::abs(velocity.y))) + 3;
    l.margin = int(reach) + 2;
    return l;
}

// The engine's internal frame and `sr` push constants of frame t of a loop.
inline ref::InternalFrame sr_loop_frame(const SrLoop& l, int t) {
    ref::InternalFrame f;
    f.width = l.lr_w;
    f.height = l.lr_h;
    const size_t n = size_t(l.lr_w) * l.lr_h;
    f.color.resize(n);
    for (size_t i = 0; i < n; ++i)
        f.color[i] = glm::vec4(l.lr[size_t(t)].rgb[i * 3], l.lr[size_t(t)].rgb[i * 3 + 1],
                               l.lr[size_t(t)].rgb[i * 3 + 2], 1.f);
    f.depth.assign(n, 1.f);
    f.mv.assign(n, l.velocity / (float(l.out_w) / float(l.lr_w)));
    f.has_mv = t > 0;
    return f;
}
inline ref::SrParams sr_loop_params(const SrLoop& l, int t, float a, float b, Resample kind = Resample::lut) {
    FrameFormat fmt;
    fmt.width = l.lr_w;
    fmt.height = l.lr_h;
    Params p;
    p.sr_a = a;
    p.sr_b = b;
    p.resample = kind;
    return params::sr_params(fmt, p, l.out_w, l.out_h, l.jitter[size_t(t)].x, l.jitter[size_t(t)].y, t > 0);
}

// Outputs of the engine's CPU reference `sr` pass on every frame of the loop (linear RGB), with the
// history resampled by `kind` (lut: the table `lut`).
inline std::array<RgbImage, kSrFrames> sr_loop_forward(const SrLoop& l, std::span<const float> lut, float a,
                                                       float b, Resample kind = Resample::lut) {
    std::array<RgbImage, kSrFrames> out;
    std::vector<glm::vec4> hist;
    const std::vector<float> prev_depth(size_t(l.lr_w) * l.lr_h, 1.f);
    for (int t = 0; t < kSrFrames; ++t) {
        hist =
            ref::super_resolve(sr_loop_frame(l, t), prev_depth, hist, sr_loop_params(l, t, a, b, kind), lut);
        out[size_t(t)] = from_vec4(hist, l.out_w, l.out_h);
    }
    return out;
}

// Adjoint of sr_loop_forward: given dL/d(out_t) for every frame (RGB, out_w x out_h each), adds
// dL/d(lut) to grad_lut. Per output pixel of frame t >= 1 that uses its history (sr.h: samples in
// reach, history position on screen), out = (a S + (1 - a) clamp(R(out_{t-1}), lo, hi)) / (a W + 1 - a),
// so the gradient reaches the resampled history R (a LUT resampling of out_{t-1} at the velocity)
// where it is not clamped, and through it the LUT and out_{t-1}.
inline void sr_loop_backward(const SrLoop& l, const std::array<RgbImage, kSrFrames>& out,
                             std::array<std::vector<float>, kSrFrames> grad_out, std::span<const float> lut,
                             float a, float b, std::span<double> grad_lut) {
    const float scale = float(l.out_w) / float(l.lr_w);
    const int lw = int(l.lr_w), lh = int(l.lr_h);
    for (int t = kSrFrames - 1; t >= 1; --t) {
        const RgbImage& prev = out[size_t(t) - 1];
        const RgbImage hist = lut_resample(prev, l.velocity, lut);
        const RgbImage& cur = l.lr[size_t(t)];
        const glm::vec2 jit = l.jitter[size_t(t)];
        std::vector<float> gh(prev.rgb.size(), 0.f);
        for (uint32_t y = 0; y < l.out_h; ++y)
            for (uint32_t x = 0; x < l.out_w; ++x) {
                const size_t q = size_t(y) * l.out_w + x;
                const float* g = &grad_out[size_t(t)][q * 3];
                if (g[0] == 0.f && g[1] == 0.f && g[2] == 0.f) continue;
                const glm::vec2 qc(float(x) + 0.5f, float(y) + 0.5f), pos = qc / scale;
                const glm::ivec2 tp =
                    glm::clamp(glm::ivec2(glm::floor(pos)), glm::ivec2(0), glm::ivec2(lw - 1, lh - 1));
                glm::vec3 lo(1e30f), hi(-1e30f);
                float wsum = 0.f, n = 0.f;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const glm::ivec2 s =
                            glm::clamp(tp + glm::ivec2(dx, dy), glm::ivec2(0), glm::ivec2(lw - 1, lh - 1));
                        const float* c = &cur.rgb[(size_t(s.y) * l.lr_w + size_t(s.x)) * 3];
                        lo = glm::min(lo, glm::vec3(c[0], c[1], c[2]));
                        hi = glm::max(hi, glm::vec3(c[0], c[1], c[2]));
                        const float d = glm::length(glm::vec2(s) + glm::vec2(0.5f) + jit - pos);
                        if (d < 1.f) {
                            wsum += std::max(1.f - b * d, 0.f);
                            n += 1.f;
                        }
                    }
                const glm::vec2 h = qc + l.velocity;
                if (n == 0.f || h.x < 0.f || h.y < 0.f || h.x > float(l.out_w) || h.y > float(l.out_h))
                    continue;
                // As sr.h: no Eq. 2 term left (a = 1, every weight 0 when b > 1) is a spatial
                // upsample, which reads no history.
                const float norm = a * wsum / n + (1.f - a);
                if (!(norm > 0.f)) continue;
                const float k = (1.f - a) / norm;
                for (int c = 0; c < 3; ++c) {
                    const float r = hist.rgb[q * 3 + size_t(c)];
                    if (r >= lo[c] && r <= hi[c]) gh[q * 3 + size_t(c)] = k * g[c];
                }
            }
        std::vector<float> gprev(prev.rgb.size(), 0.f);
        lut_resample_backward(prev, l.velocity, lut, gh, grad_lut, &gprev);
        std::vector<float>& gp = grad_out[size_t(t) - 1];
        for (size_t i = 0; i < gp.size(); ++i) gp[i] += gprev[i];
    }
}

} // namespace fgsr::cli::lutmodel
