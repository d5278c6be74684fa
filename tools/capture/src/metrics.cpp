// Display-referred PSNR / SSIM and diff images; see metrics.hpp for the contracts.
#include <fgsr/capture/metrics.hpp>
#include <fgsr/engine/color.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace fgsr::capture {

namespace {

std::string size_str(const ImageRGBA& i) {
    return std::to_string(i.width) + "x" + std::to_string(i.height);
}

// Checks that both images are well formed, non-empty and of equal size.
Result<void> check_pair(const ImageRGBA& a, const ImageRGBA& ref, const char* what) {
    for (const ImageRGBA* im : {&a, &ref}) {
        const size_t n = size_t(im->width) * im->height * 4;
        if (im->rgba.size() != n)
            return make_error(Errc::size_mismatch, std::string(what) + ": image " + size_str(*im) +
                                                       " holds " + std::to_string(im->rgba.size()) +
                                                       " floats, expected " + std::to_string(n));
    }
    if (a.width != ref.width || a.height != ref.height)
        return make_error(Errc::size_mismatch, std::string(what) + ": image sizes differ: " + size_str(a) +
                                                   " vs " + size_str(ref));
    if (a.width == 0 || a.height == 0)
        return make_error(Errc::empty_input, std::string(what) + ": empty image " + size_str(a));
    return {};
}

// Sum of squared display-domain errors over RGB of pixel i (NaN channel -> 1).
double pixel_sq_error(const ImageRGBA& a, const ImageRGBA& ref, size_t i) {
    double s = 0.0;
    for (int c = 0; c < 3; ++c) {
        const float x = metric_display_value(a.rgba[i * 4 + c]);
        const float y = metric_display_value(ref.rgba[i * 4 + c]);
        if (std::isnan(x) || std::isnan(y)) {
            s += 1.0;
        } else {
            const double d = double(x) - double(y);
            s += d * d;
        }
    }
    return s;
}

double psnr_from_mse(double mse) {
    if (mse <= 0.0) return kPsnrIdentical;
    return std::min(kPsnrIdentical, 10.0 * std::log10(1.0 / mse));
}

constexpr int kWin = 11;   // SSIM window size
constexpr int kRadius = 5; // (kWin - 1) / 2
constexpr double kSigma = 1.5;

// SSIM moment accumulation type.
using Acc = double;

std::array<Acc, kWin> gaussian_window() {
    std::array<double, kWin> w{};
    double sum = 0.0;
    for (int i = 0; i < kWin; ++i) {
        const double x = i - kRadius;
        w[i] = std::exp(-0.5 * x * x / (kSigma * kSigma));
        sum += w[i];
    }
    std::array<Acc, kWin> out{};
    for (int i = 0; i < kWin; ++i) out[i] = Acc(w[i] / sum);
    return out;
}

} // namespace

float metric_display_value(float linear) {
    if (std::isnan(linear)) return linear; // kept: a NaN output scores as the worst error
    return srgb_encode(linear);
}

Result<double> psnr(const ImageRGBA& a, const ImageRGBA& ref) {
    FGSR_TRY(check_pair(a, ref, "psnr"));
    const size_t n = size_t(a.width) * a.height;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) sum += pixel_sq_error(a, ref, i);
    return psnr_from_mse(sum / double(n * 3));
}

Result<double> psnr_masked(const ImageRGBA& a, const ImageRGBA& ref, std::span<const uint8_t> mask) {
    FGSR_TRY(check_pair(a, ref, "psnr_masked"));
    const size_t n = size_t(a.width) * a.height;
    if (mask.size() != n)
        return make_error(Errc::size_mismatch, "psnr_masked: mask holds " + std::to_string(mask.size()) +
                                                   " entries, expected " + std::to_string(n));
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!mask[i]) continue;
        sum += pixel_sq_error(a, ref, i);
        ++count;
    }
    if (count == 0) return make_error(Errc::empty_input, "psnr_masked: the mask selects no pixel");
    return psnr_from_mse(sum / double(count * 3));
}

