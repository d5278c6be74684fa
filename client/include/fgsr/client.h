/*
 * libfgsr_client: hand rendered frames to fgsrd and get generated and upscaled frames back.
 *
 *   fgsr_connection* c;  fgsr_connect(NULL, &c);
 *   fgsr_session* s;     fgsr_session_create(c, &desc, &s);
 *   per frame:           fgsr_acquire_input(s, timeout, &slot); fill slot.color/.depth/.mv;
 *                        fgsr_submit(s, &info, &seq);
 *                        while (fgsr_wait(s, timeout, &out) == FGSR_STATUS_OK) {
 *                            use out.pixels; fgsr_release_output(s, out.output_slot); }
 *   fgsr_session_destroy(s); fgsr_disconnect(c);
 *
 * Threads: a connection and its sessions may be used from one thread at a time each; different
 * sessions may be used from different threads. No function throws or aborts; each returns a
 * status (fgsr/protocol.h; fgsr_status_string describes it).
 * Recording: with FGSR_CAPTURE=DIR in the environment at fgsr_session_create (or after
 * fgsr_session_record) every frame the session submits is also written to DIR in fgsr's
 * capture format (docs/CAPTURE_FORMAT.md), so the session can be replayed with `fgsr replay`.
 * Spinning: with FGSR_WAIT_SPIN_US=N (0 to 1000; default 0) at fgsr_session_create, fgsr_wait and
 * fgsr_acquire_input with a timeout first watch the completion ring for up to N microseconds (a
 * busy loop with pause instructions and sched_yield) before they sleep: lower latency when a
 * completion comes within N, N microseconds of CPU time per wait when it does not.
 */
#ifndef FGSR_CLIENT_H
#define FGSR_CLIENT_H

#include <fgsr/protocol.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fgsr_connection fgsr_connection;
typedef struct fgsr_session fgsr_session;

typedef struct fgsr_connect_info {
    uint32_t struct_size;    /* sizeof(fgsr_connect_info) */
    uint32_t timeout_ms;     /* handshake timeout; 0: 5000 */
    const char* socket_path; /* NULL: $FGSR_SOCKET, else $XDG_RUNTIME_DIR/fgsr/fgsrd.sock */
    const char* client_name; /* for the daemon's logs; NULL: the program name */
} fgsr_connect_info;

typedef struct fgsr_daemon_info {
    uint16_t major, minor;  /* the daemon's protocol version */
    uint32_t capabilities;  /* FGSR_CAP_* */
    uint64_t epoch;         /* changes when the daemon restarts */
    char device[64];        /* Vulkan device name */
} fgsr_daemon_info;

/* Connects and shakes hands. info may be NULL (all defaults).
 * Returns OK; DAEMON_UNAVAILABLE (no socket or nobody listening); VERSION_MISMATCH (another major
 * version: the daemon's is in the log); PERMISSION_DENIED; TIMEOUT; DISCONNECTED; PROTOCOL_ERROR;
 * OUT_OF_MEMORY; INVALID_ARGUMENT (out is NULL). */
fgsr_status fgsr_connect(const fgsr_connect_info* info, fgsr_connection** out);

/* Closes the connection. Sessions of the connection must be destroyed first. NULL is fine. */
void fgsr_disconnect(fgsr_connection* connection);

/* The daemon's version, capabilities, epoch and device. Returns OK or INVALID_ARGUMENT. */
fgsr_status fgsr_daemon_info_get(const fgsr_connection* connection, fgsr_daemon_info* out);

/* Creates a session; maps its slot pools and rings.
 * Returns OK; INVALID_ARGUMENT (sizes, formats, slot counts, scale out of range); UNSUPPORTED;
 * OUT_OF_MEMORY; BUSY; DISCONNECTED; PROTOCOL_ERROR (the reply or its fds do not match). */
fgsr_status fgsr_session_create(fgsr_connection* connection, const fgsr_session_desc* desc,
                                fgsr_session** out);

/* Tears the session down (the daemon frees everything). Outputs still held become invalid. */
void fgsr_session_destroy(fgsr_session* session);

/* The negotiated layout (slot counts, plane offsets and pitches, output size). */
fgsr_status fgsr_session_layout(const fgsr_session* session, fgsr_pool_layout* out);

/* The eventfd that becomes readable when completions arrive, for poll/epoll loops. The session
 * owns it; do not close it. Returns -1 for a NULL session. */
int fgsr_session_event_fd(const fgsr_session* session);

typedef struct fgsr_input_slot {
    uint32_t index;
    uint32_t reserved;
    void* color; /* layout.color.size bytes, rows layout.color.row_pitch apart */
    void* depth; /* 32-bit float per pixel; NULL in a FGSR_SESSION_NO_DEPTH session */
    void* mv;    /* layout.mv.format per pixel; NULL in a FGSR_SESSION_NO_MVS session */
} fgsr_input_slot;

