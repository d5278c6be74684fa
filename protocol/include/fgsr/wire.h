/*
 * fgsr wire format: what libfgsr_client and fgsrd exchange on the control socket and in shared
 * memory. Private to those two (not installed; the public contract is fgsr/protocol.h, which this
 * header extends). Plain C11; also valid C++. How fgsrd reacts to violations of it:
 * daemon/fgsrd/README.md.
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
 *   The client checks the CREATE_SESSION reply: the layout equals fgsr_pool_layout_for of its own
 *   normalised description (reserved aside); fstat: the three memfds are regular files at least
 *   as large as their pool / rings size; F_GET_SEALS of both pools includes F_SEAL_SHRINK |
 *   F_SEAL_GROW, and of the output pool also F_SEAL_FUTURE_WRITE (or F_SEAL_WRITE); fds 3 and 4
 *   are eventfds. A reply that fails any check: the client closes every fd, tells the daemon to
 *   destroy the session and returns PROTOCOL_ERROR from fgsr_session_create.
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
 */
#ifndef FGSR_WIRE_H
#define FGSR_WIRE_H

#include <fgsr/protocol.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FGSR_PROTOCOL_MAGIC 0x52534746u /* "FGSR" little-endian */
#define FGSR_CACHE_LINE 64u
#define FGSR_MAX_MESSAGE_SIZE 1024u /* largest control message, header included */

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
    FGSR_MSG_ERROR = 9,                 /* daemon -> client: fgsr_reply, then the daemon may close */
    FGSR_MSG_REPORT = 10,               /* client -> daemon: fgsr_report (minor 3); no reply */
    FGSR_MSG_PROBE = 11                 /* client -> daemon: fgsr_probe (minor 3); no reply */
} fgsr_msg_type;

typedef struct fgsr_msg_header {
    uint32_t magic; /* FGSR_PROTOCOL_MAGIC */
    uint16_t type;  /* fgsr_msg_type */
    uint16_t reserved;
    uint32_t size;     /* bytes of the whole message, header included */
    uint32_t sequence; /* request counter chosen by the client; replies echo it */
} fgsr_msg_header;
FGSR_STATIC_ASSERT(sizeof(fgsr_msg_header) == 16, "fgsr_msg_header size");

/* A header for a message of `type` and `size` bytes (header included) with `sequence`. */
static inline fgsr_msg_header fgsr_msg_header_for(uint16_t type, uint32_t size, uint32_t sequence) {
    fgsr_msg_header h;
    h.magic = FGSR_PROTOCOL_MAGIC;
    h.type = type;
    h.reserved = 0;
    h.size = size;
    h.sequence = sequence;
    return h;
}

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
    uint64_t epoch;  /* identifies this daemon instance (changes on every start) */
    char device[64]; /* Vulkan device name, NUL-terminated */
} fgsr_hello_reply;
FGSR_STATIC_ASSERT(sizeof(fgsr_hello_reply) == 104, "fgsr_hello_reply size");

typedef struct fgsr_create_session {
    fgsr_msg_header header;
    fgsr_session_desc desc;
} fgsr_create_session;
FGSR_STATIC_ASSERT(sizeof(fgsr_create_session) == 144, "fgsr_create_session size");

/* Present reports (minor 3): the one request without a reply, so that a client can send them from
 * its present path without waiting. The packet holds the header, session_id, count and `count`
 * reports (it may be shorter than the struct). Sent only to a daemon that said minor >= 3; fgsrd
 * ignores reports of sessions the connection does not own, and counts reports whose values are out
 * of range (daemon/fgsrd/README.md). */
#define FGSR_MAX_REPORTS_PER_MESSAGE 16u
typedef struct fgsr_report {
    fgsr_msg_header header;
    uint32_t session_id;
    uint32_t count; /* 1..FGSR_MAX_REPORTS_PER_MESSAGE */
    fgsr_present_report reports[FGSR_MAX_REPORTS_PER_MESSAGE];
} fgsr_report;
FGSR_STATIC_ASSERT(sizeof(fgsr_report) == 920, "fgsr_report size");
#define FGSR_REPORT_MESSAGE_SIZE(count) (24u + 56u * (count))

