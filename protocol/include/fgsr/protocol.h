/*
 * fgsr wire and shared-memory contract, shared by fgsrd and libfgsr_client. Plain C11, no
 * dependencies beyond <stdint.h>; also valid C++.
 *
 * Transport
 *   Control: a SOCK_SEQPACKET Unix socket (default $XDG_RUNTIME_DIR/fgsr/fgsrd.sock). Every
 *   message starts with fgsr_msg_header; one message per packet; file descriptors travel with
 *   SCM_RIGHTS on the reply that creates them. The client speaks first (FGSR_MSG_HELLO); every
 *   request gets exactly one reply, in order.
 *   Data: per session three memfds and two eventfds, created by the daemon:
 *     - input pool  (FGSR_FD_INPUT_POOL): input_slot_count slots, client writes, daemon reads.
 *                   Sealed against shrink and grow.
 *     - output pool (FGSR_FD_OUTPUT_POOL): output_slot_count slots, daemon writes. Sealed against
 *                   shrink, grow and future writes: clients can map it read-only only.
 *     - rings       (FGSR_FD_RINGS): the submit, completion and release rings (fgsr_rings_layout).
 *     - submit eventfd   (FGSR_FD_SUBMIT_EVENT): the client writes 1 after pushing submit or
 *                        release entries.
 *     - complete eventfd (FGSR_FD_COMPLETE_EVENT): the daemon writes 1 after pushing completions.
 *
 * Frame life cycle
 *   The client owns every input slot at session start. It fills one (planes as in
 *   fgsr_pool_layout), pushes a fgsr_submit_entry naming it, and signals. The daemon copies the
 *   entry, validates it, ingests the planes and hands the input slot back with the last
 *   completion of that submit (FGSR_COMPLETION_INPUT_RELEASED). Each requested output (SR of this
 *   frame, interpolated frames, extrapolated frames) is written into a free output slot and
 *   announced by one fgsr_completion_entry; the client owns that output slot until it pushes its
 *   index on the release ring. A rejected or dropped submit gets one completion with a status and
 *   no output slot.
 *
 * Rules for shared memory (both sides)
 *   Every field of shared memory is written by exactly one side (stated per field). Entries are
 *   copied out of the ring into private memory before they are validated; nothing is re-read.
 *   Ring positions are free-running 64-bit counters; capacity is a power of two.
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

#define FGSR_PROTOCOL_MAGIC 0x52534746u /* "FGSR" little-endian */
#define FGSR_PROTOCOL_MAJOR 1u
#define FGSR_PROTOCOL_MINOR 1u /* 1: FGSR_SESSION_NO_DENOISE, FGSR_PASS_DENOISE */

#define FGSR_CACHE_LINE 64u
#define FGSR_PLANE_ALIGNMENT 4096u  /* plane offsets and slot strides (host-pointer import) */
#define FGSR_MAX_ALPHAS 8u          /* interpolated or extrapolated frames per submit, each */
#define FGSR_MAX_PASSES 12u         /* pass records per telemetry record */
#define FGSR_MAX_SLOTS 64u          /* input or output slots per session */
#define FGSR_MAX_FRAME_SIDE 16384u  /* largest width or height of an input or output frame */
#define FGSR_MAX_MESSAGE_SIZE 1024u /* largest control message, header included */
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
                                        /* fgsrd: the engine refused the frame's content (e.g.
                                         * jitter outside [-1, 1] px); input released, the
                                         * session goes on */
    FGSR_STATUS_NO_SLOT = 10,           /* no free slot; try again after completions */
    FGSR_STATUS_TIMEOUT = 11,           /* a wait ran out of time */
    FGSR_STATUS_DROPPED = 12,           /* superseded by a newer submit (mailbox policy) */
    FGSR_STATUS_NOT_READY = 13,         /* e.g. interpolation asked of the first frame */
                                        /* fgsrd: interpolation or extrapolation while fewer than
                                         * two frames were submitted since the start or the last
                                         * FGSR_SUBMIT_RESET; one completion per such output */
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

/* Capability bits (fgsr_hello / fgsr_hello_reply). */
#define FGSR_CAP_ZERO_COPY_INPUT 0x1u /* inputs imported without a copy (external host memory) */
#define FGSR_CAP_SR 0x2u
#define FGSR_CAP_INTERPOLATE 0x4u
#define FGSR_CAP_EXTRAPOLATE 0x8u
#define FGSR_CAP_CALIBRATED_TIME 0x10u /* GPU timestamps are calibrated to CLOCK_MONOTONIC */