Result<double> ssim(const ImageRGBA& a, const ImageRGBA& ref) {
    FGSR_TRY(check_pair(a, ref, "ssim"));
    if (a.width < uint32_t(kWin) || a.height < uint32_t(kWin))
        return make_error(Errc::invalid_argument,
                          "ssim: image " + size_str(a) + " is smaller than the 11x11 window");

    const size_t w = a.width, h = a.height;
    const size_t ow = w - (kWin - 1), oh = h - (kWin - 1); // valid window positions
    const std::array<Acc, kWin> g = gaussian_window();
    constexpr double C1 = (0.01 * 1.0) * (0.01 * 1.0);
    constexpr double C2 = (0.03 * 1.0) * (0.03 * 1.0);

    // Moments are accumulated in double (float loses ~3e-5 of SSIM to cancellation in flat areas)
    // from display values shifted by -0.5, which reduces the cancellation in E[x^2] - E[x]^2
    // further; the means are shifted back before use. Rows stream through a ring of the last
    // kWin horizontally filtered rows, so memory is O(width) whatever the image height.
    std::vector<Acc> xr(w), yr(w), prod(w);
    // ring[(m * kWin + slot) * ow + i]: moment m (x, y, x^2, y^2, xy) of input row slot (mod kWin).
    std::vector<Acc> ring(size_t(5) * kWin * ow);
    std::array<std::vector<Acc>, 5> row;
    for (auto& r : row) r.assign(ow, Acc(0));

    double total = 0.0;
    for (int c = 0; c < 3; ++c) {
        for (size_t r = 0; r < h; ++r) {
            for (size_t i = 0; i < w; ++i) {
                const size_t k = (r * w + i) * 4 + size_t(c);
                float xv = metric_display_value(a.rgba[k]);
                float yv = metric_display_value(ref.rgba[k]);
                const bool xn = std::isnan(xv), yn = std::isnan(yv);
                if (xn && yn) {
                    xv = 0.0f;
                    yv = 1.0f;
                } else if (xn) {
                    xv = yv < 0.5f ? 1.0f : 0.0f;
                } else if (yn) {
                    yv = xv < 0.5f ? 1.0f : 0.0f;
                }
                xr[i] = Acc(xv) - Acc(0.5);
                yr[i] = Acc(yv) - Acc(0.5);
            }

            // Horizontal pass (valid part only) into the ring.
            const size_t slot = r % kWin;
            for (int m = 0; m < 5; ++m) {
                const Acc* src = nullptr;
                switch (m) {
                case 0:
                    src = xr.data();
                    break;
                case 1:
                    src = yr.data();
                    break;
                case 2:
                    for (size_t i = 0; i < w; ++i) prod[i] = xr[i] * xr[i];
                    src = prod.data();
                    break;
                case 3:
                    for (size_t i = 0; i < w; ++i) prod[i] = yr[i] * yr[i];
                    src = prod.data();
                    break;
                default:
                    for (size_t i = 0; i < w; ++i) prod[i] = xr[i] * yr[i];
                    src = prod.data();
                    break;
                }
                Acc* dst = &ring[(size_t(m) * kWin + slot) * ow];
                for (size_t i = 0; i < ow; ++i) dst[i] = Acc(0);
                for (int k = 0; k < kWin; ++k) {
                    const Acc gk = g[k];
                    const Acc* s = src + k;
                    for (size_t i = 0; i < ow; ++i) dst[i] += gk * s[i];
                }
            }
            if (r + 1 < size_t(kWin)) continue;

            // Vertical pass over input rows r-10 .. r and the SSIM map of output row r-10.
            const size_t first = r + 1 - kWin;
            for (int m = 0; m < 5; ++m) {
                Acc* dst = row[m].data();
                for (size_t i = 0; i < ow; ++i) dst[i] = Acc(0);
                for (int k = 0; k < kWin; ++k) {
                    const Acc gk = g[k];
                    const Acc* s = &ring[(size_t(m) * kWin + (first + k) % kWin) * ow];
                    for (size_t i = 0; i < ow; ++i) dst[i] += gk * s[i];
                }
            }
            double row_sum = 0.0;
            for (size_t i = 0; i < ow; ++i) {
                const double mxs = row[0][i], mys = row[1][i]; // shifted means
                const double vx = double(row[2][i]) - mxs * mxs;
                const double vy = double(row[3][i]) - mys * mys;
                const double cxy = double(row[4][i]) - mxs * mys;
                const double mx = mxs + 0.5, my = mys + 0.5;
                const double num = (2.0 * mx * my + C1) * (2.0 * cxy + C2);
                const double den = (mx * mx + my * my + C1) * (vx + vy + C2);
                row_sum += num / den;
            }
            total += row_sum;
        }
    }
    return total / double(3 * ow * oh);
}

Result<ImageRGBA> abs_diff_image(const ImageRGBA& a, const ImageRGBA& b, float gain) {
    FGSR_TRY(check_pair(a, b, "abs_diff_image"));
    if (!std::isfinite(gain) || gain < 0.0f)
        return make_error(Errc::invalid_argument, "abs_diff_image: gain " + std::to_string(gain) +
                                                      " must be finite and non-negative");
    ImageRGBA out;
    out.width = a.width;
    out.height = a.height;
    const size_t n = size_t(a.width) * a.height;
    out.rgba.resize(n * 4);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            const float x = metric_display_value(a.rgba[i * 4 + c]);
            const float y = metric_display_value(b.rgba[i * 4 + c]);
            const float d = (std::isnan(x) || std::isnan(y)) ? 1.0f : std::min(1.0f, std::fabs(x - y) * gain);
            out.rgba[i * 4 + c] = srgb_decode(d);
        }
        out.rgba[i * 4 + 3] = 1.0f;
    }
    return out;
}

