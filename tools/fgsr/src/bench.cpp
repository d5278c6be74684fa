// `fgsr bench` (see bench.hpp): run time against error on captures, resolution scaling, frames per
// pair, the memcpy roofline and still against moving. Its outputs (CSV, Markdown, gnuplot) are
// written by bench_report.cpp.
#include <fgsr/cli/bench.hpp>

#include "bench_internal.hpp"

#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/cli_util.hpp>
#include <fgsr/cli/eval_motion.hpp>

#include <fgsr/capture/synthetic.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <thread>

namespace fgsr::cli {

namespace {

using namespace bench_detail;

using Clock = std::chrono::steady_clock;

// A capture to benchmark: spec as given (fgsr/cli/capture_spec.hpp), and the modes it is limited to
// (empty: all it supports).
struct CaptureEntry {
    std::string spec;
    std::vector<std::string> modes;
};

std::vector<CaptureEntry> capture_entries(const BenchOptions& o) {
    std::vector<CaptureEntry> out;
    if (!o.captures.empty()) {
        for (const std::string& s : o.captures) out.push_back({s, {}});
        return out;
    }
    out.push_back({"builtin", {"interp", "extrap"}});
    if (o.quick) return out;
    const std::filesystem::path root = o.shared_captures;
    auto add = [&](const std::string& rel, bool lr, std::vector<std::string> modes) {
        const std::filesystem::path dir = root / rel;
        if (!std::filesystem::is_directory(dir)) {
            progress(o, "default capture " + dir.string() + " is absent: skipped");
            return;
        }
        out.push_back({dir.string() + (lr ? "@lr" : ""), std::move(modes)});
    };
    add("blender/toss-fg", false, {"interp", "extrap"});
    add("blender/orbit-sr", false, {"sr", "isr", "esr"});
    add("mobfgsr-bunker", false, {"interp", "extrap"});
    add("mobfgsr-bunker", true, {"sr"});
    return out;
}

// Whether the capture holds the ground truth `mode` is scored against.
bool supports(const capture::Capture& c, const std::string& mode) {
    const bool consecutive = c.ground_truth_kind == capture::GroundTruth::consecutive;
    const bool fg = consecutive ? c.inputs.size() >= 3 : !c.ground_truth.empty();
    const bool sr = !c.hr_reference.empty() && c.hr_reference.size() == c.inputs.size();
    if (mode == "interp" || mode == "extrap") return fg;
    if (mode == "sr") return sr;
    return sr && (consecutive ? c.inputs.size() >= 3 : !c.hr_ground_truth.empty());
}

// Whether switch `key` changes anything in `mode` (the passes that read the field).
bool switch_applies(const std::string& key, const std::string& mode) {
    const bool fg = mode == "interp" || mode == "extrap";
    const bool joint = mode == "isr" || mode == "esr";
    if (key == "motion" || key == "fill_gaps" || key == "fill_holes") return fg || joint;
    if (key == "blend") return mode == "interp" || mode == "isr"; // extrapolation shows frame 1 only
    if (key == "passes") return fg;                               // SR passes are always fused
    if (key == "resample") return mode == "sr" || joint;
    if (key == "dilate_mvs") return mode == "sr";
    if (key == "denoise") return mode == "sr" || joint;
    if (key == "correct_vectors") return fg; // refused with super resolution
    if (key == "colour_agree") return fg || joint; // the upscaled frame does not use it (change 45)
    // fast_motion and motion_consensus act on sessions without vectors only: fast_motion's
    // configuration is the colour-only one's (configs_for), not a toggle of the configurations with
    // vectors; motion_consensus is measured with fgsr eval (docs/MOTION.md).
    return false;
}

struct Config {
    std::string name, preset, toggle;
    Params params;
    bool colour_only = false; // vectors and depth withheld (eval's fgsr-colour)
};

// The colour-only configurations' names, and their `switch` column: motion estimated as by
// default, with fast_motion=on, and with motion_search=off.
constexpr const char* kColourConfig = "balanced+colour";
constexpr const char* kColourToggle = "input=colour";
constexpr const char* kColourFastConfig = "balanced+colour+fast_motion=on";
constexpr const char* kColourFastToggle = "input=colour fast_motion=on";
constexpr const char* kColourSearchConfig = "balanced+colour+motion_search=off";
constexpr const char* kColourSearchToggle = "input=colour motion_search=off";

Result<std::vector<Config>> configs_for(const BenchOptions& o, const std::string& mode) {
    std::vector<Config> out;
    for (const std::string& p : o.presets) {
        auto params = preset_params(p);
        if (!params) return params.error();
        out.push_back({p, p, "", *params});
    }
    const Params base = preset_params(Preset::balanced);
    if (o.toggles)
        for (const std::string& t : switch_toggles(base)) {
            if (!switch_applies(t.substr(0, t.find('=')), mode)) continue;
            Params p = base;
            FGSR_TRY(apply_switch(p, t));
            out.push_back({"balanced+" + t, "balanced", t, p});
        }
    if (o.colour) {
        out.push_back({kColourConfig, "balanced", kColourToggle, base, true});
        Params fast = base;
        fast.fast_motion = true;
        out.push_back({kColourFastConfig, "balanced", kColourFastToggle, fast, true});
        Params no_search = base;
        no_search.motion_search = false;
        out.push_back({kColourSearchConfig, "balanced", kColourSearchToggle, no_search, true});
    }
    return out;
}

// A session holding every input of `c` (the last two are frames 0 and 1).
Result<std::unique_ptr<Session>> primed_session(Engine& engine, const capture::Capture& c, const Params& p) {
    auto s = engine.create_session(c.format, p);
    if (!s) return s.error();
    for (const capture::Frame& f : c.inputs) FGSR_TRY((*s)->submit(f.view()));
    return std::move(*s);
}

// One interpolation call of `alphas`: the call's total GPU ms (sum over its frames), and per pass.
Result<double> timed_call(Session& s, const std::vector<float>& alphas,
                          std::map<std::string, double>* passes) {
    auto out = s.interpolate(alphas);
    if (!out) return out.error();
    double ms = 0;
    for (const GeneratedFrame& f : *out) {
        ms += f.gpu_ms;
        if (passes)
            for (const PassTiming& p : f.passes) (*passes)[p.name] += p.ms;
    }
    return ms;
}

// "pass median (samples), ...": medians of the calls that ran each pass.
std::string pass_medians(const std::map<std::string, std::vector<double>>& samples) {
    std::string out;
    for (const auto& [p, v] : samples)
        out += fmt::format("{}{} {:.2f} ({})", out.empty() ? "" : ", ", p, median(v), v.size());
    return out;
}

capture::SceneOptions timing_scene(const Resolution& r, float speed) {
    capture::SceneOptions so;
    so.width = r.width;
    so.height = r.height;
    so.supersample = 1; // timing inputs only: no need for antialiased colour
    so.speed = speed;
    return so;
}

// The timing loops submit a new input before each call. Inputs 1 and 2 of a capture in turn would
// not be a stream: input 1's vectors describe input 0, not input 2, and ingest's cut stage
// (Params::vector_cuts) takes every other frame for a scene cut, whose pairs are refused. So the
// scene at t = 1 with vectors towards t = 2 is appended as input 3, and the loops submit inputs 2
// and 3 in turn (timing_input): the motion turns back at every frame, and every frame's vectors
// describe the frame submitted before it. (The quadratic model falls back to uniform velocity on
// the turn: the same passes, one branch per pixel.)
Result<capture::Capture> timing_capture(const capture::SceneOptions& so) {
    auto c = capture::make_synthetic_capture(so, 3);
    if (!c) return c.error();
    c->inputs.push_back(capture::synthetic_frame(capture::SyntheticScene(so), 1.0, 2.0));
    return c;
}

// Input i of a timing loop after a session was primed with every input of timing_capture (the
// last input 3): inputs 2 and 3 in turn.
const capture::Frame& timing_input(const capture::Capture& c, int i) {
    return c.inputs[i % 2 == 0 ? 2 : 3];
}

// Per-config timing samples of one capture and mode.
struct Samples {
    std::vector<double> ms;
    std::map<std::string, std::vector<double>> passes;
    std::vector<double> motion; // colour-only: the motion passes of the newest input's submit
    void add(const GeneratedFrame& f) {
        ms.push_back(f.gpu_ms);
        for (const PassTiming& p : f.passes) passes[p.name].push_back(p.ms);
    }
};

// Times every config on the frames run_eval scores (`cap` as run_eval sees it: half-rate already
// applied for frame generation), interleaved: per frame, `repeats` rounds that call each config's
// session once, so that load from other processes falls on all configs alike.
Result<std::vector<Samples>> time_configs(const BenchOptions& o, Engine& engine, const capture::Capture& cap,
                                          const std::string& mode, const std::vector<Config>& configs,
                                          float scale) {
    std::vector<std::unique_ptr<Session>> sessions;
    for (const Config& c : configs) {
        Params p = c.params;
        if (mode == "sr" || mode == "isr" || mode == "esr") p.scale = scale;
        auto s = engine.create_session(c.colour_only ? colour_only(cap.format) : cap.format, p);
        if (!s) return s.error();
        sessions.push_back(std::move(*s));
    }
    std::vector<Samples> out(configs.size());
    // A colour-only frame (or one with corrected vectors) costs the motion passes of the newest
    // input too; the other sessions run none.
    auto add = [&](size_t c, const GeneratedFrame& f) {
        const std::vector<PassTiming> motion = sessions[c]->last_motion_timings();
        if (motion.empty()) return out[c].add(f);
        double ms = 0;
        for (const PassTiming& p : motion) ms += p.ms;
        out[c].motion.push_back(ms);
        out[c].add(with_motion_timings(f, motion));
    };
    const int reps = std::max(o.repeats, 1);
    if (mode == "sr") { // the history is temporal: replay the frames from a reset, `repeats` times
        const size_t frames = std::min(cap.inputs.size(), size_t(o.frames));
        for (int r = 0; r < reps; ++r)
            for (size_t k = 0; k < frames; ++k)
                for (size_t c = 0; c < sessions.size(); ++c) {
                    FrameView v = session_view(sessions[c]->format(), cap.inputs[k].view());
                    v.reset = k == 0;
                    FGSR_TRY(sessions[c]->submit(v));
                    auto f = sessions[c]->super_resolved();
                    if (!f) return f.error();
                    add(c, *f);
                }
        return out;
    }
    const bool extrap = mode == "extrap" || mode == "esr";
    const size_t refs = mode == "isr" || mode == "esr" ? cap.hr_ground_truth.size() : cap.ground_truth.size();
    const std::vector<size_t> targets = skip_first(halfway_targets(cap.inputs, refs, extrap, 0), 1, o.frames);
    const float alpha[] = {0.5f};
    size_t next_input = 0;
    for (size_t t : targets) {
        const size_t newest = extrap ? t : t + 1;
        for (; next_input <= newest; ++next_input)
            for (auto& s : sessions)
                FGSR_TRY(s->submit(session_view(s->format(), cap.inputs[next_input].view())));
        for (int r = 0; r < reps; ++r)
            for (size_t c = 0; c < sessions.size(); ++c) {
                auto f = extrap ? sessions[c]->extrapolate(alpha) : sessions[c]->interpolate(alpha);
                if (!f && restarted_at_cut(*sessions[c])) continue; // nothing generated, nothing timed
                if (!f) return f.error();
                add(c, (*f)[0]);
            }
    }
    return out;
}

Result<void> run_captures(const BenchOptions& o, Engine& engine, BenchReport& rep) {
    const std::set<std::string> wanted(o.modes.begin(), o.modes.end());
    for (const CaptureEntry& e : capture_entries(o)) {
        EvalOptions eo;
        eo.capture = e.spec;
        const bool lr = parse_capture_spec(e.spec).lr;
        progress(o, "loading " + e.spec);
        // Half-rate captures use inputs 0, 2, 4, ...: 2 frames + 6 cover `frames` targets of any mode
        // after the skipped first one.
        auto loaded = load_eval_capture(eo, size_t(2 * o.frames + 6));
        if (!loaded) return make_error(loaded.error().code, e.spec + ": " + loaded.error().message);
        const capture::Capture& cap = *loaded;
        std::optional<capture::Capture> half; // frame generation on consecutive captures (made once)
        // The Mob-FGSR importer names LR captures "...-lr" itself.
        const bool named_lr = cap.name.size() > 3 && cap.name.compare(cap.name.size() - 3, 3, "-lr") == 0;
        const std::string label = cap.name + (lr && !named_lr ? "-lr" : "");
        for (const std::string mode : {"interp", "extrap", "sr", "isr", "esr"}) {
            if (!wanted.count(mode)) continue;
            if (!e.modes.empty() && std::find(e.modes.begin(), e.modes.end(), mode) == e.modes.end())
                continue;
            if (!supports(cap, mode)) {
                rep.skipped.push_back(label + " " + mode + ": no ground truth for this mode");
                continue;
            }
            const capture::Capture* input = &cap;
            if (mode != "sr" && cap.ground_truth_kind == capture::GroundTruth::consecutive) {
                if (!half) {
                    progress(o, label + ": half-rate inputs with composed vectors");
                    auto h = capture::make_half_rate(cap);
                    if (!h) return make_error(h.error().code, label + ": " + h.error().message);
                    half = std::move(*h);
                }
                input = &*half;
            }
            auto configs = configs_for(o, mode);
            if (!configs) return configs.error();
            const size_t first_row = rep.rows.size();
            for (size_t ci = 0; ci < configs->size(); ++ci) {
                const Config& c = (*configs)[ci];
                EvalOptions run = eo;
                run.mode = parse_eval_mode(mode);
                const std::string method = c.colour_only ? "fgsr-colour" : "fgsr";
                run.methods = {method};
                run.params = c.params;
                run.max_frames = o.frames;
                run.skip_targets = mode == "sr" ? 0 : 1; // frame 0 of the first pair has no vectors
                run.preloaded = input;
                run.engine = &engine;
                run.progress = false;
                auto r = run_eval(run);
                if (!r)
                    return make_error(r.error().code,
                                      label + " " + mode + " " + c.name + ": " + r.error().message);
                const MethodScore& s = r->methods.at(method);
                BenchRow row;
                row.capture = label;
                row.mode = mode;
                row.config = c.name;
                row.preset = c.preset;
                row.toggle = c.toggle;
                row.width = r->width;
                row.height = r->height;
                row.frames = r->frames;
                row.psnr = s.mean_psnr;
                row.ssim = s.mean_ssim;
                row.colour_only = c.colour_only;
                row.motion = c.colour_only || c.params.correct_vectors || c.params.colour_agree;
                if (!s.epe.empty()) row.epe = s.mean_epe;
                row.bytes = total_bytes(frame_bytes(run.mode, c.params, input->format.width,
                                                    input->format.height, r->width, r->height));
                rep.device = r->device;
                progress(o, fmt::format("{} {} {}/{} {}: {:.2f} dB, SSIM {:.4f}", label, mode, ci + 1,
                                        configs->size(), c.name, row.psnr, row.ssim));
                rep.rows.push_back(std::move(row));
            }
            progress(o, fmt::format("{} {}: timing {} configurations x {} frames x {} repeats (interleaved)",
                                    label, mode, configs->size(), rep.rows.back().frames, o.repeats));
            const float scale = float(rep.rows.back().width) / float(input->format.width);
            auto samples = time_configs(o, engine, *input, mode, *configs, scale);
            if (!samples)
                return make_error(samples.error().code, label + " " + mode + ": " + samples.error().message);
            std::vector<ParetoPoint> pts;
            for (size_t i = first_row; i < rep.rows.size(); ++i) {
                BenchRow& row = rep.rows[i];
                const Samples& sm = (*samples)[i - first_row];
                row.samples = sm.ms.size();
                row.ms = median(sm.ms);
                row.ms_mean = 0;
                for (double v : sm.ms) row.ms_mean += v / double(sm.ms.size());
                for (const auto& [pass, v] : sm.passes) row.pass_ms[pass] = median(v);
                if (row.motion) row.motion_ms = sm.motion.empty() ? 0 : median(sm.motion);
                pts.push_back({row.ms, row.psnr});
                progress(o, fmt::format("{} {} {}: {:.2f} ms (median of {})", label, mode, row.config, row.ms,
                                        row.samples));
            }
            const std::vector<bool> front = pareto_front(pts);
            for (size_t i = 0; i < front.size(); ++i) rep.rows[first_row + i].pareto = front[i];
        }
    }
    return {};
}

// BenchReport::colour on `cap` (the moving synthetic scene at the headline resolution).
Result<void> time_colour_only(const BenchOptions& o, Engine& engine, const capture::Capture& cap,
                              const Params& params, BenchReport::ColourTiming& t) {
    auto s = engine.create_session(colour_only(cap.format), params);
    if (!s) return s.error();
    for (const capture::Frame& f : cap.inputs) FGSR_TRY((*s)->submit(session_view((*s)->format(), f.view())));
    std::vector<double> motion, ingest, call;
    std::map<std::string, std::vector<double>> passes;
    const std::vector<float> half{0.5f};
    for (int i = 0; i < std::max(o.repeats, 9); ++i) {
        FGSR_TRY((*s)->submit(session_view((*s)->format(), timing_input(cap, i).view())));
        double m = 0;
        for (const PassTiming& p : (*s)->last_motion_timings()) {
            m += p.ms;
            passes[p.name].push_back(p.ms);
        }
        motion.push_back(m);
        ingest.push_back((*s)->last_ingest_ms());
        auto c = timed_call(**s, half, nullptr);
        if (!c && restarted_at_cut(**s)) continue; // taken for a cut: nothing generated
        if (!c) return c.error();
        call.push_back(*c);
    }
    t.measured = true;
    t.motion_ms = median(motion);
    t.ingest_ms = median(ingest);
    t.call_ms = median(call);
    for (const auto& [name, v] : passes) t.motion_pass_ms[name] = median(v);
    progress(o,
             fmt::format("colour only{}: motion {:.2f} ms, ingest {:.2f} ms, interpolate call {:.2f} ms",
                         params.fast_motion ? " (fast_motion=on)" : "", t.motion_ms, t.ingest_ms, t.call_ms));
    return {};
}

Result<void> run_timing(const BenchOptions& o, Engine& engine, BenchReport& rep) {
    const Params balanced = preset_params(Preset::balanced);
    const int reps = std::max(o.repeats, 1);
    const std::vector<float> half{0.5f};
    std::vector<Resolution> resolutions;
    for (const std::string& s : o.resolutions) {
        auto r = parse_resolution(s);
        if (!r) return make_error(Errc::invalid_argument, "resolution '" + s + "' is not <H>p or <W>x<H>");
        resolutions.push_back(*r);
    }
    if (resolutions.empty()) return {};
    rep.headline = resolutions[0];
    for (const Resolution& r : resolutions)
        if (r.name == "720p") rep.headline = r;

    for (const Resolution& r : resolutions) {
        if (o.still_only && r.name != rep.headline.name) continue;
        progress(o, fmt::format("resolution {} ({}x{}): rendering the synthetic scene", r.name, r.width,
                                r.height));
        auto cap = timing_capture(timing_scene(r, 1.f));
        if (!cap) return cap.error();
        auto s = primed_session(engine, *cap, balanced);
        if (!s) return s.error();
        std::vector<double> samples;
        std::map<std::string, std::vector<double>> pass_samples;
        for (int i = 0; i < (o.still_only ? 0 : reps); ++i) {
            std::map<std::string, double> passes;
            auto ms = timed_call(**s, half, &passes);
            if (!ms) return ms.error();
            samples.push_back(*ms);
            for (const auto& [p, v] : passes) pass_samples[p].push_back(v);
        }
        if (!o.still_only) {
            ScaleRow row;
            row.res = r;
            row.ms = median(samples);
            for (const auto& [p, v] : pass_samples) row.pass_ms[p] = median(v);
            row.bytes = total_bytes(frame_bytes(EvalMode::interp, balanced, r.width, r.height));
            row.copy_ms = time_copy_ms(row.bytes, std::max(reps, 5), rep.copy_threads);
            progress(
                o,
                fmt::format(
                    "resolution {}: {:.2f} ms per frame, memcpy of {:.1f} MB traffic {:.2f} ms ({:.1f}x); {}",
                    r.name, row.ms, double(row.bytes) / 1e6, row.copy_ms, row.ms / row.copy_ms,
                    pass_medians(pass_samples)));
            rep.scaling.push_back(row);
        }

        if (r.name != rep.headline.name) continue;
        // Frames per pair: one call generating `count` evenly spaced frames; the counts in turn in
        // each round (interleaved, so that load from other processes falls on all counts alike).
        const std::vector<int> counts = o.still_only ? std::vector<int>{} : o.alpha_counts;
        for (int count : counts)
            if (count < 1 || count > 64)
                return make_error(Errc::invalid_argument, "alpha count outside [1, 64]");
        std::vector<std::vector<double>> calls(counts.size());
        std::vector<std::map<std::string, std::vector<double>>> call_passes(counts.size());
        for (int i = 0; i < reps; ++i)
            for (size_t c = 0; c < counts.size(); ++c) {
                std::vector<float> alphas;
                for (int k = 1; k <= counts[c]; ++k) alphas.push_back(float(k) / float(counts[c] + 1));
                std::map<std::string, double> passes;
                auto ms = timed_call(**s, alphas, &passes);
                if (!ms) return ms.error();
                calls[c].push_back(*ms);
                for (const auto& [name, pass_ms] : passes) call_passes[c][name].push_back(pass_ms);
            }
        for (size_t c = 0; c < counts.size(); ++c) {
            AlphaRow row{counts[c], median(calls[c]), {}, {}};
            for (const auto& [name, v] : call_passes[c]) {
                row.pass_ms[name] = median(v);
                row.pass_calls[name] = v.size();
            }
            rep.alphas.push_back(std::move(row));
            progress(o,
                     fmt::format("{} frames per pair: {:.2f} ms per call", counts[c], rep.alphas.back().ms));
        }
        // Still (no motion, identical frames, zero vectors) against moving, alternating; each call
        // on a fresh pair: a new input is submitted (timing_input: the scene moving forward and back
        // in turn) and its ingest counted in the per-frame figure.
        auto still_cap = timing_capture(timing_scene(r, 0.f));
        if (!still_cap) return still_cap.error();
        auto still = primed_session(engine, *still_cap, balanced);
        if (!still) return still.error();
        std::vector<double> st, mv, st_frame, mv_frame, mv_wall;
        std::map<std::string, std::vector<double>> mv_passes;
        for (int i = 0; i < std::max(reps, 9); ++i) {
            // Inputs 2 and 3 in turn for both: they carry vectors (zero in the still scene), input 0 none.
            FGSR_TRY((*still)->submit(timing_input(*still_cap, i).view()));
            auto a = timed_call(**still, half, nullptr);
            if (!a) return a.error();
            st.push_back(*a);
            st_frame.push_back(*a + (*still)->last_ingest_ms());
            // Wall time of the moving frame's submit and call: the host's share (copies, allocation of
            // the returned frame, submission and waits) that the GPU timestamps leave out.
            const auto w0 = Clock::now();
            FGSR_TRY((*s)->submit(timing_input(*cap, i).view()));
            std::map<std::string, double> passes;
            auto b = timed_call(**s, half, &passes);
            if (!b) return b.error();
            mv_wall.push_back(std::chrono::duration<double, std::milli>(Clock::now() - w0).count());
            mv.push_back(*b);
            mv_frame.push_back(*b + (*s)->last_ingest_ms());
            for (const auto& [p, v] : passes) mv_passes[p].push_back(v);
            mv_passes["ingest"].push_back((*s)->last_ingest_ms());
        }
        progress(o, "moving, fresh pairs, per pass: " + pass_medians(mv_passes));
        progress(o, fmt::format(
                        "moving, fresh pairs, wall time of submit + interpolate (host included): {:.2f} ms",
                        median(mv_wall)));
        // A run of consecutive moving calls on a fresh session: the calls that classify (the
        // adaptive rule, daemon/engine/src/session.hpp) counted in the mean.
        if (o.moving_run) {
            auto run = primed_session(engine, *cap, balanced);
            if (!run) return run.error();
            std::vector<double> all, classified, plain;
            const int run_calls = std::max(8 * reps, 64);
            for (int i = 0; i < run_calls; ++i) {
                FGSR_TRY((*run)->submit(timing_input(*cap, i).view()));
                std::map<std::string, double> passes;
                auto ms = timed_call(**run, half, &passes);
                if (!ms) return ms.error();
                all.push_back(*ms);
                (passes.count("classify") ? classified : plain).push_back(*ms);
                if ((i + 1) % 16 == 0)
                    progress(o, fmt::format("moving run: {} of {} calls", i + 1, run_calls));
            }
            BenchReport::MovingRun& m = rep.moving_run;
            m.calls = run_calls;
            m.classified = int(classified.size());
            for (double v : all) m.mean_ms += v / double(run_calls);
            m.max_ms = *std::max_element(all.begin(), all.end());
            m.classified_ms = classified.empty() ? 0 : median(classified);
            m.plain_ms = plain.empty() ? 0 : median(plain);
            progress(
                o, fmt::format("moving run of {} calls: {} classified (median {:.2f} ms), the others median "
                               "{:.2f} ms; mean {:.2f} ms, max {:.2f} ms",
                               run_calls, m.classified, m.classified_ms, m.plain_ms, m.mean_ms, m.max_ms));
        }
        if (o.colour) {
            FGSR_TRY(time_colour_only(o, engine, *cap, balanced, rep.colour));
            Params fast = balanced;
            fast.fast_motion = true;
            FGSR_TRY(time_colour_only(o, engine, *cap, fast, rep.colour_fast));
        }
        rep.still_ms = median(st);
        rep.moving_ms = median(mv);
        rep.still_frame_ms = median(st_frame);
        rep.moving_frame_ms = median(mv_frame);
        progress(o,
                 fmt::format("still {:.2f} ms, moving {:.2f} ms: ratio {:.2f} (interpolate call); per frame "
                             "with the new input's ingest: still {:.2f} ms, moving {:.2f} ms: ratio {:.2f}",
                             rep.still_ms, rep.moving_ms, rep.still_ms / rep.moving_ms, rep.still_frame_ms,
                             rep.moving_frame_ms, rep.still_frame_ms / rep.moving_frame_ms));
    }
    return {};
}

} // namespace

double time_copy_ms(uint64_t bytes, int repeats, unsigned threads) {
    const size_t size = std::max<size_t>(size_t(bytes / 2), 1);
    std::unique_ptr<std::byte[]> src(new std::byte[size]), dst(new std::byte[size]);
    std::memset(src.get(), 1, size); // fault the pages in before timing
    std::memset(dst.get(), 2, size);
    threads = std::max(threads, 1u);
    auto copy_once = [&] {
        const auto t0 = Clock::now();
        std::vector<std::thread> pool;
        const size_t chunk = (size + threads - 1) / threads;
        for (unsigned t = 0; t < threads; ++t) {
            const size_t begin = std::min(size, size_t(t) * chunk), end = std::min(size, begin + chunk);
            pool.emplace_back(
                [&, begin, end] { std::memcpy(dst.get() + begin, src.get() + begin, end - begin); });
        }
        for (std::thread& th : pool) th.join();
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    };
    copy_once(); // warm-up
    std::vector<double> t;
    for (int i = 0; i < std::max(repeats, 1); ++i) t.push_back(copy_once());
    return median(t);
}

Result<BenchReport> run_bench(const BenchOptions& o) {
    if (o.repeats < 1 || o.frames < 1)
        return make_error(Errc::invalid_argument, "--repeats and --frames must be at least 1");
    for (const std::string& m : o.modes)
        if (m != "interp" && m != "extrap" && m != "sr" && m != "isr" && m != "esr")
            return make_error(Errc::invalid_argument,
                              "unknown mode '" + m + "' (modes: interp, extrap, sr, isr, esr)");
    const auto t0 = Clock::now();
    BenchReport rep;
    rep.repeats = o.repeats;
    rep.frames = o.frames;
    rep.copy_threads = std::max(std::thread::hardware_concurrency(), 1u);
    auto engine = Engine::create(o.device);
    if (!engine) return engine.error();
    rep.device = (*engine)->device_name();
    progress(o, "device: " + rep.device);
    if (!o.still_only) FGSR_TRY(run_captures(o, **engine, rep));
    FGSR_TRY(run_timing(o, **engine, rep));
    rep.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return rep;
}

CLI::App* add_bench_command(CLI::App& app, BenchCli& c) {
    BenchOptions& o = c.options;
    auto* cmd =
        app.add_subcommand("bench", "Run time against error: every mode and quality preset on captures, "
                                    "resolution scaling, roofline, still vs moving");
    cmd->add_option("--captures", c.captures,
                    "Comma-separated: 'builtin', capture directories, DIR@lr (Mob-FGSR LR inputs). Default: "
                    "builtin, toss-fg, orbit-sr, mobfgsr-bunker (HR; @lr for sr) under --shared-captures");
    cmd->add_option("--shared-captures", o.shared_captures, "Where the default captures live")
        ->capture_default_str();
    cmd->add_option("--modes", c.modes, "Comma-separated subset of interp,extrap,sr,isr,esr");
    cmd->add_option("--presets", c.presets,
                    "Comma-separated presets (default: performance,balanced,quality)");
    cmd->add_flag("--no-toggles", c.no_toggles, "Do not toggle each single switch from balanced");
    cmd->add_flag("--no-colour", c.no_colour,
                  "Leave out balanced+colour (balanced on colour alone: vectors and depth withheld)");
    cmd->add_option(
        "--resolutions", c.resolutions,
        "Comma-separated <H>p or <W>x<H> for scaling and roofline (default: 540p,720p,1080p,2160p); "
        "the headline is 720p when listed, else the first");
    cmd->add_option("--alphas", c.alphas, "Frames per pair to time, comma-separated (default: 1,2,4,8)");
    cmd->add_option("--repeats", o.repeats, "Engine calls per generated frame (median)")
        ->capture_default_str();
    cmd->add_option("--frames", o.frames, "Generated frames per capture and mode")->capture_default_str();
    cmd->add_option("--out", c.out, "Output directory (CSV, Markdown, plots)")->capture_default_str();
    cmd->add_flag(
        "--quick", o.quick,
        "Small run: builtin capture, 1 frame, 2 repeats, 180p, 1 and 2 frames per pair (unless given)");
    cmd->add_flag("--no-plots", c.no_plots, "Do not draw plots");
    cmd->add_flag("--no-moving-run", c.no_moving_run,
                  "No run of consecutive moving calls (at least 64) at the headline resolution");
    cmd->add_flag("--still-only", o.still_only,
                  "Only still against moving at the headline resolution (720p if listed in --resolutions)");
    cmd->add_option("--device", o.device.device, "Vulkan device index or name substring");
    cmd->add_flag("--quiet", c.quiet, "No progress on stderr");
    return cmd;
}

int bench_main(BenchCli& c, CLI::App* cmd) {
    BenchOptions& o = c.options;
    if (!c.captures.empty()) o.captures = split_list(c.captures);
    if (!c.modes.empty()) o.modes = split_list(c.modes);
    if (!c.presets.empty()) o.presets = split_list(c.presets);
    if (!c.out.empty()) o.out = c.out;
    o.toggles = !c.no_toggles;
    o.colour = !c.no_colour;
    o.moving_run = !c.no_moving_run;
    o.plots = !c.no_plots;
    o.progress = !c.quiet;
    if (o.quick) {
        if (!cmd->count("--frames")) o.frames = 1;
        if (!cmd->count("--repeats")) o.repeats = 2;
        if (c.resolutions.empty()) o.resolutions = {"180p"};
        if (c.alphas.empty()) o.alpha_counts = {1, 2};
    }
    if (!c.resolutions.empty()) o.resolutions = split_list(c.resolutions);
    if (!c.alphas.empty()) {
        o.alpha_counts.clear();
        for (const std::string& a : split_list(c.alphas)) {
            char* end = nullptr;
            const long v = std::strtol(a.c_str(), &end, 10);
            if (!end || *end != '\0' || v < 1 || v > 64) {
                std::fprintf(stderr, "fgsr: invalid_argument: --alphas entry '%s' is not in [1, 64]\n",
                             a.c_str());
                return 1;
            }
            o.alpha_counts.push_back(int(v));
        }
    }
    auto r = run_bench(o);
    if (!r) return report_error(r.error());
    auto w = write_bench_outputs(o, *r);
    if (!w) return report_error(w.error());
    std::fputs(bench_markdown(*r).c_str(), stdout);
    std::printf("\nwritten to %s (bench.csv, bench.md, scaling.csv, alphas.csv%s)\n", o.out.c_str(),
                o.plots && !r->rows.empty() ? ", time_vs_error.png/svg, passes.png/svg" : "");
    return 0;
}

} // namespace fgsr::cli