/* ---------------------------------------------------------------------------------------------
 * Control messages (socket).
 * ------------------------------------------------------------------------------------------- */
typedef enum fgsr_msg_type {
    FGSR_MSG_HELLO = 1,                 /* client -> daemon: fgsr_hello */
    FGSR_MSG_HELLO_REPLY = 2,           /* daemon -> client: fgsr_hello_reply */
    FGSR_MSG_CREATE_SESSION = 3,        /* client -> daemon: fgsr_session_desc */
    FGSR_MSG_CREATE_SESSION_REPLY = 4,  /* daemon -> client: fgsr_create_session_reply + 5 fds */
    FGSR_MSG_DESTROY_SESSION = 5,       /* client -> daemon: fgsr_session_ref */
    FGSR_MSG_DESTROY_SESSION_REPLY = 6, /* daemon -> client: fgsr_reply */
    FGSR_MSG_STATS = 7,                 /* client -> daemon: fgsr_session_ref */
    FGSR_MSG_STATS_REPLY = 8,           /* daemon -> client: fgsr_stats_reply */
    FGSR_MSG_ERROR = 9                  /* daemon -> client: fgsr_reply, then the daemon may close */
    /* fgsrd's reading: every protocol violation gets FGSR_MSG_ERROR (status PROTOCOL_ERROR, reason)
     * and then the connection is closed, all its sessions torn down. Violations: a packet shorter
     * than its struct or than a header, wrong magic, header.size != packet size, a packet over
     * FGSR_MAX_MESSAGE_SIZE, an unknown type, any request before HELLO or a second HELLO, fds
     * attached to any message (they are closed unread), desc.struct_size < 128 or beyond the
     * packet; and in the rings: see fgsr_submit_entry and fgsr_release_entry. Longer packets of
     * a known type are accepted (trailing bytes ignored). STATS or DESTROY_SESSION naming a
     * session this connection does not own is not a violation: reply status INVALID_ARGUMENT.
     * HELLO refused (VERSION_MISMATCH, PERMISSION_DENIED, BUSY beyond --max-clients): the reply,
     * then close. */
} fgsr_msg_type;

typedef struct fgsr_msg_header {
    uint32_t magic; /* FGSR_PROTOCOL_MAGIC */
    uint16_t type;  /* fgsr_msg_type */
    uint16_t reserved;
    uint32_t size;     /* bytes of the whole message, header included */
    uint32_t sequence; /* request counter chosen by the client; replies echo it */
} fgsr_msg_header;
FGSR_STATIC_ASSERT(sizeof(fgsr_msg_header) == 16, "fgsr_msg_header size");

typedef struct fgsr_hello {
    fgsr_msg_header header;
    uint16_t major; /* FGSR_PROTOCOL_MAJOR of the client */
    uint16_t minor;
    uint32_t capabilities; /* FGSR_CAP_* the client can use */
    uint32_t pid;          /* informational; the daemon trusts SO_PEERCRED instead */
    uint32_t reserved;
    char name[32]; /* client name for logs, NUL-terminated (the daemon terminates it anyway) */
} fgsr_hello;
FGSR_STATIC_ASSERT(sizeof(fgsr_hello) == 64, "fgsr_hello size");

