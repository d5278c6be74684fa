// Image quality metrics on display-referred colour.
//
// Every metric here compares what a viewer would see: each linear RGB channel is clamped to [0,1]
// (+Inf -> 1, -Inf -> 0) and encoded with the standard piecewise sRGB OETF, giving display values
// in [0,1]. Alpha is ignored. NaN is never ignored: a NaN channel counts as the largest possible
// error (see each function), so broken outputs score badly instead of being skipped.
//
// Errors are values: mismatched sizes, empty images and images whose rgba vector does not hold
// width*height*4 floats are reported through Result, never asserted.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace fgsr::capture {

// PSNR reported for identical images (and the cap for any result): a large finite value.
inline constexpr double kPsnrIdentical = 100.0;

// Display value of one linear channel as the metrics see it: clamp to [0,1], then sRGB OETF.
// NaN maps to NaN (the metrics handle it explicitly).
float metric_display_value(float linear);

// Peak signal-to-noise ratio in dB over the RGB channels of every pixel, peak 1 in the display
// domain: 10*log10(1 / MSE). Capped at kPsnrIdentical (returned for identical images). A NaN in
// either image contributes a squared error of 1 for that channel.
// Errors: size_mismatch (different sizes or malformed rgba vector), empty_input (zero pixels).
Result<double> psnr(const ImageRGBA& a, const ImageRGBA& ref);

// PSNR over the pixels whose mask entry is non-zero (mask: width*height bytes, top row first).
// Errors as psnr(), plus size_mismatch for a mask of the wrong size and empty_input when the mask
// selects no pixel.
Result<double> psnr_masked(const ImageRGBA& a, const ImageRGBA& ref, std::span<const uint8_t> mask);

// Mean structural similarity (Wang et al. 2004), as scikit-image's structural_similarity with
// gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1: an 11x11 Gaussian
// window (sigma 1.5, normalised), K1 = 0.01, K2 = 0.03, L = 1, evaluated at every window position
// that lies fully inside the image, per RGB channel, and averaged over positions and channels.
// Result in [-1, 1]; 1 for identical images. A NaN channel value is replaced by the display value
// farthest from the other image's value at that pixel (1 if the other is < 0.5, else 0; 0 vs 1 when
// both are NaN).
// Errors: size_mismatch, empty_input, invalid_argument when the image is smaller than 11x11.
Result<double> ssim(const ImageRGBA& a, const ImageRGBA& ref);

// Visualisation of |a - b|: per RGB channel, the absolute difference of the display values times
// `gain`, clamped to [0,1] (NaN in either input -> 1). The result is a linear ImageRGBA holding the
// sRGB-decoded value of that display difference, so an image writer that sRGB-encodes shows exactly
// gain*|display(a) - display(b)|. Alpha is 1.
// Errors: size_mismatch, empty_input, invalid_argument for a negative or non-finite gain.
Result<ImageRGBA> abs_diff_image(const ImageRGBA& a, const ImageRGBA& b, float gain = 1.0f);

// Temporal stability (QRISP section 4): the mean over pixels and RGB channels of the standard
// deviation over frames of the display value (population std, display units in [0,1]; 0 for a
// perfectly still image). Frames are added one at a time; all must have the first one's size.
// A NaN channel value counts as 1. Not thread-safe.
class TemporalStd {
  public:
    // Errors: size_mismatch (a size other than the first frame's, or a malformed rgba vector),
    // empty_input (zero pixels).
    Result<void> add(const ImageRGBA& frame);
    size_t frames() const { return frames_; }
    // Mean per-pixel standard deviation of the frames added so far (0 with fewer than 2 frames).
    double mean_std() const;

  private:
    uint32_t width_ = 0, height_ = 0;
    size_t frames_ = 0;
    std::vector<double> sum_, sum_sq_; // per pixel and RGB channel
};

} // namespace fgsr::capture
