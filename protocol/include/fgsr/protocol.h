/*
 * fgsr public contract: the types and values libfgsr_client's API (fgsr/client.h) speaks in, and
 * that fgsrd honours. Plain C11, no dependencies beyond <stdint.h>; also valid C++. Installed with
 * libfgsr_client.
 *
 * What travels on the socket and in shared memory between the client library and fgsrd (control
 * messages, rings, entries) is private to those two: fgsr/wire.h, not installed. How fgsrd reads
 * the parts of this contract it leaves open: daemon/fgsrd/README.md.
 *
 * Compatibility
 *   Structs are fixed-width with explicit padding; new fields only at the end, signalled by the
 *   minor version or a struct_size field. A peer with another major version is refused with
 *   FGSR_STATUS_VERSION_MISMATCH.
 */
#ifndef FGSR_PROTOCOL_H
#define FGSR_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define FGSR_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
extern "C" {
#else
#define FGSR_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#endif

#define FGSR_PROTOCOL_MAJOR 1u
/* Minor versions: 1: FGSR_SESSION_NO_DENOISE, FGSR_PASS_DENOISE;
 * 2: FGSR_SESSION_NO_MVS, FGSR_SESSION_NO_DEPTH, motion passes;
 * 3: present reports (fgsr_present_report, FGSR_MSG_REPORT);
 * 4: FGSR_SESSION_CORRECT_MVS;
 * 5: FGSR_SESSION_FAST_MOTION;
 * 6: FGSR_PASS_AGREE;
 * 7: FGSR_SESSION_COLOUR_AGREE, fgsr_pass_record.runs (one record per pass and output);
 * 8: FGSR_SESSION_COLOUR_AGREE with a scale other than 1 (ISR, ESR) */
#define FGSR_PROTOCOL_MINOR 8u

#define FGSR_PLANE_ALIGNMENT 4096u  /* plane offsets and slot strides (host-pointer import) */
#define FGSR_MAX_ALPHAS 8u          /* interpolated or extrapolated frames per submit, each */
#define FGSR_MAX_PASSES 12u         /* pass records per telemetry record */
#define FGSR_MAX_SLOTS 64u          /* input or output slots per session */
#define FGSR_MAX_FRAME_SIDE 16384u  /* largest width or height of an input or output frame */
#define FGSR_NO_SLOT 0xffffffffu

/* ---------------------------------------------------------------------------------------------
 * Status codes: the wire, the completion records and the client C API share them.
 * ------------------------------------------------------------------------------------------- */
typedef enum fgsr_status {
    FGSR_STATUS_OK = 0,
    FGSR_STATUS_INVALID_ARGUMENT = 1,   /* a value out of range (alpha, size, slot index, format) */
    FGSR_STATUS_DAEMON_UNAVAILABLE = 2, /* no daemon listens on the socket path */
    FGSR_STATUS_DISCONNECTED = 3,       /* the daemon went away (or dropped this client) */
    FGSR_STATUS_VERSION_MISMATCH = 4,   /* the peer speaks another major protocol version */
    FGSR_STATUS_PROTOCOL_ERROR = 5,     /* a malformed message or ring entry */
    FGSR_STATUS_PERMISSION_DENIED = 6,  /* the daemon refuses this user */
    FGSR_STATUS_OUT_OF_MEMORY = 7,      /* host or device memory exhausted */
    FGSR_STATUS_UNSUPPORTED = 8,        /* format, mode or scale the daemon does not handle */
    FGSR_STATUS_BAD_FRAME = 9,          /* a submitted frame was rejected (reason in the log) */
    FGSR_STATUS_NO_SLOT = 10,           /* no free slot; try again after completions */
    FGSR_STATUS_TIMEOUT = 11,           /* a wait ran out of time */
    FGSR_STATUS_DROPPED = 12,           /* superseded by a newer submit (mailbox policy) */
    FGSR_STATUS_NOT_READY = 13,         /* e.g. interpolation asked of the first frame */
    FGSR_STATUS_DEVICE_ERROR = 14,      /* the engine or the GPU failed */
    FGSR_STATUS_BUSY = 15,              /* too many sessions or clients */
    FGSR_STATUS_INTERNAL = 16,          /* a bug; please report */
    FGSR_STATUS_COUNT_ = 17
} fgsr_status;

/* A static English description of a status ("unknown status" for values out of range). */
const char* fgsr_status_string(int32_t status);

/* ---------------------------------------------------------------------------------------------
 * Formats and conventions (values equal the engine's enums in fgsr/core/types.hpp).
 * ------------------------------------------------------------------------------------------- */
typedef enum fgsr_color_format {
    FGSR_COLOR_RGBA8_SRGB = 0,     /* 4 bytes/pixel */
    FGSR_COLOR_RGBA16F_LINEAR = 1, /* 8 bytes/pixel */
    FGSR_COLOR_RGBA32F_LINEAR = 2  /* 16 bytes/pixel */
} fgsr_color_format;

typedef enum fgsr_depth_kind {
    FGSR_DEPTH_LINEAR = 0,
    FGSR_DEPTH_DEVICE = 1,
    FGSR_DEPTH_DEVICE_REVERSED = 2
} fgsr_depth_kind;

typedef enum fgsr_mv_format { FGSR_MV_RG16F = 0, FGSR_MV_RG32F = 1 } fgsr_mv_format;

/* Bytes per pixel of a colour or vector format, 0 for a value outside its enum: the one table of
 * plane sizes (C, and C++ constant expressions: fgsr/core/types.hpp bytes_per_pixel). */
#define FGSR_COLOR_FORMAT_BYTES(f)                                                                           \
    ((uint32_t)(f) == (uint32_t)FGSR_COLOR_RGBA8_SRGB       ? 4u                                             \
     : (uint32_t)(f) == (uint32_t)FGSR_COLOR_RGBA16F_LINEAR ? 8u                                             \
     : (uint32_t)(f) == (uint32_t)FGSR_COLOR_RGBA32F_LINEAR ? 16u                                            \
                                                            : 0u)
#define FGSR_MV_FORMAT_BYTES(f)                                                                              \
    ((uint32_t)(f) == (uint32_t)FGSR_MV_RG16F ? 4u : (uint32_t)(f) == (uint32_t)FGSR_MV_RG32F ? 8u : 0u)
typedef enum fgsr_mv_units { FGSR_MV_PIXELS = 0, FGSR_MV_UV = 1 } fgsr_mv_units;
typedef enum fgsr_mv_direction { FGSR_MV_TO_PREVIOUS = 0, FGSR_MV_FROM_PREVIOUS = 1 } fgsr_mv_direction;

typedef enum fgsr_queue_policy {
    FGSR_QUEUE_FIFO = 0,   /* every submit is processed in order (replay, capture) */
    FGSR_QUEUE_MAILBOX = 1 /* only the newest pending submit is processed; older ones DROPPED */
} fgsr_queue_policy;

/* Bits of fgsr_session_desc.modes: the outputs a session may request. */
#define FGSR_MODE_SR 0x1u          /* the submitted frame, upscaled (needs scale > 1) */
#define FGSR_MODE_INTERPOLATE 0x2u /* frames between the previous submit and this one */
#define FGSR_MODE_EXTRAPOLATE 0x4u /* frames after this one */

/* Bits of fgsr_session_desc.flags. */
#define FGSR_SESSION_MVS_CONTAIN_JITTER 0x1u /* vectors are differences of jittered positions */
#define FGSR_SESSION_DILATE_MVS 0x2u         /* frontmost vector of the 3x3 neighbourhood */
#define FGSR_SESSION_MV_Y_UP 0x4u            /* +y of the vectors points up on screen */
#define FGSR_SESSION_LINEAR_MOTION 0x8u      /* uniform velocity instead of quadratic motion */
#define FGSR_SESSION_NO_DENOISE 0x10u        /* SR: no pre-filter of noisy input (minor 1) */
/* Colour-only input (minor 2), e.g. a Vulkan layer on an unmodified application. NO_MVS: the client
 * gives no vectors; the daemon estimates them from colour (luma pyramid, block matching,
 * forward-backward consistency; scene cuts reset). NO_DEPTH: the client gives no depth; the daemon
 * orders surfaces by a depth proxy derived from the motion (daemon/engine/README.md). The slot has
 * no plane for what is absent (its fgsr_plane has size 0 and row_pitch 0); mv_format, mv_units,
 * mv_direction and depth_kind are then ignored, and FGSR_SUBMIT_HAS_MV is refused. */
#define FGSR_SESSION_NO_MVS 0x20u
#define FGSR_SESSION_NO_DEPTH 0x40u
/* Given vectors checked against colour (minor 4): the daemon also estimates motion from colour, as
 * for NO_MVS, and replaces a pixel's vector by the estimate where the colour follows the estimate
 * by far better than the given vector (shading that moves on its own: sun shadows, shadows of
 * objects fixed to the camera). Depth stays the client's. Costs the motion passes at every submit.
 * Refused together with NO_MVS, and with a scale other than 1 (on jittered, aliased input it loses). */
#define FGSR_SESSION_CORRECT_MVS 0x80u
/* Fast motion estimation (minor 5), with FGSR_SESSION_NO_MVS only: the daemon estimates motion
 * without refining the estimated vectors, for CPU devices that cannot afford the refinement. On
 * lavapipe the motion passes then take 0.5-0.6x the time (a whole frame about 0.65-0.7x, up to
 * 960x540; above, the two are the same), and frames lose 0.3-0.4 dB on average, up to 1.2 dB
 * (docs/MOTION.md, "The fast setting"). Refused without FGSR_SESSION_NO_MVS. */
#define FGSR_SESSION_FAST_MOTION 0x100u
/* Frame generation from two fields (minor 7): the daemon also estimates motion from colour, as for
 * NO_MVS, generates each interpolated and extrapolated frame from the given vectors and from the
 * estimate, and per pixel takes the estimate's frame where it explains the colour and the given
 * vectors do not (shading that moves on its own: sun shadows; docs/ACCURACY.md, changes 33 to 35).
 * Where the given vectors explain the colour the frame is the one without the flag. Costs the
 * motion passes at every submit and a second generation per frame (on lavapipe about five times an
 * interpolated frame's time). Refused together with NO_MVS. With a scale other than 1 (minor 8)
 * the generated frames (ISR, ESR) come from both fields, mixed by each field's residual at the
 * newest input, and the estimate's session upscales every submit too (its own sr pass); the
 * upscaled frame is the one without the flag: refused there unless modes has
 * FGSR_MODE_INTERPOLATE or FGSR_MODE_EXTRAPOLATE. */
#define FGSR_SESSION_COLOUR_AGREE 0x200u

/* Capability bits (fgsr_hello / fgsr_hello_reply). */
#define FGSR_CAP_ZERO_COPY_INPUT 0x1u /* inputs imported without a copy (external host memory) */
#define FGSR_CAP_SR 0x2u
#define FGSR_CAP_INTERPOLATE 0x4u
#define FGSR_CAP_EXTRAPOLATE 0x8u
#define FGSR_CAP_CALIBRATED_TIME 0x10u /* GPU timestamps are calibrated to CLOCK_MONOTONIC */

/* What a session needs; the body of FGSR_MSG_CREATE_SESSION. Zero means "default" where stated. */
typedef struct fgsr_session_desc {
    uint32_t struct_size; /* sizeof(fgsr_session_desc) of the sender */
    uint32_t width;       /* rendered (input) size in pixels, 1..FGSR_MAX_FRAME_SIDE */
    uint32_t height;
    uint32_t color_format; /* fgsr_color_format of the input colour */
    uint32_t mv_format;    /* fgsr_mv_format */
    uint32_t depth_kind;   /* fgsr_depth_kind; depth is always 32-bit float */
    uint32_t mv_units;     /* fgsr_mv_units */
    uint32_t mv_direction; /* fgsr_mv_direction */
    float near_plane;      /* device depth only; finite */
    float far_plane;       /* device depth only; 0 or +inf: infinite; not NaN */
    float scale;           /* output size = round(size * scale); 1: no super resolution.
                            * One of 1, 1.5, 2, 3, 4; output_width = lround((double)width *
                            * (double)scale), same for height. */
    uint32_t modes;        /* FGSR_MODE_* bits the session will request */
    uint32_t flags;        /* FGSR_SESSION_* bits (no others) */
    uint32_t queue_policy; /* fgsr_queue_policy */
    uint32_t input_slots;  /* 0: 3; at most FGSR_MAX_SLOTS */
    uint32_t output_slots; /* 0: 4; at most FGSR_MAX_SLOTS */
    uint32_t output_format; /* fgsr_color_format of the outputs (linear or sRGB-encoded) */
    uint32_t ring_capacity; /* entries per ring, power of two; 0: 64. At least
                             * max(input_slots, output_slots) after defaults, at most 4096, so
                             * that neither the submit nor the release ring can overflow. */
    float t_depth;          /* 0: the engine's default; finite, >= 0 */
    float t_bright;         /* 0: the engine's default; finite, >= 0 */
    float sr_a;             /* 0: the engine's default; finite, >= 0 */
    float sr_b;             /* 0: the engine's default; finite, >= 0 */
    uint32_t reserved[10];  /* zero */
} fgsr_session_desc;
FGSR_STATIC_ASSERT(sizeof(fgsr_session_desc) == 128, "fgsr_session_desc size");

/* One plane inside a slot. Rows are tightly packed unless row_pitch says otherwise. */
typedef struct fgsr_plane {
    uint64_t offset;    /* from the start of the slot; multiple of FGSR_PLANE_ALIGNMENT */
    uint64_t size;      /* bytes */
    uint32_t row_pitch; /* bytes between rows */
    uint32_t format;    /* fgsr_color_format, fgsr_mv_format, or 0 for 32-bit float depth */
} fgsr_plane;
FGSR_STATIC_ASSERT(sizeof(fgsr_plane) == 24, "fgsr_plane size");

/* Where everything lives in a session's shared memory. One function computes it for a session
 * description (fgsr_pool_layout_for, fgsr/wire.h): fgsrd sends what it returns, and the client
 * accepts the daemon's layout only when it equals what the client computes itself (every field
 * but `reserved`). The properties it guarantees:
 *   - slot counts and ring_capacity equal the request after defaults (3, 4, 64);
 *   - output_width/height as stated at fgsr_session_desc.scale;
 *   - strides and plane offsets multiples of FGSR_PLANE_ALIGNMENT; each plane inside its slot,
 *     row_pitch >= width * bytes per pixel, size >= row_pitch * height, input planes disjoint;
 *     a plane the session declared absent (FGSR_SESSION_NO_MVS / NO_DEPTH) is all zero but its
 *     format (offset 0, size 0, row_pitch 0);
 *     plane formats: color = desc.color_format, depth = 0, mv = desc.mv_format,
 *     output = desc.output_format;
 *   - pool sizes = count * stride, each at most 2 GiB (a larger session is INVALID_ARGUMENT);
 *     rings_size = the rings memfd's size for ring_capacity. */
typedef struct fgsr_pool_layout {
    uint64_t input_slot_stride; /* bytes; multiple of FGSR_PLANE_ALIGNMENT */
    uint64_t input_pool_size;   /* input_slot_count * input_slot_stride */
    uint32_t input_slot_count;
    uint32_t output_slot_count;
    uint64_t output_slot_stride;
    uint64_t output_pool_size;
    uint32_t output_width; /* input size times scale */
    uint32_t output_height;
    fgsr_plane color; /* input planes, within an input slot */
    fgsr_plane depth;
    fgsr_plane mv;
    fgsr_plane output; /* the output colour, within an output slot */
    uint64_t rings_size; /* bytes of the rings memfd */
    uint32_t ring_capacity;
    uint32_t reserved;
} fgsr_pool_layout;
FGSR_STATIC_ASSERT(sizeof(fgsr_pool_layout) == 160, "fgsr_pool_layout size");

/* Aggregates over a session's life (FGSR_MSG_STATS). Latencies: submit to completion, ns. */
typedef struct fgsr_session_stats {
    uint64_t frames_submitted; /* submit entries read */
    uint64_t frames_rejected;  /* completed with an error status other than DROPPED */
    uint64_t frames_dropped;   /* mailbox: superseded */
    uint64_t outputs_written;
    uint64_t latency_p50_ns; /* percentiles over recent outputs (fgsrd: daemon/fgsrd/README.md) */
    uint64_t latency_p99_ns;
    uint64_t gpu_p50_ns; /* engine GPU time per output */
    uint64_t gpu_p99_ns;
    uint64_t queue_wait_p50_ns;
    uint64_t queue_wait_p99_ns;
    uint64_t bytes_copied; /* host copies of frame data the daemon made (0 with zero-copy input) */
    uint64_t reserved[5];
} fgsr_session_stats;
FGSR_STATIC_ASSERT(sizeof(fgsr_session_stats) == 128, "fgsr_session_stats size");

/* Bits of fgsr_submit_entry.flags. */
#define FGSR_SUBMIT_RESET 0x1u    /* scene cut: forget history and the previous frame */
#define FGSR_SUBMIT_HAS_MV 0x2u   /* the mv plane holds vectors (else unknown) */
#define FGSR_SUBMIT_WANT_SR 0x4u  /* write the super-resolved frame */

typedef enum fgsr_frame_type {
    FGSR_FRAME_NONE = 0,         /* no output (error or drop) */
    FGSR_FRAME_UPSCALED = 1,     /* the rendered frame, super-resolved */
    FGSR_FRAME_INTERPOLATED = 2, /* between the previous and this frame */
    FGSR_FRAME_EXTRAPOLATED = 3  /* after this frame */
} fgsr_frame_type;

/* Pass ids and names follow from the pass table (fgsr/passes.h): INGEST 0 .. CLASSIFY 9,
 * DENOISE 10 (minor 1), LUMA 11, MATCH 12, FLOW 13 (minor 2: motion estimation from colour). */
#include <fgsr/passes.h>
typedef enum fgsr_pass_id {
#define FGSR_PASS_ID_(ID, name, value) FGSR_PASS_##ID = value,
    FGSR_PASSES(FGSR_PASS_ID_)
#undef FGSR_PASS_ID_
    FGSR_PASS_COUNT_
} fgsr_pass_id;
FGSR_STATIC_ASSERT(FGSR_PASS_COUNT_ == 16, "the pass table's values are 0..15 in order");

/* The engine's name of a pass ("ingest", ..., "flow"; "unknown" for values out of range). */
const char* fgsr_pass_name(uint32_t pass);

typedef struct fgsr_pass_record {
    uint32_t pass;         /* fgsr_pass_id */
    uint32_t tiles_total;  /* 0 when the pass does not classify tiles */
    uint32_t tiles_skipped;
    /* Minor 7: how many runs of the pass this record sums (0 from older daemons: one). A pass that
     * ran more than once for one output (FGSR_SESSION_COLOUR_AGREE generates from two fields) has one
     * record: gpu_begin_ns is its first run's begin, gpu_end_ns - gpu_begin_ns the sum of its runs'
     * times (then not a span of the timeline), tiles the sums of its runs'. */
    uint32_t runs;
    uint64_t gpu_begin_ns; /* CLOCK_MONOTONIC (calibrated when FGSR_CAP_CALIBRATED_TIME) */
    uint64_t gpu_end_ns;
} fgsr_pass_record;
FGSR_STATIC_ASSERT(sizeof(fgsr_pass_record) == 32, "fgsr_pass_record size");

/* Per output frame. All times CLOCK_MONOTONIC ns. */
typedef struct fgsr_telemetry {
    uint32_t frame_type;     /* fgsr_frame_type */
    uint32_t pass_count;     /* valid entries of passes[] */
    float target_time;       /* alpha (interpolated), 1 + alpha (extrapolated), 1 (upscaled) */
    uint32_t skipped_passes; /* bit (1 << fgsr_pass_id) per pass skipped for this frame */
    uint64_t target_present_ns; /* present time the frame stands for (0: unknown) */
    uint64_t submit_ns;         /* copied from the submit entry */
    uint64_t dequeue_ns;        /* the daemon read the submit */
    uint64_t start_ns;          /* the daemon began this frame's work */
    uint64_t complete_ns;       /* the output was written and published */
    uint64_t queue_wait_ns;     /* start_ns - dequeue_ns */
    uint64_t gpu_ns;            /* sum of the passes' GPU time */
    uint64_t daemon_cpu_ns;     /* daemon thread CPU time spent on this output */
    fgsr_pass_record passes[FGSR_MAX_PASSES];
} fgsr_telemetry;
FGSR_STATIC_ASSERT(sizeof(fgsr_telemetry) == 464, "fgsr_telemetry size");

/* What the client did with a frame (minor 3): the application's own frame or an output, when it
 * held it and when it was presented. fgsrd adds them to the session's telemetry (its dashboard,
 * /metrics and /trace.json show them: frame times from present times, client-observed latency).
 * All times CLOCK_MONOTONIC ns, 0 where unknown. */
#define FGSR_REPORT_APPLICATION 0xffffffffu /* output_index of the application's own frame */
#define FGSR_REPORT_DROPPED 0x1u            /* flags: the frame was not presented */
typedef struct fgsr_present_report {
    uint64_t sequence;     /* the submit the frame belongs to (0: a frame that was never submitted) */
    uint32_t output_index; /* the output's index within the submit, or FGSR_REPORT_APPLICATION */
    uint32_t frame_type;   /* fgsr_frame_type; FGSR_FRAME_NONE for the application's own frame */
    uint32_t flags;        /* FGSR_REPORT_* */
    uint32_t reserved;
    uint64_t submit_ns;    /* the application's present call (own frame) or the submit (output) */
    uint64_t received_ns;  /* the client held the output (fgsr_wait returned it) */
    uint64_t intended_ns;  /* when the client's pacing meant to present it */
    uint64_t presented_ns; /* when it was presented (the present call returned, or present-wait) */
} fgsr_present_report;
FGSR_STATIC_ASSERT(sizeof(fgsr_present_report) == 56, "fgsr_present_report size");

/* A click-to-photon measurement of a hardware latency probe (minor 3; `fgsr probe`, docs/PROBE.md):
 * the probe injected a click and its photodiode saw the screen change. fgsrd's dashboard shows them
 * as click-to-photon latency. Times CLOCK_MONOTONIC ns (the probe's clock mapped onto it). */
#define FGSR_PROBE_MODE_UNKNOWN 0u
#define FGSR_PROBE_MODE_OFF 1u         /* frame generation off */
#define FGSR_PROBE_MODE_INTERPOLATE 2u
#define FGSR_PROBE_MODE_EXTRAPOLATE 3u
typedef struct fgsr_probe_sample {
    uint64_t click_ns;  /* the click was injected */
    uint64_t photon_ns; /* the photodiode saw the change (>= click_ns) */
    uint32_t mode;      /* FGSR_PROBE_MODE_* of the measured application */
    uint32_t pid;       /* the measured application's process (0: unknown) */
} fgsr_probe_sample;
FGSR_STATIC_ASSERT(sizeof(fgsr_probe_sample) == 24, "fgsr_probe_sample size");

/* Bits of fgsr_completion_entry.flags. */
#define FGSR_COMPLETION_INPUT_RELEASED 0x1u /* input_slot is the client's again */
#define FGSR_COMPLETION_LAST 0x2u           /* the last completion of this submit */

#ifdef __cplusplus
}
#endif

#endif /* FGSR_PROTOCOL_H */