typedef struct fgsr_hello_reply {
    fgsr_msg_header header;
    int32_t status; /* OK, VERSION_MISMATCH, PERMISSION_DENIED, BUSY */
    uint16_t major; /* the daemon's protocol version */
    uint16_t minor;
    uint32_t capabilities; /* FGSR_CAP_* the daemon offers */
    uint32_t reserved;
    uint64_t epoch; /* identifies this daemon instance (changes on every start) */
    char device[64]; /* Vulkan device name, NUL-terminated */
} fgsr_hello_reply;
FGSR_STATIC_ASSERT(sizeof(fgsr_hello_reply) == 104, "fgsr_hello_reply size");

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
    float near_plane;      /* device depth only */
    float far_plane;       /* device depth only; 0 or +inf: infinite */
    float scale;           /* output size = round(size * scale); 1: no super resolution.
                            * Reading (client side): output_width = lround((double)width *
                            * (double)scale), same for height; the client checks the layout's
                            * output size against it. Range [1, 4]. */
    uint32_t modes;        /* FGSR_MODE_* bits the session will request */
    uint32_t flags;        /* FGSR_SESSION_* bits */
    uint32_t queue_policy; /* fgsr_queue_policy */
    uint32_t input_slots;  /* 0: 3; at most FGSR_MAX_SLOTS */
    uint32_t output_slots; /* 0: 4; at most FGSR_MAX_SLOTS. fgsrd's reading: a submit starts only
                            * when as many output slots are free as it requests outputs (NOT_READY
                            * ones included), so a submit requesting more outputs than
                            * output_slots is completed at once with INVALID_ARGUMENT (input
                            * released, no disconnect). */
    uint32_t output_format; /* fgsr_color_format of the outputs (linear or sRGB-encoded) */
    uint32_t ring_capacity; /* entries per ring, power of two; 0: 64. Reading: at least
                             * max(input_slots, output_slots) after defaults, at most 4096, so
                             * that neither the submit nor the release ring can overflow (the
                             * client refuses smaller values with INVALID_ARGUMENT). */
    float t_depth;          /* 0: the engine's default */
    float t_bright;         /* 0: the engine's default */
    float sr_a;             /* 0: the engine's default */
    float sr_b;             /* 0: the engine's default */
    uint32_t reserved[10];  /* zero */
} fgsr_session_desc;
FGSR_STATIC_ASSERT(sizeof(fgsr_session_desc) == 128, "fgsr_session_desc size");

typedef struct fgsr_create_session {
    fgsr_msg_header header;
    fgsr_session_desc desc;
} fgsr_create_session;
FGSR_STATIC_ASSERT(sizeof(fgsr_create_session) == 144, "fgsr_create_session size");

/* One plane inside a slot. Rows are tightly packed unless row_pitch says otherwise. */
typedef struct fgsr_plane {
    uint64_t offset;    /* from the start of the slot; multiple of FGSR_PLANE_ALIGNMENT */
    uint64_t size;      /* bytes */
    uint32_t row_pitch; /* bytes between rows */
    uint32_t format;    /* fgsr_color_format, fgsr_mv_format, or 0 for 32-bit float depth */
} fgsr_plane;
FGSR_STATIC_ASSERT(sizeof(fgsr_plane) == 24, "fgsr_plane size");

/* Where everything lives; computed by the daemon, validated by the client.
 * What the client checks (libfgsr_client, client/src/client.cpp), so the daemon must satisfy it:
 *   - slot counts and ring_capacity equal the request after defaults (3, 4, 64);
 *   - output_width/height as stated at fgsr_session_desc.scale;
 *   - strides and plane offsets multiples of FGSR_PLANE_ALIGNMENT; each plane inside its slot,
 *     row_pitch >= width * bytes per pixel, size >= row_pitch * height, input planes disjoint;
 *     plane formats: color = desc.color_format, depth = 0, mv = desc.mv_format,
 *     output = desc.output_format;
 *   - pool sizes = count * stride; rings_size = fgsr_rings_layout_for(ring_capacity).total_size;
 *   - fstat: the three memfds are regular files at least as large as their pool / rings size;
 *     F_GET_SEALS of both pools includes F_SEAL_SHRINK | F_SEAL_GROW, and of the output pool also
 *     F_SEAL_FUTURE_WRITE (or F_SEAL_WRITE); fds 3 and 4 are eventfds.
 *   A layout or fd set that fails any check: the client closes every fd and returns
 *   PROTOCOL_ERROR from fgsr_session_create. */
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

/* Order of the fds sent with FGSR_MSG_CREATE_SESSION_REPLY. */
enum {
    FGSR_FD_INPUT_POOL = 0,
    FGSR_FD_OUTPUT_POOL = 1,
    FGSR_FD_RINGS = 2,
    FGSR_FD_SUBMIT_EVENT = 3,
    FGSR_FD_COMPLETE_EVENT = 4,
    FGSR_FD_COUNT = 5
};

typedef struct fgsr_create_session_reply {
    fgsr_msg_header header;
    int32_t status;      /* OK, INVALID_ARGUMENT, UNSUPPORTED, OUT_OF_MEMORY, BUSY */
    uint32_t session_id; /* nonzero; unique within the daemon's epoch */
    uint64_t epoch;
    fgsr_pool_layout layout;
    char reason[64]; /* why, when status is not OK; NUL-terminated */
} fgsr_create_session_reply;
FGSR_STATIC_ASSERT(sizeof(fgsr_create_session_reply) == 256, "fgsr_create_session_reply size");

