// The model `fgsr lut-train` optimises, header-only so that tests/test_lut.cpp checks exactly what
// the trainer runs:
//   - lut_resample(): the engine's LUT resampling (shaders/resample.h, RESAMPLE_LUT) of a whole
//     image at a global shift, bit-for-bit the arithmetic of fgsr::ref::resample_image, plus its
//     adjoint (gradients with respect to the LUT weights and the source image);
//   - ssim_with_grad(): mean SSIM as fgsr::capture::ssim defines it (11x11 Gaussian, sigma 1.5,
//     valid windows only) of one channel, with its analytic gradient;
//   - history images: the training / evaluation images (see make_history_image);
//   - shift sequences: six sub-pixel shifts whose sum is a whole-pixel vector, so the exact result
//     of the repeated resampling is the first image translated by whole pixels.
#pragma once

#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/types.hpp>

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

} // namespace fgsr::cli::lutmodel
