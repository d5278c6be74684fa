// Parameter building (fgsr/engine/params.hpp): the checks of Params and of a frame against its
// format, and the push constants of the passes, for the GPU path and the CPU reference alike.
#include <fgsr/engine/color.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/params.hpp>

#include <cmath>
#include <string>

namespace fgsr {

Result<void> validate(const Params& p) {
    auto bad = [](const char* field, float v, const char* range) {
        return make_error(Errc::invalid_argument, std::string("parameter ") + field + " = " +
                                                      std::to_string(v) + " is outside " + range);
    };
    if (!(std::isfinite(p.t_depth) && p.t_depth >= 0.f)) return bad("t_depth", p.t_depth, "[0, inf)");
    if (!(std::isfinite(p.t_bright) && p.t_bright >= 0.f)) return bad("t_bright", p.t_bright, "[0, inf)");
    if (!(p.sr_a >= 0.f && p.sr_a <= 1.f)) return bad("sr_a", p.sr_a, "[0, 1]");
    if (!(std::isfinite(p.sr_b) && p.sr_b >= 0.f)) return bad("sr_b", p.sr_b, "[0, inf)");
    if (!(std::isfinite(p.sr_clip) && p.sr_clip >= 0.f)) return bad("sr_clip", p.sr_clip, "[0, inf)");
    if (!(std::isfinite(p.sr_clip_antialiased) && p.sr_clip_antialiased >= 0.f))
        return bad("sr_clip_antialiased", p.sr_clip_antialiased, "[0, inf)");
    if (!(std::isfinite(p.sr_disagree) && p.sr_disagree >= 0.f))
        return bad("sr_disagree", p.sr_disagree, "[0, inf)");
    if (!(std::isfinite(p.dilate_bright) && p.dilate_bright >= 0.f))
        return bad("dilate_bright", p.dilate_bright, "[0, inf)");
    if (!(std::isfinite(p.dilate_edges) && p.dilate_edges >= 0.f))
        return bad("dilate_edges", p.dilate_edges, "[0, inf)");
    if (!(p.correct_ratio >= 0.f && p.correct_ratio <= 1.f))
        return bad("correct_ratio", p.correct_ratio, "[0, 1]");
    if (!(std::isfinite(p.correct_margin) && p.correct_margin >= 0.f))
        return bad("correct_margin", p.correct_margin, "[0, inf)");
    if (!(p.correct_depth >= 0.f)) return bad("correct_depth", p.correct_depth, "[0, inf]");
    if (!(p.correct_front >= 0.f)) return bad("correct_front", p.correct_front, "[0, inf]");
    if (!(p.denoise_strength >= 0.f && p.denoise_strength <= 64.f))
        return bad("denoise_strength", p.denoise_strength, "[0, 64]");
    if (!(std::isfinite(p.noise_floor) && p.noise_floor >= 0.f))
        return bad("noise_floor", p.noise_floor, "[0, inf)");
    if (!(p.denoise_gamma >= 0.f && p.denoise_gamma <= 2.f))
        return bad("denoise_gamma", p.denoise_gamma, "[0, 2]");
    if (!(std::isfinite(p.scale) && p.scale >= 1.f && p.scale <= 4.f))
        return make_error(Errc::invalid_argument,
                          "scale factor " + std::to_string(p.scale) + " is outside [1, 4]");
    // Measured on jittered, aliased SR input: -0.2 to -2 dB in sr, isr and esr (docs/ACCURACY.md,
    // change 4), where colour matching follows the aliasing.
    if (p.correct_vectors && p.scale != 1.f)
        return make_error(Errc::invalid_argument,
                          "correct_vectors is for sessions without super resolution (scale 1), not scale " +
                              std::to_string(p.scale));
    if (uint32_t(p.motion) > uint32_t(MotionModel::linear) || uint32_t(p.blend) > uint32_t(BlendMode::mix) ||
        uint32_t(p.resample) > uint32_t(Resample::lut) ||
        uint32_t(p.warp_resample.value_or(Resample::bilinear)) > uint32_t(Resample::lut) ||
        uint32_t(p.sr_spatial) > uint32_t(SrSpatial::bspline) ||
        uint32_t(p.warp_kernel) > uint32_t(WarpKernel::cubic))
        return make_error(
            Errc::invalid_argument,
            "unknown motion model, blend mode, resampling kind, sr spatial kernel or warp kernel");
    if (!p.lut.empty() && p.lut.size() != kLutSize)
        return make_error(Errc::invalid_argument, "LUT has " + std::to_string(p.lut.size()) +
                                                      " weights, expected " + std::to_string(kLutSize));
    for (size_t i = 0; i < p.lut.size(); ++i)
        if (!std::isfinite(p.lut[i]))
            return make_error(Errc::invalid_argument,
                              "LUT weight " + std::to_string(i) + " is " + std::to_string(p.lut[i]));
    return {};
}

namespace params {

using gpu::DenoiseParams;
using gpu::GenParams;
using gpu::IngestParams;
using gpu::SrParams;

Result<void> validate_formats(const FrameFormat& f) {
    if (bytes_per_pixel(f.color_format) == 0)
        return make_error(Errc::unsupported,
                          "unknown colour format " + std::to_string(uint32_t(f.color_format)));
    if (bytes_per_pixel(f.mv_format) == 0)
        return make_error(Errc::unsupported,
                          "unknown motion-vector format " + std::to_string(uint32_t(f.mv_format)));
    return {};
}

Result<void> validate(const FrameFormat& f, const FrameView& frame) {
    if (f.width == 0 || f.height == 0)
        return make_error(Errc::empty_input,
                          "frame size is " + std::to_string(f.width) + "x" + std::to_string(f.height));
    if (f.width > kMaxFrameSide || f.height > kMaxFrameSide)
        return make_error(Errc::invalid_argument, "frame size " + std::to_string(f.width) + "x" +
                                                      std::to_string(f.height) + " exceeds " +
                                                      std::to_string(kMaxFrameSide) + "x" +
                                                      std::to_string(kMaxFrameSide));
    FGSR_TRY(validate_formats(f));
    const Conventions& c = f.conventions;
    if (uint32_t(c.depth_kind) > uint32_t(DepthKind::device_reversed))
        return make_error(Errc::unsupported, "unknown depth kind " + std::to_string(uint32_t(c.depth_kind)));
    if (uint32_t(c.mv_units) > uint32_t(MvUnits::uv) ||
        uint32_t(c.mv_direction) > uint32_t(MvDirection::from_previous))
        return make_error(Errc::unsupported, "unknown motion-vector units or direction");
    if (c.depth_kind != DepthKind::linear) {
        bool far_ok = std::isinf(c.far_plane) || c.far_plane == 0.f ||
                      (std::isfinite(c.far_plane) && c.far_plane > c.near_plane);
        if (!(std::isfinite(c.near_plane) && c.near_plane > 0.f) || !far_ok)
            return make_error(Errc::invalid_argument,
                              "device depth needs 0 < near < far (far may be 0 or inf for an "
                              "infinite far plane); got near " +
                                  std::to_string(c.near_plane) + ", far " + std::to_string(c.far_plane));
    }
    const size_t n = size_t(f.width) * f.height;
    auto check = [&](std::span<const std::byte> plane, size_t bpp, const char* what) -> Result<void> {
        if (plane.empty()) return make_error(Errc::empty_input, std::string(what) + " plane is empty");
        if (plane.size() != n * bpp)
            return make_error(Errc::size_mismatch,
                              std::string(what) + " plane has " + std::to_string(plane.size()) +
                                  " bytes, expected " + std::to_string(n * bpp) + " for " +
                                  std::to_string(f.width) + "x" + std::to_string(f.height));
        return {};
    };
    FGSR_TRY(check(frame.color, bytes_per_pixel(f.color_format), "colour"));
    // Planes a colour-only session does not have are ignored (FrameFormat::has_depth / has_vectors).
    if (f.has_depth) FGSR_TRY(check(frame.depth, 4, "depth"));
    if (f.has_vectors && !frame.mv.empty())
        FGSR_TRY(check(frame.mv, bytes_per_pixel(f.mv_format), "motion-vector"));
    return {};
}

IngestParams ingest_params(const FrameFormat& f, bool has_mv) {
    const Conventions& c = f.conventions;
    float sx = c.mv_units == MvUnits::uv ? float(f.width) : 1.f;
    float sy = c.mv_units == MvUnits::uv ? float(f.height) : 1.f;
    if (c.mv_direction == MvDirection::from_previous) sx = -sx, sy = -sy;
    if (c.mv_y_up) sy = -sy;
    IngestParams p{};
    p.width = f.width;
    p.height = f.height;
    p.color_format = uint32_t(f.color_format);
    p.depth_kind = uint32_t(c.depth_kind);
    p.near_plane = c.near_plane;
    p.far_plane = std::isinf(c.far_plane) ? 0.f : c.far_plane;
    p.mv_format = uint32_t(f.mv_format);
    p.has_mv = has_mv ? 1u : 0u;
    p.has_depth = f.has_depth ? 1u : 0u;
    p.mv_scale_x = sx;
    p.mv_scale_y = sy;
    p.bright_tiles_x = (f.width + (1u << FGSR_BRIGHT_TILE_SHIFT) - 1) >> FGSR_BRIGHT_TILE_SHIFT;
    return p;
}

void set_dilate(IngestParams& p, const FrameFormat& f, const Params& params, bool has_previous) {
    const bool given = f.has_vectors && f.has_depth && p.has_mv != 0u;
    const bool on = given && params.dilate_bright > 0.f && f.color_format != ColorFormat::rgba8_srgb;
    p.bright = on ? params.dilate_bright : 0.f;
    p.edge_ratio = given && has_previous ? params.dilate_edges : 0.f;
    p.dilate_depth = params.t_depth;
}

gpu::AgreeParams agree_params(const GenParams& g) {
    gpu::AgreeParams p{};
    p.g = g;
    p.radius = defaults::agree_radius;
    p.ratio = defaults::agree_ratio;
    p.centre = defaults::agree_centre;
    p.softness = defaults::agree_softness;
    p.depth_band = g.extrapolate != 0u ? defaults::agree_extrap_depth_band : defaults::agree_depth_band;
    p.colour_limit = defaults::agree_colour_limit;
    // Interpolation only: extrapolation's stage 4 compares frame 1 with frame 0 at t + mv.
    p.gain = g.extrapolate != 0u ? 0.f : defaults::agree_gain;
    p.gain_radius = defaults::agree_gain_radius;
    return p;
}

InputMeasure input_measure(const Session& s) {
    return InputMeasure{s.input_aliasing(), s.input_jittered()};
}

GenParams gen_params(const FrameFormat& format, const Params& params, float alpha, bool extrapolate,
                     bool frame0_has_mv, bool frame1_has_mv, InputMeasure input) {
    GenParams g{};
    g.width = format.width;
    g.height = format.height;
    g.alpha = alpha;
    g.extrapolate = extrapolate ? 1u : 0u;
    // Vectors estimated from colour give no usable acceleration (the difference of two estimates
    // is mostly their error): uniform velocity, which measured better on every capture
    // (docs/MOTION.md).
    g.quadratic = params.motion == MotionModel::quadratic && format.has_vectors
                      ? MOTION_ACCEL | (params.accel_search ? MOTION_ACCEL_SEARCH : 0u) |
                            (params.accel_median ? MOTION_ACCEL_MEDIAN : 0u) |
                            (params.accel_depth_motion ? MOTION_DEPTH_MOTION : 0u)
                      : 0u;
    g.frame0_has_mv = frame0_has_mv ? 1u : 0u;
    g.frame1_has_mv = frame1_has_mv ? 1u : 0u;
    g.t_depth = params.t_depth;
    g.t_bright = params.t_bright;
    g.blend_mode = (params.blend == BlendMode::mix ? BLEND_MIX : 0u) |
                   (params.blend_depth_motion ? BLEND_DEPTH_MOTION : 0u);
    g.fill_gaps = params.fill_gaps ? 1u : 0u;
    g.fill_holes = params.fill_holes ? 1u | (params.cover_edges ? FGSR_FILL_HOLES_COVER : 0u) |
                                           (params.hole_frame0 ? FGSR_FILL_HOLES_FRAME0 : 0u)
                                     : 0u;
    // automatic: the cubic where the positions are the client's vectors' (not estimated from colour)
    // and the frames are inputs on both sides of the instant (docs/ACCURACY.md change 39).
    g.warp_cubic = params.warp_kernel == WarpKernel::cubic ||
                           (params.warp_kernel == WarpKernel::automatic && !extrapolate &&
                            format.has_vectors && measures_antialiased(input.aliasing))
                       ? 1u
                       : 0u;
    return g;
}

SrParams sr_params(const FrameFormat& format, const Params& params, uint32_t out_width, uint32_t out_height,
                   float jitter_x, float jitter_y, bool has_history, InputMeasure input) {
    SrParams p{};
    p.lr_width = format.width;
    p.lr_height = format.height;
    p.hr_width = out_width;
    p.hr_height = out_height;
    p.scale = float(out_width) / float(format.width);
    p.jitter_x = jitter_x;
    p.jitter_y = jitter_y;
    p.a = params.sr_a;
    p.b = params.sr_b;
    p.t_depth = params.t_depth;
    p.resample = uint32_t(params.resample);
    p.has_history = has_history ? 1u : 0u;
    p.dilate = params.dilate_mvs ? 1u : 0u;
    // measures_antialiased is false for an unmeasured input; aliased means measured and not that.
    const bool antialiased = measures_antialiased(input.aliasing);
    p.clip = antialiased ? params.sr_clip_antialiased : params.sr_clip;
    const bool aliased = input.aliasing >= 0.f && !antialiased;
    p.disagree = antialiased && !input.jittered ? params.sr_disagree : 0.f;
    const bool smooth = params.sr_spatial == SrSpatial::bspline || (params.sr_spatial == SrSpatial::automatic && aliased);
    p.flags = (params.sr_depth_motion ? SR_DEPTH_MOTION : 0u) | (smooth ? SR_SMOOTH_SPATIAL : 0u) |
              (params.sr_noise_average && aliased ? SR_NOISE_AVERAGE : 0u) |
              (params.sr_noise_kernel && aliased && params.resample == Resample::lut ? SR_NOISE_KERNEL : 0u) |
              (params.sr_sharp_current && antialiased ? SR_SHARP_CURRENT : 0u);
    return p;
}

Resample warp_resample(const Params& params, bool extrapolate, InputMeasure input) {
    if (params.warp_resample) return *params.warp_resample;
    return !extrapolate && measures_antialiased(input.aliasing) ? Resample::catmull_rom : Resample::bilinear;
}

SrParams generate_sr_params(const FrameFormat& format, const Params& params, uint32_t out_width,
                            uint32_t out_height, float jitter_x, float jitter_y, bool extrapolate,
                            InputMeasure input) {
    SrParams p = sr_params(format, params, out_width, out_height, jitter_x, jitter_y, true, input);
    p.resample = uint32_t(warp_resample(params, extrapolate, input));
    return p;
}

DenoiseParams denoise_params(const FrameFormat& format, const Params& params) {
    DenoiseParams d{};
    d.width = format.width;
    d.height = format.height;
    d.strength = params.denoise_strength;
    d.noise_floor = params.noise_floor;
    d.gamma = params.denoise_gamma;
    return d;
}

} // namespace params
} // namespace fgsr