typedef struct fgsr_session_ref {
    fgsr_msg_header header;
    uint32_t session_id;
    uint32_t reserved;
} fgsr_session_ref;
FGSR_STATIC_ASSERT(sizeof(fgsr_session_ref) == 24, "fgsr_session_ref size");

typedef struct fgsr_reply {
    fgsr_msg_header header;
    int32_t status;
    uint32_t session_id;
    char reason[128]; /* NUL-terminated */
} fgsr_reply;
FGSR_STATIC_ASSERT(sizeof(fgsr_reply) == 152, "fgsr_reply size");

/* Aggregates over a session's life (FGSR_MSG_STATS). Latencies: submit to completion, ns. */
typedef struct fgsr_session_stats {
    uint64_t frames_submitted; /* submit entries read */
    uint64_t frames_rejected;  /* completed with an error status other than DROPPED */
    uint64_t frames_dropped;   /* mailbox: superseded */
    uint64_t outputs_written;
    uint64_t latency_p50_ns; /* fgsrd: percentiles over the last <= 4096 outputs; latency from
                              * submit_time_ns (dequeue time when 0 or in the future) */
    uint64_t latency_p99_ns;
    uint64_t gpu_p50_ns; /* engine GPU time per output */
    uint64_t gpu_p99_ns;
    uint64_t queue_wait_p50_ns;
    uint64_t queue_wait_p99_ns;
    uint64_t bytes_copied; /* host copies of frame data the daemon made (0 with zero-copy input) */
    uint64_t reserved[5];
} fgsr_session_stats;
FGSR_STATIC_ASSERT(sizeof(fgsr_session_stats) == 128, "fgsr_session_stats size");

typedef struct fgsr_stats_reply {
    fgsr_msg_header header;
    int32_t status;
    uint32_t session_id;
    fgsr_session_stats stats;
} fgsr_stats_reply;
FGSR_STATIC_ASSERT(sizeof(fgsr_stats_reply) == 152, "fgsr_stats_reply size");

/* ---------------------------------------------------------------------------------------------
 * Rings (the FGSR_FD_RINGS memfd): three SPSC rings, each a header followed by its entries.
 * ------------------------------------------------------------------------------------------- */
typedef struct fgsr_ring_header {
    uint64_t head; /* written by the producer only: entries pushed (free-running) */
    uint8_t pad0[FGSR_CACHE_LINE - 8];
    uint64_t tail; /* written by the consumer only: entries consumed (free-running) */
    uint8_t pad1[FGSR_CACHE_LINE - 8];
} fgsr_ring_header;
FGSR_STATIC_ASSERT(sizeof(fgsr_ring_header) == 128, "fgsr_ring_header size");

/* Bits of fgsr_submit_entry.flags. */
#define FGSR_SUBMIT_RESET 0x1u    /* scene cut: forget history and the previous frame */
#define FGSR_SUBMIT_HAS_MV 0x2u   /* the mv plane holds vectors (else unknown) */
#define FGSR_SUBMIT_WANT_SR 0x4u  /* write the super-resolved frame */

/* Client -> daemon: one rendered frame and the outputs wanted from it.
 * fgsrd's reading: each entry is copied, then checked; these are protocol violations (ERROR, then
 * disconnect): submit head - tail > capacity; sequence not above the previous one; input_slot out
 * of range or still held by the daemon; unknown flag bits; WANT_SR, interp_count or extrap_count
 * for a mode the session did not declare; a count > FGSR_MAX_ALPHAS; an alpha that is not finite
 * or outside its range (only the first count alphas are read); a completion tail the client moved
 * beyond the daemon's head or more than capacity behind it. */
typedef struct fgsr_submit_entry {
    uint64_t sequence;   /* strictly increasing per session, starts at 1 */
    uint32_t input_slot; /* < input_slot_count, owned by the client until released back */
    uint32_t flags;      /* FGSR_SUBMIT_* */
    float jitter_x;      /* camera jitter of this frame, pixels */
    float jitter_y;
    uint32_t interp_count; /* <= FGSR_MAX_ALPHAS: frames between the previous submit and this */
    uint32_t extrap_count; /* <= FGSR_MAX_ALPHAS: frames after this one */
    float interp_alphas[FGSR_MAX_ALPHAS]; /* each in (0, 1) */
    float extrap_alphas[FGSR_MAX_ALPHAS]; /* each in (0, 1]: frame at 1 + alpha */
    uint64_t submit_time_ns;  /* CLOCK_MONOTONIC when the client pushed the entry */
    uint64_t present_time_ns; /* when this frame is meant to be shown (0: unknown) */
    uint64_t user_data;       /* echoed in the completions */
    uint64_t reserved;
} fgsr_submit_entry;
FGSR_STATIC_ASSERT(sizeof(fgsr_submit_entry) == 128, "fgsr_submit_entry size");