/* Takes a free input slot, waiting up to timeout_ms for the daemon to hand one back (0: do not
 * wait). Returns OK; NO_SLOT (none free within the timeout); DISCONNECTED (also with timeout 0:
 * every call checks whether the daemon hung up); INVALID_ARGUMENT. */
fgsr_status fgsr_acquire_input(fgsr_session* session, uint32_t timeout_ms, fgsr_input_slot* out);

typedef struct fgsr_submit_info {
    uint32_t struct_size; /* sizeof(fgsr_submit_info) */
    uint32_t input_slot;  /* from fgsr_acquire_input */
    uint32_t flags;       /* FGSR_SUBMIT_* */
    float jitter_x, jitter_y;
    uint32_t interp_count; /* <= FGSR_MAX_ALPHAS */
    const float* interp_alphas;
    uint32_t extrap_count; /* <= FGSR_MAX_ALPHAS */
    const float* extrap_alphas;
    uint64_t present_time_ns; /* 0: unknown */
    uint64_t user_data;
} fgsr_submit_info;

/* Hands the slot's frame to the daemon. The slot belongs to the daemon until a completion
 * releases it. out_sequence (may be NULL) receives the submit's sequence number.
 * Returns OK; INVALID_ARGUMENT (slot not acquired, counts or alphas out of range, modes the
 * session did not declare); NO_SLOT (submit ring full); DISCONNECTED. */
fgsr_status fgsr_submit(fgsr_session* session, const fgsr_submit_info* info, uint64_t* out_sequence);

typedef struct fgsr_output {
    uint64_t sequence; /* of the submit */
    int32_t status;    /* the fate of this output: OK, BAD_FRAME, DROPPED, NOT_READY, ... */
    uint32_t output_slot; /* FGSR_NO_SLOT when there is no image */
    uint32_t output_index;
    uint32_t width, height, row_pitch, format; /* of pixels */
    uint32_t reserved;
    const void* pixels; /* read-only; valid until fgsr_release_output(output_slot) */
    uint64_t user_data;
    fgsr_telemetry telemetry;
    uint32_t flags; /* FGSR_COMPLETION_* of the entry: LAST marks the submit's last completion (added
                     * by the client engineer so that callers can tell when a submit is finished) */
    uint32_t reserved2;
} fgsr_output;

/* The next completion, waiting up to timeout_ms (0: poll). Returns OK (out filled; look at
 * out->status for the frame's fate); TIMEOUT (nothing arrived); DISCONNECTED; PROTOCOL_ERROR
 * (the daemon wrote a malformed completion); INVALID_ARGUMENT. */
fgsr_status fgsr_wait(fgsr_session* session, uint32_t timeout_ms, fgsr_output* out);

/* Gives an output slot back to the daemon. Returns OK; INVALID_ARGUMENT (not held); DISCONNECTED. */
fgsr_status fgsr_release_output(fgsr_session* session, uint32_t output_slot);

/* Aggregates the daemon keeps for this session. Returns OK; DISCONNECTED; TIMEOUT. */
fgsr_status fgsr_session_stats_get(fgsr_session* session, fgsr_session_stats* out);

/* Tells the daemon what became of frames: presented when, or dropped (fgsr_present_report). The
 * reports are buffered and sent without waiting (at most 50 ms late; at session destroy at the
 * latest); a full socket drops them rather than block. Returns OK; INVALID_ARGUMENT (NULL with a
 * count, or a frame_type out of range); UNSUPPORTED (the daemon predates protocol minor 3: the
 * reports are dropped); DISCONNECTED. */
fgsr_status fgsr_report_presents(fgsr_session* session, const fgsr_present_report* reports, uint32_t count);

/* Sends click-to-photon samples of a hardware probe to the daemon (its dashboard, /metrics and
 * /trace.json show them), without a session. Sent at once, without waiting for a reply; a full
 * socket drops them. Returns OK; INVALID_ARGUMENT (NULL with a count, photon before click, a mode
 * out of range); UNSUPPORTED (the daemon predates protocol minor 3); DISCONNECTED. */
fgsr_status fgsr_report_probe_samples(fgsr_connection* connection, const fgsr_probe_sample* samples,
                                      uint32_t count);

/* Starts (or stops, with dir NULL) recording every submitted frame to dir as an fgsr capture.
 * Returns OK; INVALID_ARGUMENT; UNSUPPORTED (cannot create dir or write there). */
fgsr_status fgsr_session_record(fgsr_session* session, const char* dir);

#ifdef __cplusplus
}
#endif

#endif /* FGSR_CLIENT_H */