Result<void> TemporalStd::add(const ImageRGBA& frame) {
    const size_t n = size_t(frame.width) * frame.height;
    if (n == 0) return make_error(Errc::empty_input, "temporal std: empty frame");
    if (frame.rgba.size() != n * 4)
        return make_error(Errc::size_mismatch, "temporal std: rgba holds " +
                                                   std::to_string(frame.rgba.size()) + " floats, expected " +
                                                   std::to_string(n * 4));
    if (frames_ == 0) {
        width_ = frame.width;
        height_ = frame.height;
        sum_.assign(n * 3, 0.0);
        sum_sq_.assign(n * 3, 0.0);
    } else if (frame.width != width_ || frame.height != height_) {
        return make_error(Errc::size_mismatch, "temporal std: frame " + std::to_string(frame.width) + "x" +
                                                   std::to_string(frame.height) + " after " +
                                                   std::to_string(width_) + "x" + std::to_string(height_));
    }
    for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < 3; ++c) {
            float v = metric_display_value(frame.rgba[i * 4 + c]);
            if (std::isnan(v)) v = 1.f;
            sum_[i * 3 + c] += v;
            sum_sq_[i * 3 + c] += double(v) * v;
        }
    ++frames_;
    return {};
}

double TemporalStd::mean_std() const {
    if (frames_ < 2) return 0.0;
    const double k = double(frames_);
    double total = 0.0;
    for (size_t i = 0; i < sum_.size(); ++i) {
        const double mean = sum_[i] / k;
        total += std::sqrt(std::max(sum_sq_[i] / k - mean * mean, 0.0));
    }
    return total / double(sum_.size());
}

namespace {

Result<void> check_field(std::span<const float> v, size_t per_pixel, size_t n, const char* what) {
    if (v.size() != per_pixel * n)
        return make_error(Errc::size_mismatch, std::string(what) + " holds " + std::to_string(v.size()) +
                                                   " floats, expected " + std::to_string(per_pixel * n));
    return {};
}

} // namespace

Result<std::vector<uint8_t>> visible_in_both(std::span<const float> reference_mv,
                                             std::span<const float> depth,
                                             std::span<const float> previous_depth, uint32_t width,
                                             uint32_t height, float depth_tolerance,
                                             std::span<const uint8_t> known) {
    const size_t n = size_t(width) * height;
    if (n == 0)
        return make_error(Errc::empty_input, "visible_in_both: empty frame " + std::to_string(width) + "x" +
                                                 std::to_string(height));
    FGSR_TRY(check_field(reference_mv, 2, n, "visible_in_both: reference vector field"));
    FGSR_TRY(check_field(depth, 1, n, "visible_in_both: depth"));
    FGSR_TRY(check_field(previous_depth, 1, n, "visible_in_both: previous depth"));
    if (!known.empty() && known.size() != n)
        return make_error(Errc::size_mismatch, "visible_in_both: known-vector mask holds " +
                                                   std::to_string(known.size()) + " bytes, expected " +
                                                   std::to_string(n));
    if (!std::isfinite(depth_tolerance) || depth_tolerance < 0.f)
        return make_error(Errc::invalid_argument, "visible_in_both: depth tolerance " +
                                                      std::to_string(depth_tolerance) +
                                                      " is not a finite value >= 0");
    std::vector<uint8_t> mask(n, 0);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            const size_t i = size_t(y) * width + x;
            if (!known.empty() && known[i] == 0) continue;
            const double vx = reference_mv[2 * i], vy = reference_mv[2 * i + 1];
            if (!std::isfinite(vx) || !std::isfinite(vy)) continue;
            const double qx = double(x) + 0.5 + vx, qy = double(y) + 0.5 + vy;
            if (!(qx >= 0.0 && qx < double(width) && qy >= 0.0 && qy < double(height))) continue;
            const size_t j = size_t(qy) * width + size_t(qx); // floor: both are >= 0
            const double d = depth[i], dp = previous_depth[j];
            if (!std::isfinite(d) || !std::isfinite(dp) || d <= 0.0 || dp <= 0.0) continue;
            mask[i] = std::abs(dp - d) / std::min(dp, d) <= double(depth_tolerance) ? 1 : 0;
        }
    return mask;
}

Result<double> end_point_error(std::span<const float> estimated_mv, std::span<const float> reference_mv,
                               std::span<const uint8_t> mask, uint32_t width, uint32_t height) {
    const size_t n = size_t(width) * height;
    if (n == 0)
        return make_error(Errc::empty_input, "end_point_error: empty frame " + std::to_string(width) + "x" +
                                                 std::to_string(height));
    FGSR_TRY(check_field(estimated_mv, 2, n, "end_point_error: estimated vector field"));
    FGSR_TRY(check_field(reference_mv, 2, n, "end_point_error: reference vector field"));
    if (mask.size() != n)
        return make_error(Errc::size_mismatch, "end_point_error: mask holds " + std::to_string(mask.size()) +
                                                   " bytes, expected " + std::to_string(n));
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        if (mask[i] == 0) continue;
        const double dx = double(estimated_mv[2 * i]) - double(reference_mv[2 * i]);
        const double dy = double(estimated_mv[2 * i + 1]) - double(reference_mv[2 * i + 1]);
        const double e = std::sqrt(dx * dx + dy * dy);
        sum += std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
        ++count;
    }
    if (count == 0) return make_error(Errc::empty_input, "end_point_error: the mask selects no pixel");
    return sum / double(count);
}

} // namespace fgsr::capture