typedef enum fgsr_frame_type {
    FGSR_FRAME_NONE = 0,         /* no output (error or drop) */
    FGSR_FRAME_UPSCALED = 1,     /* the rendered frame, super-resolved */
    FGSR_FRAME_INTERPOLATED = 2, /* between the previous and this frame */
    FGSR_FRAME_EXTRAPOLATED = 3  /* after this frame */
} fgsr_frame_type;

/* Pass ids and names follow from the pass table (fgsr/passes.h): INGEST 0 .. CLASSIFY 9,
 * DENOISE 10 (minor 1). */
#include <fgsr/passes.h>
typedef enum fgsr_pass_id {
#define FGSR_PASS_ID_(ID, name, value) FGSR_PASS_##ID = value,
    FGSR_PASSES(FGSR_PASS_ID_)
#undef FGSR_PASS_ID_
    FGSR_PASS_COUNT_
} fgsr_pass_id;
FGSR_STATIC_ASSERT(FGSR_PASS_COUNT_ == 11, "the pass table's values are 0..10 in order");

/* The engine's name of a pass ("ingest", ..., "denoise"; "unknown" for values out of range). */
const char* fgsr_pass_name(uint32_t pass);

typedef struct fgsr_pass_record {
    uint32_t pass;         /* fgsr_pass_id */
    uint32_t tiles_total;  /* 0 when the pass does not classify tiles */
    uint32_t tiles_skipped;
    uint32_t reserved;
    uint64_t gpu_begin_ns; /* CLOCK_MONOTONIC (calibrated when FGSR_CAP_CALIBRATED_TIME) */
    uint64_t gpu_end_ns;
} fgsr_pass_record;
FGSR_STATIC_ASSERT(sizeof(fgsr_pass_record) == 32, "fgsr_pass_record size");

/* Per output frame. All times CLOCK_MONOTONIC ns. */
typedef struct fgsr_telemetry {
    uint32_t frame_type;     /* fgsr_frame_type */
    uint32_t pass_count;     /* valid entries of passes[] */
    float target_time;       /* alpha (interpolated), 1 + alpha (extrapolated), 1 (upscaled) */
    uint32_t skipped_passes; /* bit (1 << fgsr_pass_id) per pass skipped for this frame
                              * (fgsrd: the passes an output with a non-OK status did not run,
                              * and the passes that skipped every tile, e.g. splat of a still
                              * frame; per-tile shares are in passes[].tiles_*) */
    uint64_t target_present_ns; /* present time the frame stands for (0: unknown). fgsrd:
                                 * upscaled = present_time_ns; generated = previous present +
                                 * (present - previous present) * target_time when both known */
    uint64_t submit_ns;         /* copied from the submit entry */
    uint64_t dequeue_ns;        /* the daemon read the submit */
    uint64_t start_ns;          /* the daemon began this frame's work */
    uint64_t complete_ns;       /* the output was written and published */
    uint64_t queue_wait_ns;     /* start_ns - dequeue_ns */
    uint64_t gpu_ns;            /* sum of the passes' GPU time (fgsrd: passes[0] is the frame's
                                 * ingest pass, repeated in each output of the submit and counted
                                 * in each gpu_ns; ingest and SR run at submit) */
    uint64_t daemon_cpu_ns;     /* daemon thread CPU time spent on this output (fgsrd:
                                 * CLOCK_THREAD_CPUTIME_ID since the previous output of the same
                                 * submit was published; the first output carries ingest) */
    fgsr_pass_record passes[FGSR_MAX_PASSES];
} fgsr_telemetry;
FGSR_STATIC_ASSERT(sizeof(fgsr_telemetry) == 464, "fgsr_telemetry size");

/* Bits of fgsr_completion_entry.flags. */
#define FGSR_COMPLETION_INPUT_RELEASED 0x1u /* input_slot is the client's again */
#define FGSR_COMPLETION_LAST 0x2u           /* the last completion of this submit */

