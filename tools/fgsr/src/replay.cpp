// `fgsr replay` and `fgsr eval --socket`: a capture streamed through fgsrd with libfgsr_client.
//
// The frames submitted and the outputs requested are those of in-process `fgsr eval` for the
// "fgsr" method (same capture preparation, same halfway_targets, same alphas), so with rgba32f
// outputs the scores are computed on bit-identical images by the same score_image/finish_means.
//
// Presents (replay_presents.hpp): replay has no display; it "presents" each frame as soon as it
// holds it, in display order (per submit: interpolated outputs, the application's own frame, or
// in sr mode the upscaled output in its place, then extrapolated outputs). Every present is
// reported to fgsrd (fgsr_report_presents; a daemon before protocol minor 3 gets none) and, with
// --telemetry, written as one row of PresentMon's columns (fgsr/core/presentmon.hpp); failed
// outputs and dropped submits get a row with their fgsr_status and MsUntilDisplayed NA.
#include <fgsr/cli/replay.hpp>

#include "replay_presents.hpp"

#include <fgsr/cli/capture_spec.hpp>

#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/session_desc.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/client.hpp>
#include <fgsr/core/clock.hpp>
#include <fgsr/stress/client_planes.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <thread>
#include <time.h>
#include <vector>

namespace fgsr::cli {

namespace {

constexpr uint32_t kWaitMs = 60000; // generous: lavapipe at 1080p

Error client_error(fgsr_status s, const std::string& what) {
    const Errc c = s == FGSR_STATUS_INVALID_ARGUMENT ? Errc::invalid_argument
                   : s == FGSR_STATUS_UNSUPPORTED    ? Errc::unsupported
                                                     : Errc::io;
    return make_error(c, what + ": " + fgsr_status_string(s));
}

double percentile_ms(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t i = std::min(v.size() - 1, size_t(std::ceil(q * double(v.size()))) - (q > 0 ? 1 : 0));
    return v[i];
}

// What one submit asks for and how its output is scored.
struct Plan {
    bool want_sr = false;
    std::vector<float> interp, extrap;
    const ImageRGBA* reference = nullptr; // scored against this when set
    size_t target = 0;                    // ground-truth index (file stem k + 1, as eval)
};

Result<capture::Capture> load_capture(const ReplayOptions& o) {
    return load_capture_spec(o.capture, o.prefer_lr);
}

using stress::copy_plane;

uint64_t thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

struct Stream {
    fgsr::client::Connection conn;
    fgsr::client::Session session;
    fgsr_pool_layout layout{};
    FILE* csv = nullptr;
    std::vector<double> latency_ms, overhead_ms, wake_us, handoff_us, return_us;
    ReplaySummary summary;
    ~Stream() {
        if (csv) std::fclose(csv);
    }
};

fgsr_session_desc make_desc(const FrameFormat& f, const ReplayOptions& o, float scale, uint32_t modes) {
    Params p = o.params;
    p.scale = scale;
    fgsr_session_desc d = capture::session_desc(f, p, modes);
    d.queue_policy = o.mailbox ? FGSR_QUEUE_MAILBOX : FGSR_QUEUE_FIFO;
    return d;
}

} // namespace

Result<ReplaySummary> run_replay(const ReplayOptions& o) {
    const bool extrap = o.mode == EvalMode::extrap || o.mode == EvalMode::esr;
    const bool joint = o.mode == EvalMode::isr || o.mode == EvalMode::esr;
    FGSR_TRY(check_alpha(o.alpha, extrap));
    if (o.progress) std::fprintf(stderr, "[replay] loading %s\n", o.capture.c_str());
    auto loaded = load_capture(o);
    if (!loaded) return loaded.error();
    capture::Capture cap = std::move(*loaded);
    // The same preparation as eval: consecutive frames are evaluated at half rate.
    if (o.mode != EvalMode::sr)
        FGSR_TRY(evaluate_at_half_rate(
            cap, o.progress, "[replay] consecutive frames: replaying at half rate with composed vectors"));

    // Plans per input, as eval requests them.
    const size_t n = cap.inputs.size();
    std::vector<Plan> plans(n);
    float scale = 1.f;
    uint32_t modes = 0;
    size_t last_input = n - 1;
    size_t scored = 0;
    if (o.mode == EvalMode::sr) {
        if (cap.hr_reference.empty())
            return make_error(Errc::empty_input,
                              "capture '" + cap.name + "' has no high-resolution reference (sr)");
        scale = float(cap.hr_reference[0].width) / float(cap.format.width);
        modes = FGSR_MODE_SR;
        size_t frames = n;
        if (o.max_frames > 0) frames = std::min(frames, size_t(o.max_frames));
        last_input = frames - 1;
        for (size_t k = 0; k < frames; ++k) {
            plans[k].want_sr = true;
            if (k < cap.hr_reference.size()) {
                plans[k].reference = &cap.hr_reference[k];
                plans[k].target = k;
                ++scored;
            }
        }
    } else {
        const std::vector<ImageRGBA>& refs = joint ? cap.hr_ground_truth : cap.ground_truth;
        if (joint) {
            if (cap.hr_ground_truth.empty())
                return make_error(Errc::empty_input, "capture '" + cap.name +
                                                         "' has no high-resolution reference "
                                                         "between inputs (isr/esr)");
            scale = float(cap.hr_ground_truth[0].width) / float(cap.format.width);
        }
        if (std::abs(o.alpha - 0.5f) > 1e-6f && !refs.empty())
            return make_error(Errc::invalid_argument,
                              "references exist only halfway between inputs; use --alpha 0.5");
        // Without references (e.g. a recorded session) every pair gets its frame, unscored.
        std::vector<size_t> targets =
            halfway_targets(cap.inputs, refs.empty() ? n : refs.size(), extrap, o.max_frames);
        if (targets.empty())
            return make_error(Errc::empty_input, "capture '" + cap.name + "' has too few frames");
        modes = extrap ? FGSR_MODE_EXTRAPOLATE : FGSR_MODE_INTERPOLATE;
        for (size_t k : targets) {
            Plan& p = plans[extrap ? k : k + 1];
            (extrap ? p.extrap : p.interp).push_back(o.alpha);
            p.target = k;
            if (k < refs.size()) {
                p.reference = &refs[k];
                ++scored;
            }
        }
        last_input = targets.back() + (extrap ? 0 : 1);
    }

    Stream st;
    st.summary.capture = cap.name;
    st.summary.mode = o.mode == EvalMode::interp   ? "interp"
                      : o.mode == EvalMode::extrap ? "extrap"
                      : o.mode == EvalMode::sr     ? "sr"
                      : o.mode == EvalMode::isr    ? "isr"
                                                   : "esr";
    fgsr_status s = st.conn.connect(o.socket.empty() ? nullptr : o.socket.c_str(), "fgsr-replay");
    if (s != FGSR_STATUS_OK)
        return client_error(s, "cannot connect to fgsrd" +
                                   (o.socket.empty() ? std::string() : " at " + o.socket));
    fgsr_daemon_info info{};
    (void)st.conn.daemon_info(info);
    st.summary.device = info.device;
    const fgsr_session_desc desc = make_desc(cap.format, o, scale, modes);
    s = st.session.create(st.conn, desc);
    if (s != FGSR_STATUS_OK) return client_error(s, "cannot create a session");
    (void)st.session.layout(st.layout);

    EvalReport rep = new_report(cap, st.summary.mode, o.mode == EvalMode::sr ? 0.f : o.alpha, scored,
                                st.layout.output_width, st.layout.output_height, {"fgsr"});
    rep.device = info.device;
    MethodScore& score = rep.methods["fgsr"];

    if (o.out) {
        std::error_code ec;
        std::filesystem::create_directories(*o.out / "fgsr", ec);
        if (o.mode == EvalMode::interp || o.mode == EvalMode::extrap)
            std::filesystem::create_directories(*o.out / "reference", ec);
        if (ec) return make_error(Errc::io, "cannot create " + o.out->string() + ": " + ec.message());
    }
    if (o.telemetry) {
        st.csv = std::fopen(o.telemetry->c_str(), "w");
        if (!st.csv) return make_error(Errc::io, "cannot write " + o.telemetry->string());
    }
    ReplayPresenter presenter(st.session, st.csv);
    // Waits, with the client thread's CPU time in them counted (the cost of FGSR_WAIT_SPIN_US).
    auto wait = [&](uint32_t ms, fgsr_output& out) {
        const uint64_t c0 = thread_cpu_ns();
        const fgsr_status ws = st.session.wait(ms, out);
        st.summary.client_wait_cpu_ns += thread_cpu_ns() - c0;
        return ws;
    };

    // Completions are matched to plans by sequence (sequence = input index + 1).
    size_t finished = 0; // submits whose LAST completion arrived
    auto handle = [&](const fgsr_output& out) -> Result<void> {
        const uint64_t seen = monotonic_ns();
        if (out.flags & FGSR_COMPLETION_LAST) ++finished;
        if (out.status == FGSR_STATUS_DROPPED)
            ++st.summary.dropped;
        else if (out.status != FGSR_STATUS_OK)
            ++st.summary.rejected;
        const fgsr_telemetry& t = out.telemetry;
        const double client_ms = double(seen - t.submit_ns) * 1e-6;
        if (out.output_slot != FGSR_NO_SLOT) {
            ++st.summary.outputs;
            st.latency_ms.push_back(client_ms);
            st.overhead_ms.push_back(client_ms - double(t.complete_ns - t.start_ns) * 1e-6);
            // The steps of the overhead (each clamped at 0: the daemon's stamps are another process's).
            const auto us = [](uint64_t from, uint64_t to) {
                return to > from ? double(to - from) * 1e-3 : 0.0;
            };
            st.wake_us.push_back(us(t.submit_ns, t.dequeue_ns));
            st.handoff_us.push_back(us(t.dequeue_ns, t.start_ns));
            st.return_us.push_back(us(t.complete_ns, seen));
        }
        presenter.completed(out, seen);
        FGSR_TRY(presenter.flush());
        if (out.output_slot == FGSR_NO_SLOT) return {};
        ImageRGBA img = stress::output_image(out);
        st.summary.client_bytes_copied += img.rgba.size() * sizeof(float);
        (void)st.session.release_output(out.output_slot);
        if (out.sequence == 0 || out.sequence > n)
            return make_error(Errc::io, "completion of an unknown frame");
        const Plan& p = plans[out.sequence - 1];
        if (o.out) {
            const std::string stem = fmt::format("{:04d}", p.target + 1);
            FGSR_TRY(capture::write_png(*o.out / "fgsr" / (stem + ".png"), img));
            if (o.mode == EvalMode::interp || o.mode == EvalMode::extrap) {
                FGSR_TRY(capture::write_exr(*o.out / "fgsr" / (stem + ".exr"), img));
                if (p.reference)
                    FGSR_TRY(capture::write_png(*o.out / "reference" / (stem + ".png"), *p.reference));
            }
        }
        if (!p.reference) return {};
        FGSR_TRY(score_image(score, img, *p.reference));
        GeneratedFrame gf;
        gf.gpu_ms = double(t.gpu_ns) * 1e-6;
        for (uint32_t i = 0; i < t.pass_count && i < FGSR_MAX_PASSES; ++i)
            if (t.passes[i].pass != FGSR_PASS_INGEST)
                gf.passes.push_back({fgsr_pass_name(t.passes[i].pass),
                                     double(t.passes[i].gpu_end_ns - t.passes[i].gpu_begin_ns) * 1e-6});
        add_timing(score, gf);
        return {};
    };

    const uint64_t t0 = monotonic_ns();
    const FrameFormat& f = cap.format;
    const size_t cb = size_t(f.width) * (f.color_format == ColorFormat::rgba8_srgb       ? 4
                                         : f.color_format == ColorFormat::rgba16f_linear ? 8
                                                                                         : 16);
    const size_t mb = size_t(f.width) * (f.mv_format == MvFormat::rg16f ? 4 : 8);
    for (size_t i = 0; i <= last_input; ++i) {
        if (o.fps > 0) {
            const uint64_t due = t0 + uint64_t(double(i) * 1e9 / o.fps);
            const uint64_t t = monotonic_ns();
            if (due > t) std::this_thread::sleep_for(std::chrono::nanoseconds(due - t));
        }
        fgsr_input_slot in{};
        const uint64_t c0 = thread_cpu_ns();
        s = st.session.acquire_input(kWaitMs, in);
        st.summary.client_wait_cpu_ns += thread_cpu_ns() - c0;
        if (s != FGSR_STATUS_OK) return client_error(s, "no input slot");
        const capture::Frame& fr = cap.inputs[i];
        copy_plane(in.color, st.layout.color.row_pitch, fr.color, cb, f.height);
        copy_plane(in.depth, st.layout.depth.row_pitch, fr.depth, size_t(f.width) * 4, f.height);
        if (!fr.mv.empty()) copy_plane(in.mv, st.layout.mv.row_pitch, fr.mv, mb, f.height);
        st.summary.client_bytes_copied += fr.color.size() + fr.depth.size() + fr.mv.size();
        const Plan& p = plans[i];
        fgsr_submit_info si{};
        si.struct_size = sizeof(si);
        si.input_slot = in.index;
        si.flags = (fr.mv.empty() ? 0u : FGSR_SUBMIT_HAS_MV) | (p.want_sr ? FGSR_SUBMIT_WANT_SR : 0u) |
                   (fr.reset ? FGSR_SUBMIT_RESET : 0u);
        si.jitter_x = fr.jitter_x;
        si.jitter_y = fr.jitter_y;
        si.interp_count = uint32_t(p.interp.size());
        si.interp_alphas = p.interp.data();
        si.extrap_count = uint32_t(p.extrap.size());
        si.extrap_alphas = p.extrap.data();
        si.user_data = i;
        const uint64_t submit_ns = monotonic_ns();
        uint64_t sequence = 0;
        s = st.session.submit(si, &sequence);
        if (s != FGSR_STATUS_OK) return client_error(s, fmt::format("submit of frame {}", i));
        ++st.summary.submitted;
        presenter.submitted(sequence, submit_ns, si.interp_count, p.want_sr);
        FGSR_TRY(presenter.flush());
        // Whatever has completed meanwhile (the client keeps completions seen while acquiring).
        fgsr_output out{};
        while ((s = wait(0, out)) == FGSR_STATUS_OK) FGSR_TRY(handle(out));
        if (s != FGSR_STATUS_TIMEOUT) return client_error(s, "waiting for outputs");
        while (o.closed_loop && finished < st.summary.submitted) {
            s = wait(kWaitMs, out);
            if (s != FGSR_STATUS_OK) return client_error(s, "waiting for outputs");
            FGSR_TRY(handle(out));
        }
        if (o.progress)
            std::fprintf(stderr, "\r[replay] %s %s: submitted %zu/%zu, outputs %zu", cap.name.c_str(),
                         st.summary.mode.c_str(), i + 1, last_input + 1, st.summary.outputs);
    }
    // Drain: every submit ends with a LAST completion; wait until the last one arrived.
    while (finished < st.summary.submitted) {
        fgsr_output out{};
        s = wait(kWaitMs, out);
        if (s != FGSR_STATUS_OK) return client_error(s, "waiting for outputs");
        FGSR_TRY(handle(out));
    }
    if (o.progress) std::fprintf(stderr, "\n");
    if (st.csv && std::fflush(st.csv) != 0)
        return make_error(Errc::io, "cannot write " + o.telemetry->string());
    st.summary.wall_s = double(monotonic_ns() - t0) * 1e-9;
    st.summary.latency_p50_ms = percentile_ms(st.latency_ms, 0.5);
    st.summary.latency_p99_ms = percentile_ms(st.latency_ms, 0.99);
    st.summary.overhead_p50_ms = percentile_ms(st.overhead_ms, 0.5);
    st.summary.overhead_p99_ms = percentile_ms(st.overhead_ms, 0.99);
    st.summary.wake_p50_us = percentile_ms(st.wake_us, 0.5);
    st.summary.handoff_p50_us = percentile_ms(st.handoff_us, 0.5);
    st.summary.return_p50_us = percentile_ms(st.return_us, 0.5);
    fgsr_session_stats stats{};
    if (st.session.stats(stats) == FGSR_STATUS_OK) {
        st.summary.daemon_latency_p50_ms = double(stats.latency_p50_ns) * 1e-6;
        st.summary.daemon_latency_p99_ms = double(stats.latency_p99_ns) * 1e-6;
        st.summary.daemon_bytes_copied = stats.bytes_copied;
    }
    if (!score.psnr.empty()) {
        finish_means(rep);
        rep.frames = score.psnr.size();
        if (o.out) FGSR_TRY(write_metrics_json(rep, *o.out));
        st.summary.metrics = std::move(rep);
    }
    return std::move(st.summary);
}

std::string replay_summary_text(const ReplaySummary& s) {
    std::string t =
        fmt::format("replay {} ({}) through fgsrd on {}: {} frames submitted, {} outputs, {} dropped, "
                    "{} rejected in {:.2f} s\n",
                    s.capture, s.mode, s.device, s.submitted, s.outputs, s.dropped, s.rejected, s.wall_s);
    t += fmt::format("latency (client-observed, submit to output): p50 {:.2f} ms, p99 {:.2f} ms; "
                     "daemon-reported p50 {:.2f} ms, p99 {:.2f} ms\n",
                     s.latency_p50_ms, s.latency_p99_ms, s.daemon_latency_p50_ms, s.daemon_latency_p99_ms);
    t += fmt::format(
        "service overhead (client-observed minus the daemon's work, queueing behind earlier frames "
        "included; --bench keeps one frame in flight): p50 {:.3f} ms, p99 {:.3f} ms\n",
        s.overhead_p50_ms, s.overhead_p99_ms);
    const double submits = double(std::max<size_t>(1, s.submitted));
    t += fmt::format("bytes copied per submit: daemon {:.0f} (stats.bytes_copied), client {:.0f} (planes into "
                     "input slots, outputs copied out)\n",
                     double(s.daemon_bytes_copied) / submits, double(s.client_bytes_copied) / submits);
    if (s.metrics) t += report_table(*s.metrics);
    return t;
}

} // namespace fgsr::cli
