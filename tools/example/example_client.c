/*
 * fgsr_example_client: the smallest useful client of fgsrd, in C.
 *
 * Connects (socket: argv[1], else $FGSR_SOCKET, else $XDG_RUNTIME_DIR/fgsr/fgsrd.sock), creates a
 * 64x36 interpolation session, submits four synthetic frames (a bright square moving 2 pixels to
 * the right per frame over a dark background, vectors to the previous frame), asks for the frame
 * halfway between each pair, and prints each completion's telemetry and the session's stats.
 *
 * Build: cc example_client.c $(pkg-config --cflags --libs fgsr-client)
 */
#include <fgsr/client.h>

#include <stdio.h>
#include <string.h>

enum { W = 64, H = 36, FRAMES = 4, SQUARE = 8 };

/* rgba32f colour, linear depth, rg32f vectors in pixels pointing to the previous position. */
static void render(const fgsr_input_slot* in, const fgsr_pool_layout* l, int frame) {
    const int x0 = 8 + 2 * frame, y0 = 14;
    for (int y = 0; y < H; ++y) {
        float* c = (float*)((char*)in->color + (size_t)y * l->color.row_pitch);
        float* d = (float*)((char*)in->depth + (size_t)y * l->depth.row_pitch);
        float* m = (float*)((char*)in->mv + (size_t)y * l->mv.row_pitch);
        for (int x = 0; x < W; ++x) {
            const int in_square = x >= x0 && x < x0 + SQUARE && y >= y0 && y < y0 + SQUARE;
            const float v = in_square ? 0.9f : 0.1f + 0.004f * (float)x;
            c[4 * x + 0] = v;
            c[4 * x + 1] = v;
            c[4 * x + 2] = in_square ? 0.2f : v;
            c[4 * x + 3] = 1.f;
            d[x] = in_square ? 5.f : 50.f;
            m[2 * x + 0] = in_square ? -2.f : 0.f; /* the square came from 2 pixels to the left */
            m[2 * x + 1] = 0.f;
        }
    }
}

static int check(fgsr_status s, const char* what) {
    if (s == FGSR_STATUS_OK) return 0;
    fprintf(stderr, "example_client: %s: %s\n", what, fgsr_status_string(s));
    return 1;
}

int main(int argc, char** argv) {
    fgsr_connect_info ci;
    memset(&ci, 0, sizeof(ci));
    ci.struct_size = sizeof(ci);
    ci.socket_path = argc > 1 ? argv[1] : NULL;
    ci.client_name = "example_client";
    fgsr_connection* conn = NULL;
    if (check(fgsr_connect(&ci, &conn), "connect")) return 1;
    fgsr_daemon_info info;
    fgsr_daemon_info_get(conn, &info);
    printf("fgsrd protocol %u.%u on %s\n", info.major, info.minor, info.device);

    fgsr_session_desc desc;
    memset(&desc, 0, sizeof(desc));
    desc.struct_size = sizeof(desc);
    desc.width = W;
    desc.height = H;
    desc.color_format = FGSR_COLOR_RGBA32F_LINEAR;
    desc.mv_format = FGSR_MV_RG32F;
    desc.depth_kind = FGSR_DEPTH_LINEAR;
    desc.mv_units = FGSR_MV_PIXELS;
    desc.mv_direction = FGSR_MV_TO_PREVIOUS;
    desc.scale = 1.f;
    desc.modes = FGSR_MODE_INTERPOLATE;
    desc.queue_policy = FGSR_QUEUE_FIFO;
    desc.output_format = FGSR_COLOR_RGBA32F_LINEAR;
    fgsr_session* session = NULL;
    if (check(fgsr_session_create(conn, &desc, &session), "create session")) {
        fgsr_disconnect(conn);
        return 1;
    }
    fgsr_pool_layout layout;
    fgsr_session_layout(session, &layout);

    int failed = 0;
    const float half = 0.5f;
    for (int f = 0; f < FRAMES && !failed; ++f) {
        fgsr_input_slot in;
        if ((failed = check(fgsr_acquire_input(session, 5000, &in), "acquire input"))) break;
        render(&in, &layout, f);
        fgsr_submit_info si;
        memset(&si, 0, sizeof(si));
        si.struct_size = sizeof(si);
        si.input_slot = in.index;
        si.flags = f > 0 ? FGSR_SUBMIT_HAS_MV : 0; /* the first frame's vectors are unknown */
        si.interp_count = f > 0 ? 1 : 0;           /* nothing to interpolate before frame 1 */
        si.interp_alphas = &half;
        uint64_t seq = 0;
        if ((failed = check(fgsr_submit(session, &si, &seq), "submit"))) break;
        /* Every submit ends with a completion flagged LAST (it also returns the input slot). */
        for (;;) {
            fgsr_output out;
            if ((failed = check(fgsr_wait(session, 30000, &out), "wait"))) break;
            const fgsr_telemetry* t = &out.telemetry;
            if (out.output_slot != FGSR_NO_SLOT) {
                /* The square's centre pixel halfway between frames f-1 and f. */
                const int cx = 8 + 2 * f - 1 + SQUARE / 2, cy = 14 + SQUARE / 2;
                const float* px = (const float*)((const char*)out.pixels + (size_t)cy * out.row_pitch) + 4 * cx;
                printf("frame %llu: %s at t=%.2f, status %s, GPU %.3f ms, queue %.3f ms, latency %.3f ms, "
                       "daemon CPU %.3f ms, centre pixel %.2f %.2f %.2f\n",
                       (unsigned long long)out.sequence,
                       t->frame_type == FGSR_FRAME_INTERPOLATED ? "interpolated" : "other",
                       (double)t->target_time, fgsr_status_string(out.status), (double)t->gpu_ns * 1e-6,
                       (double)t->queue_wait_ns * 1e-6, (double)(t->complete_ns - t->submit_ns) * 1e-6,
                       (double)t->daemon_cpu_ns * 1e-6, (double)px[0], (double)px[1], (double)px[2]);
                fgsr_release_output(session, out.output_slot);
            } else if (out.status != FGSR_STATUS_OK) {
                printf("frame %llu: %s\n", (unsigned long long)out.sequence, fgsr_status_string(out.status));
            }
            if (out.flags & FGSR_COMPLETION_LAST) break;
        }
    }
    fgsr_session_stats stats;
    if (!failed && fgsr_session_stats_get(session, &stats) == FGSR_STATUS_OK)
        printf("session: %llu frames submitted, %llu outputs, %llu dropped, latency p50 %.3f ms, p99 %.3f ms\n",
               (unsigned long long)stats.frames_submitted, (unsigned long long)stats.outputs_written,
               (unsigned long long)stats.frames_dropped, (double)stats.latency_p50_ns * 1e-6,
               (double)stats.latency_p99_ns * 1e-6);
    fgsr_session_destroy(session);
    fgsr_disconnect(conn);
    return failed;
}
