// Parameter building: checks of a frame against its format, and the push constants of every pass
// (shaders/common.h: IngestParams, GenParams, SrParams, DenoiseParams) from a format and Params.
// The GPU path and the CPU reference (fgsr/engine/reference.hpp) both take them from here; the
// check of Params itself is fgsr::validate(const Params&) (engine.hpp), defined with these.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>
#include <fgsr/engine/engine.hpp>

#include "common.h" // shaders/: the push-constant structs

namespace fgsr::params {

using fgsr::validate; // of Params (engine.hpp)

// Checks the colour and motion-vector format codes of a format. Errors: unsupported.
Result<void> validate_formats(const FrameFormat& format);

// Checks a frame against its format (sizes, enum values, near/far). Shared by the engine and tools.
Result<void> validate(const FrameFormat& format, const FrameView& frame);

// The push constants the engine uses for `ingest` of a frame of this format.
gpu::IngestParams ingest_params(const FrameFormat& format, bool has_mv);
// ... with its dilate stage's switches (shaders/dilate.h), for frames with the client's vectors and
// depth, not corrected by colour (Params::correct_vectors): the over-white rule (bright =
// Params::dilate_bright) in a linear colour format; the edge rule (edge_ratio =
// Params::dilate_edges) when the frame has a previous one (`has_previous`: not the session's first
// frame, no scene cut). Otherwise off (0).
void set_dilate(gpu::IngestParams& p, const FrameFormat& format, const Params& params, bool has_previous);

// What a session measured of its input (Session::input_aliasing, Session::input_jittered).
struct InputMeasure {
    float aliasing = -1.f; // aliasing_ratio of the first frames; negative: not measured
    bool jittered = false; // some frame so far carried jitter
};
// What session s measured of its input (its input_aliasing and input_jittered), as the engine
// passes it to gen_params and sr_params: for tools and tests that rebuild a session's push constants.
InputMeasure input_measure(const Session& s);

// The push constants the engine uses for one generated frame. The input measure decides
// WarpKernel::automatic (the cubic in interpolation where the input measures antialiased).
gpu::GenParams gen_params(const FrameFormat& format, const Params& params, float alpha, bool extrapolate,
                          bool frame0_has_mv, bool frame1_has_mv, InputMeasure input = {});
// The agree pass's push constants (Params::colour_agree) for generated frame `g`.
gpu::AgreeParams agree_params(const gpu::GenParams& g);

// The push constants of the `sr` pass for a frame (has_history: a previous output exists and
// the frame is no reset). The input measure decides Params::sr_disagree (only without jitter and
// measuring antialiased, shaders/sr.h step 6) and SrSpatial::automatic (the B-spline where the
// input measures aliased, jittered or not, step 5).
gpu::SrParams sr_params(const FrameFormat& format, const Params& params, uint32_t out_width,
                        uint32_t out_height, float jitter_x, float jitter_y, bool has_history,
                        InputMeasure input = {});

// The resampling of the SR outputs in ISR (extrapolate false) or ESR: Params::warp_resample where
// set; unset, Catmull-Rom for ISR on input that measures antialiased, else bilinear
// (docs/ACCURACY.md, change 48).
Resample warp_resample(const Params& params, bool extrapolate, InputMeasure input);

// The SR half of the `generate_sr` push constants (ISR / ESR): sr_params with history, and
// warp_resample above as the resampling of the SR outputs; the history's clip is
// Params::sr_clip_antialiased where `input` measures antialiased, else Params::sr_clip.
gpu::SrParams generate_sr_params(const FrameFormat& format, const Params& params, uint32_t out_width,
                                 uint32_t out_height, float jitter_x, float jitter_y, bool extrapolate,
                                 InputMeasure input = {});

// The push constants of the `denoise` pass (stage left 0) for frames of this format.
gpu::DenoiseParams denoise_params(const FrameFormat& format, const Params& params);

} // namespace fgsr::params
