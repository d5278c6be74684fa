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

struct Stream {
    fgsr::client::Connection conn;
    fgsr::client::Session session;
    fgsr_pool_layout layout{};
    FILE* csv = nullptr;
    std::vector<double> latency_ms, overhead_ms;
    ReplaySummary summary;
    ~Stream() {
        if (csv) std::fclose(csv);
    }
};

fgsr_session_desc make_desc(const FrameFormat& f, const ReplayOptions& o, float scale, uint32_t modes) {
    fgsr_session_desc d = capture::session_desc(f, o.params, modes);
    d.scale = scale;
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
        s = st.session.acquire_input(kWaitMs, in);
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
        while ((s = st.session.wait(0, out)) == FGSR_STATUS_OK) FGSR_TRY(handle(out));
        if (s != FGSR_STATUS_TIMEOUT) return client_error(s, "waiting for outputs");
        while (o.closed_loop && finished < st.summary.submitted) {
            s = st.session.wait(kWaitMs, out);
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
        s = st.session.wait(kWaitMs, out);
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
    if (s.metrics) t += report_table(*s.metrics);
    return t;
}

Result<void> run_replay_bench(const std::string& socket, int frames, bool progress) {
    struct Size {
        uint32_t w, h;
    } sizes[] = {{1280, 720}, {1920, 1080}};
    std::printf("%-10s %8s %12s %12s %12s %12s %16s %16s\n", "size", "frames", "rtt p50 ms", "rtt p99 ms",
                "ovh p50 ms", "ovh p99 ms", "daemon B/frame", "client B/frame");
    for (const Size& z : sizes) {
        // A synthetic capture at the size: two rendered frames repeated (content does not matter for
        // the overhead; the engine's time is subtracted).
        capture::SceneOptions so;
        so.width = z.w;
        so.height = z.h;
        so.supersample = 1;
        auto two = capture::make_synthetic_capture(so, 2);
        if (!two) return two.error();
        capture::Capture cap = *two;
        cap.name = fmt::format("bench-{}x{}", z.w, z.h);
        cap.inputs.clear();
        for (int i = 0; i < frames; ++i) cap.inputs.push_back(two->inputs[size_t(i % 2 == 0 ? 1 : 0)]);
        cap.inputs[0].mv.clear();
        cap.ground_truth.clear();
        cap.ground_truth_kind = capture::GroundTruth::halfway; // no references: nothing scored
        std::filesystem::path tmp =
            std::filesystem::temp_directory_path() / fmt::format("fgsr-bench-{}", z.w);
        auto w = capture::save_fgsr(cap, tmp);
        if (!w) return w.error();
        ReplayOptions o;
        o.capture = tmp.string();
        o.mode = EvalMode::interp;
        o.socket = socket;
        o.progress = progress;
        o.closed_loop = true; // one frame in flight: the overhead excludes queueing behind earlier frames
        auto r = run_replay(o);
        std::error_code ec;
        std::filesystem::remove_all(tmp, ec);
        if (!r) return r.error();
        std::printf("%4ux%-5u %8zu %12.3f %12.3f %12.3f %12.3f %16.0f %16.0f\n", z.w, z.h, r->outputs,
                    r->latency_p50_ms, r->latency_p99_ms, r->overhead_p50_ms, r->overhead_p99_ms,
                    double(r->daemon_bytes_copied) / double(std::max<size_t>(1, r->submitted)),
                    double(r->client_bytes_copied) / double(std::max<size_t>(1, r->submitted)));
        std::fflush(stdout);
    }
    std::printf(
        "rtt: submit to completion seen by the client; ovh: rtt minus the daemon's work on the frame "
        "(telemetry start_ns..complete_ns); daemon B: stats.bytes_copied; client B: planes written into "
        "input slots plus outputs copied out.\n");
    return {};
}

} // namespace fgsr::cli
