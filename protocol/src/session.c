/* The session description's one set of rules and the pool layout derived from it (fgsr/wire.h):
 * libfgsr_client checks a description before sending it and checks the daemon's layout against
 * fgsr_pool_layout_for; fgsrd checks what it receives and lays the session out with the same two
 * functions. */
#include <fgsr/wire.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static fgsr_status refuse(char* reason, size_t reason_size, const char* fmt, ...) {
    if (reason_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(reason, reason_size, fmt, ap);
        va_end(ap);
    }
    return FGSR_STATUS_INVALID_ARGUMENT;
}

uint32_t fgsr_color_format_bytes(uint32_t format) {
    return FGSR_COLOR_FORMAT_BYTES(format);
}

uint32_t fgsr_mv_format_bytes(uint32_t format) {
    return FGSR_MV_FORMAT_BYTES(format);
}

static int is_scale(float s) {
    return s == 1.f || s == 1.5f || s == 2.f || s == 3.f || s == 4.f;
}

static int finite_nonneg(float v) {
    return isfinite(v) && v >= 0.f;
}

static const uint32_t kKnownModes = FGSR_MODE_SR | FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
static const uint32_t kKnownSessionFlags =
    FGSR_SESSION_MVS_CONTAIN_JITTER | FGSR_SESSION_DILATE_MVS | FGSR_SESSION_MV_Y_UP |
    FGSR_SESSION_LINEAR_MOTION | FGSR_SESSION_NO_DENOISE | FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH |
    FGSR_SESSION_CORRECT_MVS | FGSR_SESSION_FAST_MOTION | FGSR_SESSION_COLOUR_AGREE;

fgsr_status fgsr_session_desc_normalize(const fgsr_session_desc* in, fgsr_session_desc* out, char* reason,
                                        size_t reason_size) {
    if (reason_size > 0) reason[0] = '\0';
    if (in->struct_size < sizeof(fgsr_session_desc))
        return refuse(reason, reason_size, "session description struct_size %u is below %zu", in->struct_size,
                      sizeof(fgsr_session_desc));
    fgsr_session_desc d = *in;
    d.struct_size = sizeof(fgsr_session_desc);
    if (d.input_slots == 0) d.input_slots = FGSR_DEFAULT_INPUT_SLOTS;
    if (d.output_slots == 0) d.output_slots = FGSR_DEFAULT_OUTPUT_SLOTS;
    if (d.ring_capacity == 0) d.ring_capacity = FGSR_DEFAULT_RING_CAPACITY;
    *out = d;
    if (d.width < 1 || d.width > FGSR_MAX_FRAME_SIDE || d.height < 1 || d.height > FGSR_MAX_FRAME_SIDE)
        return refuse(reason, reason_size, "size %ux%u outside 1..%u", d.width, d.height,
                      FGSR_MAX_FRAME_SIDE);
    if (fgsr_color_format_bytes(d.color_format) == 0 || fgsr_color_format_bytes(d.output_format) == 0)
        return refuse(reason, reason_size, "unknown colour format");
    if (fgsr_mv_format_bytes(d.mv_format) == 0 || d.mv_units > FGSR_MV_UV ||
        d.mv_direction > FGSR_MV_FROM_PREVIOUS)
        return refuse(reason, reason_size, "unknown motion-vector format, units or direction");
    if (d.depth_kind > FGSR_DEPTH_DEVICE_REVERSED) return refuse(reason, reason_size, "unknown depth kind");
    if (!is_scale(d.scale))
        return refuse(reason, reason_size, "scale %g not in {1, 1.5, 2, 3, 4}", (double)d.scale);
    if (d.modes == 0 || (d.modes & ~kKnownModes))
        return refuse(reason, reason_size, "modes must be a nonzero set of FGSR_MODE_* bits");
    if ((d.modes & FGSR_MODE_SR) && d.scale == 1.f)
        return refuse(reason, reason_size, "FGSR_MODE_SR needs a scale above 1");
    /* FGSR_MAX_FRAME_SIDE bounds the outputs too (protocol.h); the engine refuses larger ones. */
    const long out_w = lround((double)d.width * (double)d.scale);
    const long out_h = lround((double)d.height * (double)d.scale);
    if (out_w > (long)FGSR_MAX_FRAME_SIDE || out_h > (long)FGSR_MAX_FRAME_SIDE)
        return refuse(reason, reason_size, "output size %ldx%ld (size %ux%u times scale %g) exceeds %ux%u", out_w,
                      out_h, d.width, d.height, (double)d.scale, FGSR_MAX_FRAME_SIDE, FGSR_MAX_FRAME_SIDE);
    if (d.flags & ~kKnownSessionFlags) return refuse(reason, reason_size, "unknown session flags");
    if ((d.flags & FGSR_SESSION_CORRECT_MVS) && (d.flags & FGSR_SESSION_NO_MVS))
        return refuse(reason, reason_size,
                      "FGSR_SESSION_CORRECT_MVS needs vectors: not with FGSR_SESSION_NO_MVS");
    if ((d.flags & FGSR_SESSION_COLOUR_AGREE) && (d.flags & FGSR_SESSION_NO_MVS))
        return refuse(reason, reason_size,
                      "FGSR_SESSION_COLOUR_AGREE needs vectors: not with FGSR_SESSION_NO_MVS");
    if ((d.flags & FGSR_SESSION_FAST_MOTION) && !(d.flags & FGSR_SESSION_NO_MVS))
        return refuse(reason, reason_size,
                      "FGSR_SESSION_FAST_MOTION is for motion estimated from colour: only with "
                      "FGSR_SESSION_NO_MVS");
    if ((d.flags & FGSR_SESSION_CORRECT_MVS) && d.scale != 1.f)
        return refuse(reason, reason_size,
                      "FGSR_SESSION_CORRECT_MVS is for scale 1, not %g (no super resolution)",
                      (double)d.scale);
    if ((d.flags & FGSR_SESSION_COLOUR_AGREE) && d.scale != 1.f &&
        !(d.modes & (FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE)))
        return refuse(reason, reason_size,
                      "FGSR_SESSION_COLOUR_AGREE at scale %g is for generated frames (ISR, ESR): modes lack "
                      "FGSR_MODE_INTERPOLATE and FGSR_MODE_EXTRAPOLATE",
                      (double)d.scale);
    if (d.queue_policy > FGSR_QUEUE_MAILBOX) return refuse(reason, reason_size, "unknown queue policy");
    if (d.input_slots > FGSR_MAX_SLOTS || d.output_slots > FGSR_MAX_SLOTS)
        return refuse(reason, reason_size, "slot counts must be 1..%u", FGSR_MAX_SLOTS);
    /* Every slot can be in flight at once, and the completions of one submit (at most
     * output_slots) fit in the ring: neither the submit nor the release ring can overflow. */
    const uint32_t min_capacity = d.input_slots > d.output_slots ? d.input_slots : d.output_slots;
    if ((d.ring_capacity & (d.ring_capacity - 1)) != 0 || d.ring_capacity < min_capacity ||
        d.ring_capacity > FGSR_MAX_RING_CAPACITY)
        return refuse(reason, reason_size, "ring capacity %u is not a power of two in %u..%u",
                      d.ring_capacity, min_capacity, FGSR_MAX_RING_CAPACITY);
    if (!isfinite(d.near_plane) || isnan(d.far_plane))
        return refuse(reason, reason_size, "near_plane must be finite and far_plane not NaN");
    if (!finite_nonneg(d.t_depth) || !finite_nonneg(d.t_bright) || !finite_nonneg(d.sr_a) ||
        !finite_nonneg(d.sr_b))
        return refuse(reason, reason_size, "t_depth, t_bright, sr_a and sr_b must be finite and >= 0");
    for (size_t i = 0; i < sizeof(d.reserved) / sizeof(d.reserved[0]); ++i)
        if (d.reserved[i] != 0) return refuse(reason, reason_size, "reserved fields must be zero");
    const fgsr_pool_layout l = fgsr_pool_layout_for(&d);
    if (l.input_pool_size > FGSR_MAX_POOL_SIZE || l.output_pool_size > FGSR_MAX_POOL_SIZE)
        return refuse(reason, reason_size, "slot pools would exceed the daemon's limit of 2 GiB each");
    return FGSR_STATUS_OK;
}