/* Click-to-photon samples of a hardware probe (minor 3; `fgsr probe`), not tied to a session; no
 * reply. The packet holds the header, count, reserved and `count` samples. */
#define FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE 32u
typedef struct fgsr_probe {
    fgsr_msg_header header;
    uint32_t count; /* 1..FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE */
    uint32_t reserved;
    fgsr_probe_sample samples[FGSR_MAX_PROBE_SAMPLES_PER_MESSAGE];
} fgsr_probe;
FGSR_STATIC_ASSERT(sizeof(fgsr_probe) == 792, "fgsr_probe size");
#define FGSR_PROBE_MESSAGE_SIZE(count) (24u + 24u * (count))

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

/* Client -> daemon: one rendered frame and the outputs wanted from it. */
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
    uint64_t submit_time_ns;              /* CLOCK_MONOTONIC when the client pushed the entry */
    uint64_t present_time_ns;             /* when this frame is meant to be shown (0: unknown) */
    uint64_t user_data;                   /* echoed in the completions */
    uint64_t reserved;
} fgsr_submit_entry;
FGSR_STATIC_ASSERT(sizeof(fgsr_submit_entry) == 128, "fgsr_submit_entry size");

/* Daemon -> client: one output (or the fate of a submit that produced none). */
typedef struct fgsr_completion_entry {
    uint64_t sequence;     /* of the submit */
    int32_t status;        /* OK, BAD_FRAME, DROPPED, NOT_READY, DEVICE_ERROR, ... */
    uint32_t flags;        /* FGSR_COMPLETION_* */
    uint32_t input_slot;   /* the submit's slot (valid when INPUT_RELEASED) */
    uint32_t output_slot;  /* FGSR_NO_SLOT when no output */
    uint32_t output_index; /* 0-based index of this output within the submit. Reading: outputs
                            * are numbered in presentation order: interp_alphas[0..interp_count),
                            * then the upscaled frame (FGSR_SUBMIT_WANT_SR), then
                            * extrap_alphas[0..extrap_count). A submit that requests no output
                            * still gets exactly one completion (status OK, FGSR_FRAME_NONE,
                            * output_slot FGSR_NO_SLOT, INPUT_RELEASED | LAST) so that its input
                            * slot comes back. INPUT_RELEASED is set on the LAST completion only. */
    uint32_t reserved0;
    uint64_t user_data; /* from the submit */
    fgsr_telemetry telemetry;
    uint8_t reserved1[24];
} fgsr_completion_entry;
FGSR_STATIC_ASSERT(sizeof(fgsr_completion_entry) == 528, "fgsr_completion_entry size");

/* Client -> daemon: an output slot the client no longer reads. */
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

static inline uint64_t fgsr_align_up(uint64_t v, uint64_t a) {
    return (v + a - 1) / a * a;
}

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

/* Ring access. Each side keeps a private copy of the position it writes (the producer its head,
 * the consumer its tail) and never reads it back from shared memory. `entries` points at the
 * ring's first entry, `size` is the entry size. The producer: fgsr_ring_free_space, write the
 * entry at fgsr_ring_slot(head), then fgsr_ring_publish(head + 1). The consumer:
 * fgsr_ring_available, copy the entry at fgsr_ring_slot(tail) out, then fgsr_ring_consume(tail + 1).
 * A consumer must treat available > capacity as a protocol violation by the producer, a producer
 * a negative free space as one by the consumer. (C++: fgsr/ipc/ring.hpp wraps both loops.) */
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
/* Entries the producer has published beyond the consumer's private `tail` (more than the
 * capacity: the producer misbehaves). */
