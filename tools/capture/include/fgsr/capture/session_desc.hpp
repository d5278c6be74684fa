// The fgsrd session description (fgsr/protocol.h) that asks the service for what an in-process
// engine session of `format` and `params` does: formats, conventions, colour-only input (no
// vectors / no depth), scale, motion model, vector dilation and jitter handling, the correction of
// vectors and interpolation by agreement (both only with vectors, agreement only at scale 1, as
// the engine), thresholds; fifo queue, rgba32f linear outputs (bit-comparable with the engine's
// ImageRGBA), default slot counts. Header-only: includers need fgsr/protocol.h on their include
// path (fgsr_protocol or fgsr_client). Callers adjust the rest (slots, policy).
#pragma once

#include <fgsr/engine/engine.hpp>
#include <fgsr/protocol.h>

namespace fgsr::capture {

// modes: FGSR_MODE_* bits the session will request.
inline fgsr_session_desc session_desc(const FrameFormat& f, const Params& p, uint32_t modes) {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = f.width;
    d.height = f.height;
    d.color_format = uint32_t(f.color_format);
    d.mv_format = uint32_t(f.mv_format);
    d.depth_kind = uint32_t(f.conventions.depth_kind);
    d.mv_units = uint32_t(f.conventions.mv_units);
    d.mv_direction = uint32_t(f.conventions.mv_direction);
    d.near_plane = f.conventions.near_plane;
    d.far_plane = f.conventions.far_plane;
    d.scale = p.scale;
    d.modes = modes;
    d.flags = (f.conventions.mv_y_up ? FGSR_SESSION_MV_Y_UP : 0u) |
              (p.dilate_mvs ? FGSR_SESSION_DILATE_MVS : 0u) |
              (p.mvs_contain_jitter ? FGSR_SESSION_MVS_CONTAIN_JITTER : 0u) |
              (p.motion == MotionModel::linear ? FGSR_SESSION_LINEAR_MOTION : 0u) |
              (p.denoise ? 0u : FGSR_SESSION_NO_DENOISE) | (f.has_vectors ? 0u : FGSR_SESSION_NO_MVS) |
              (f.has_depth ? 0u : FGSR_SESSION_NO_DEPTH) |
              (p.correct_vectors && f.has_vectors ? FGSR_SESSION_CORRECT_MVS : 0u) |
              (colour_agree_applies(f, p) &&
                       (p.scale == 1.f || (modes & (FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE)) != 0u)
                   ? FGSR_SESSION_COLOUR_AGREE
                   : 0u) |
              (p.fast_motion && !f.has_vectors ? FGSR_SESSION_FAST_MOTION : 0u);
    d.queue_policy = FGSR_QUEUE_FIFO;
    d.output_format = FGSR_COLOR_RGBA32F_LINEAR;
    d.t_depth = p.t_depth;
    d.t_bright = p.t_bright;
    d.sr_a = p.sr_a;
    d.sr_b = p.sr_b;
    return d;
}

} // namespace fgsr::capture