static fgsr_plane plane(uint64_t offset, uint32_t width, uint32_t height, uint32_t bpp, uint32_t format) {
    fgsr_plane p;
    p.offset = offset;
    p.size = (uint64_t)width * height * bpp;
    p.row_pitch = width * bpp;
    p.format = format;
    return p;
}

fgsr_pool_layout fgsr_pool_layout_for(const fgsr_session_desc* d) {
    fgsr_pool_layout l;
    memset(&l, 0, sizeof(l));
    l.input_slot_count = d->input_slots;
    l.output_slot_count = d->output_slots;
    l.color = plane(0, d->width, d->height, fgsr_color_format_bytes(d->color_format), d->color_format);
    /* Planes the session declared absent take no space (offset, size and pitch 0). */
    uint64_t end = fgsr_align_up(l.color.size, FGSR_PLANE_ALIGNMENT);
    if (d->flags & FGSR_SESSION_NO_DEPTH) {
        l.depth = plane(0, 0, 0, 4, 0);
    } else {
        l.depth = plane(end, d->width, d->height, 4, 0);
        end = fgsr_align_up(l.depth.offset + l.depth.size, FGSR_PLANE_ALIGNMENT);
    }
    if (d->flags & FGSR_SESSION_NO_MVS) {
        l.mv = plane(0, 0, 0, fgsr_mv_format_bytes(d->mv_format), d->mv_format);
    } else {
        l.mv = plane(end, d->width, d->height, fgsr_mv_format_bytes(d->mv_format), d->mv_format);
        end = fgsr_align_up(l.mv.offset + l.mv.size, FGSR_PLANE_ALIGNMENT);
    }
    l.input_slot_stride = end;
    l.input_pool_size = l.input_slot_stride * d->input_slots;
    l.output_width = (uint32_t)lround((double)d->width * (double)d->scale);
    l.output_height = (uint32_t)lround((double)d->height * (double)d->scale);
    l.output = plane(0, l.output_width, l.output_height, fgsr_color_format_bytes(d->output_format),
                     d->output_format);
    l.output_slot_stride = fgsr_align_up(l.output.size, FGSR_PLANE_ALIGNMENT);
    l.output_pool_size = l.output_slot_stride * d->output_slots;
    l.rings_size = fgsr_rings_layout_for(d->ring_capacity).total_size;
    l.ring_capacity = d->ring_capacity;
    return l;
}