static inline uint64_t fgsr_ring_available(const fgsr_ring_header* r, uint64_t tail) {
    return fgsr_ring_load_head(r) - tail;
}
/* Entries the producer may still push beyond its private `head`; negative when the consumer's
 * tail is beyond the head or more than the capacity behind it (the consumer misbehaves). */
static inline int64_t fgsr_ring_free_space(const fgsr_ring_header* r, uint64_t head, uint32_t capacity) {
    const uint64_t used = head - fgsr_ring_load_tail(r);
    return used > capacity ? -1 : (int64_t)(capacity - used);
}
/* The entry at `position` of a ring of `capacity` entries of `size` bytes starting at `entries`. */
static inline void* fgsr_ring_slot(const void* entries, uint64_t size, uint64_t position, uint32_t capacity) {
    return (void*)((const unsigned char*)entries + fgsr_ring_index(position, capacity) * size);
}

/* ---------------------------------------------------------------------------------------------
 * Session description and pool layout: the one definition both sides use (protocol/src/session.c).
 * Not exported from libfgsr_client (hidden visibility).
 * ------------------------------------------------------------------------------------------- */
#define FGSR_DEFAULT_INPUT_SLOTS 3u
#define FGSR_DEFAULT_OUTPUT_SLOTS 4u
#define FGSR_DEFAULT_RING_CAPACITY 64u
#define FGSR_MAX_RING_CAPACITY 4096u
#define FGSR_MAX_POOL_SIZE (2ull << 30) /* bytes per slot pool and session */

#if defined(__GNUC__)
#define FGSR_WIRE_INTERNAL __attribute__((visibility("hidden")))
#else
#define FGSR_WIRE_INTERNAL
#endif

/* Bytes per pixel of a fgsr_color_format / fgsr_mv_format value (0 for an unknown value). */
FGSR_WIRE_INTERNAL uint32_t fgsr_color_format_bytes(uint32_t format);
FGSR_WIRE_INTERNAL uint32_t fgsr_mv_format_bytes(uint32_t format);

/* Copies `in` into `out` with defaults applied (input_slots 3, output_slots 4, ring_capacity 64,
 * struct_size = sizeof(fgsr_session_desc)) and checks every rule of fgsr_session_desc: struct_size
 * at least 128; size 1..FGSR_MAX_FRAME_SIDE; known formats, depth kind, vector units and
 * direction, queue policy, session flags; scale one of 1, 1.5, 2, 3, 4; a nonzero set of known
 * modes, FGSR_MODE_SR only with scale > 1; slot counts at most FGSR_MAX_SLOTS; ring_capacity a
 * power of two in max(slots)..FGSR_MAX_RING_CAPACITY; near_plane finite, far_plane not NaN;
 * t_depth, t_bright, sr_a, sr_b finite and >= 0; reserved zero; each slot pool at most
 * FGSR_MAX_POOL_SIZE. Returns FGSR_STATUS_OK, or FGSR_STATUS_INVALID_ARGUMENT with a
 * NUL-terminated reason in `reason` (when reason_size > 0; `out` is then unspecified). */
FGSR_WIRE_INTERNAL fgsr_status fgsr_session_desc_normalize(const fgsr_session_desc* in,
                                                           fgsr_session_desc* out, char* reason,
                                                           size_t reason_size);

/* The pool layout of a description fgsr_session_desc_normalize accepted: planes packed in the
 * order colour, depth, vectors, each on FGSR_PLANE_ALIGNMENT with tight rows; one output plane at
 * offset 0; strides rounded up to FGSR_PLANE_ALIGNMENT; rings_size from fgsr_rings_layout_for.
 * reserved is 0. */
FGSR_WIRE_INTERNAL fgsr_pool_layout fgsr_pool_layout_for(const fgsr_session_desc* normalized);

#ifdef __cplusplus
}
#endif

#endif /* FGSR_WIRE_H */
