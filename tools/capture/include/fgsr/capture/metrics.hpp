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

// ----- Motion vectors -----
// Vector fields are in the engine's internal convention (fgsr/core/types.hpp): 2 floats per pixel,
// row-major, top row first, in pixels, x right, y down, from the pixel centre in the current frame
// to the position of the same surface point in the previous frame. Depths are linear view depths
// (larger is farther), one float per pixel.

// Relative depth difference up to which the previous frame's surface at a vector's landing point
// is taken to be the same surface as the current pixel's (10 %: the half-rate composition's test,
// docs/CAPTURE_FORMAT.md; well above the depth change of one surface between two frames, well
// below the gap between an occluder and what it hides in every capture measured).
inline constexpr float kVisibleDepthTolerance = 0.1f;

// The pixels of the current frame that are visible in both frames: pixel p (centre p + 0.5) is
// visible when its reference vector v is finite (and known[p] != 0 when `known` is given), the
// landing point q = p + 0.5 + v lies inside the previous frame ([0, width) x [0, height)), and the
// previous frame's depth at the nearest pixel to q (floor(q)) agrees with the current depth:
// |d_prev - d| / min(d_prev, d) <= depth_tolerance, both depths finite and positive.
// Result: width*height bytes, 1 = visible, 0 = not.
// Errors: size_mismatch (spans not 2*width*height / width*height floats, known neither empty nor
// width*height), empty_input (zero pixels), invalid_argument (tolerance negative or not finite).
Result<std::vector<uint8_t>> visible_in_both(std::span<const float> reference_mv,
                                             std::span<const float> depth,
                                             std::span<const float> previous_depth, uint32_t width,
                                             uint32_t height, float depth_tolerance = kVisibleDepthTolerance,
                                             std::span<const uint8_t> known = {});

// Mean end-point error in pixels: the mean over the pixels with mask != 0 of the Euclidean length
// of estimated - reference. A non-finite estimated vector on a masked pixel makes the result
// +infinity (broken estimates score badly instead of being skipped).
// Errors: size_mismatch (vector spans not 2*width*height floats, mask not width*height bytes),
// empty_input (zero pixels, or a mask that selects no pixel).
Result<double> end_point_error(std::span<const float> estimated_mv, std::span<const float> reference_mv,
                               std::span<const uint8_t> mask, uint32_t width, uint32_t height);

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