/* Daemon -> client: one output (or the fate of a submit that produced none). */
typedef struct fgsr_completion_entry {
    uint64_t sequence;    /* of the submit */
    int32_t status;       /* OK, BAD_FRAME, DROPPED, NOT_READY, DEVICE_ERROR, ... */
    uint32_t flags;       /* FGSR_COMPLETION_* */
    uint32_t input_slot;  /* the submit's slot (valid when INPUT_RELEASED) */
    uint32_t output_slot; /* FGSR_NO_SLOT when no output */
    uint32_t output_index; /* 0-based index of this output within the submit. Reading: outputs
                            * are numbered in presentation order: interp_alphas[0..interp_count),
                            * then the upscaled frame (FGSR_SUBMIT_WANT_SR), then
                            * extrap_alphas[0..extrap_count). A submit that requests no output
                            * still gets exactly one completion (status OK, FGSR_FRAME_NONE,
                            * output_slot FGSR_NO_SLOT, INPUT_RELEASED | LAST) so that its input
                            * slot comes back. INPUT_RELEASED is set on the LAST completion only. */
    uint32_t reserved0;
    uint64_t user_data;    /* from the submit */
    fgsr_telemetry telemetry;
    uint8_t reserved1[24];
} fgsr_completion_entry;
FGSR_STATIC_ASSERT(sizeof(fgsr_completion_entry) == 528, "fgsr_completion_entry size");

/* Client -> daemon: an output slot the client no longer reads. fgsrd: an index out of range or of
 * a slot the client does not hold is a protocol violation. */
typedef struct fgsr_release_entry {
    uint32_t output_slot;
    uint32_t reserved;
} fgsr_release_entry;
FGSR_STATIC_ASSERT(sizeof(fgsr_release_entry) == 8, "fgsr_release_entry size");

/* Layout of the rings memfd for a capacity of n entries per ring (n a power of two):
 *   [submit header][n submit entries][completion header][n completion entries]
 *   [release header][n release entries], each section starting on a cache line. */
typedef struct fgsr_rings_layout {
    uint64_t submit_header, submit_entries;
    uint64_t completion_header, completion_entries;
    uint64_t release_header, release_entries;
    uint64_t total_size;
} fgsr_rings_layout;

static inline uint64_t fgsr_align_up(uint64_t v, uint64_t a) { return (v + a - 1) / a * a; }

static inline fgsr_rings_layout fgsr_rings_layout_for(uint32_t capacity) {
    fgsr_rings_layout l;
    uint64_t o = 0;
    l.submit_header = o;
    o += sizeof(fgsr_ring_header);
    l.submit_entries = o;
    o = fgsr_align_up(o + (uint64_t)capacity * sizeof(fgsr_submit_entry), FGSR_CACHE_LINE);
    l.completion_header = o;
    o += sizeof(fgsr_ring_header);
    l.completion_entries = o;
    o = fgsr_align_up(o + (uint64_t)capacity * sizeof(fgsr_completion_entry), FGSR_CACHE_LINE);
    l.release_header = o;
    o += sizeof(fgsr_ring_header);
    l.release_entries = o;
    o = fgsr_align_up(o + (uint64_t)capacity * sizeof(fgsr_release_entry), FGSR_CACHE_LINE);
    l.total_size = fgsr_align_up(o, 4096);
    return l;
}

/* Ring access. `entries` points at the ring's first entry, `size` is the entry size. The
 * producer: fgsr_ring_free_space, write the entry at fgsr_ring_slot(head), then fgsr_ring_publish.
 * The consumer: fgsr_ring_available, copy the entry out, then fgsr_ring_consume. A consumer must
 * treat available > capacity as a protocol violation by the producer. */
static inline uint64_t fgsr_ring_load_head(const fgsr_ring_header* r) {
    return __atomic_load_n(&r->head, __ATOMIC_ACQUIRE);
}
static inline uint64_t fgsr_ring_load_tail(const fgsr_ring_header* r) {
    return __atomic_load_n(&r->tail, __ATOMIC_ACQUIRE);
}
static inline void fgsr_ring_publish(fgsr_ring_header* r, uint64_t new_head) {
    __atomic_store_n(&r->head, new_head, __ATOMIC_RELEASE);
}
static inline void fgsr_ring_consume(fgsr_ring_header* r, uint64_t new_tail) {
    __atomic_store_n(&r->tail, new_tail, __ATOMIC_RELEASE);
}
static inline uint64_t fgsr_ring_index(uint64_t position, uint32_t capacity) {
    return position & (uint64_t)(capacity - 1u);
}

#ifdef __cplusplus
}
#endif

#endif /* FGSR_PROTOCOL_H */
