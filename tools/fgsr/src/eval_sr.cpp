// `fgsr eval --mode sr`: super resolution of every input frame, scored against the capture's
// high-resolution reference of the same instant, side by side with spatial upscaling.
#include <fgsr/cli/eval.hpp>
#include <fgsr/cli/eval_motion.hpp>

#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/core/halton.hpp>
#include <fgsr/engine/color.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/reference.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

namespace fgsr::cli {

namespace {

bool is_engine_sr(const std::string& m) {
    return m == "fgsr" || m == "fgsr-bilinear" || m == "fgsr-bicubic" || is_colour_method(m);
}

constexpr const char* kSrMethods = "fgsr, fgsr-colour, fgsr-bilinear, fgsr-bicubic, bilinear, bicubic";

// A colour-only method's output (or one with --correct-vectors) costs the motion estimation of its
// newest input too; sessions that estimate nothing time no motion passes.
GeneratedFrame timed(const Session& s, GeneratedFrame f) {
    return with_motion_timings(std::move(f), s.last_motion_timings());
}

// After every session took input k: the capture's vectors of it, then each colour-only
// session's estimate against them (fgsr/cli/eval_motion.hpp).
Result<void> score_vectors(const capture::Frame& input, VectorReference& reference,
                           std::map<std::string, std::unique_ptr<Session>>& sessions, EvalReport& rep) {
    bool any = false;
    for (const auto& [name, s] : sessions) any = any || is_colour_method(name);
    if (!any) return {};
    FGSR_TRY(reference.add_frame(input.view()));
    for (const auto& [name, s] : sessions)
        if (is_colour_method(name)) FGSR_TRY(reference.score(*s, rep.methods[name]));
    return {};
}

// History resampling of a method; `fgsr` keeps `preset` (EvalOptions::params.resample).
Resample resample_of(const std::string& m, Resample preset = Resample::lut) {
    if (m == "fgsr-bilinear" || m == "bilinear") return Resample::bilinear;
    if (m == "fgsr-bicubic" || m == "bicubic") return Resample::catmull_rom;
    return preset;
}

// Sessions of the engine methods: the same pipeline with the method's resampling. `fgsr` (and
// `fgsr-colour`) keep the options' history and warp kernels (the warp's unset: the engine's
// automatic choice); `fgsr-bilinear` / `fgsr-bicubic` use theirs for both (the history of `sr` and
// ISR / ESR's warps of the SR outputs).
SessionParams sr_params_for(const EvalOptions& o, float scale, bool generates) {
    return [&o, scale, generates](const std::string& m) -> std::optional<Params> {
        if (!is_engine_sr(m)) return std::nullopt;
        Params p = o.params;
        p.scale = scale;
        // With super resolution only ISR and ESR generate from both fields (Params::colour_agree):
        // sr would pay for the twin's motion and upscale and use neither.
        p.colour_agree = p.colour_agree && generates;
        p.resample = resample_of(m, o.params.resample);
        if (m != "fgsr" && !is_colour_method(m)) p.warp_resample = resample_of(m);
        return p;
    };
}

// Temporal stability of still content (QRISP section 4). Captures have no static stretch, so one
// is made: input `last` (the last one evaluated) is submitted again, with zero vectors, kWarmup +
// static_frames times while the jitter sequence goes on (the capture's jitters cyclically from
// `last + 1`; Halton(2,3) - 1/2, 16 long, for captures without jitter): the content is still and only
// the declared jitter moves, so what changes in an output is flicker. Every method's outputs over
// the last static_frames submissions go into capture::TemporalStd (MethodScore::stability_std).
Result<void> measure_stability(const EvalOptions& o, const capture::Capture& cap, size_t last,
                               std::map<std::string, std::unique_ptr<Session>>& sessions, EvalReport& rep) {
    constexpr int kWarmup = 4;
    const capture::Frame& src = cap.inputs[last];
    bool has_jitter = false;
    for (const capture::Frame& f : cap.inputs)
        has_jitter = has_jitter || f.jitter_x != 0.f || f.jitter_y != 0.f;
    const std::vector<std::byte> zero_mv(src.mv.size(), std::byte{0}); // 0.0 in rg16f and rg32f
    const ImageRGBA lr = capture::decode_color(cap.format, src);
    std::map<std::string, capture::TemporalStd> acc;
    for (int i = 0; i < kWarmup + o.static_frames; ++i) {
        if (o.progress)
            std::fprintf(stderr, "[eval] %s sr: static frame %d/%d\n", cap.name.c_str(), i + 1,
                         kWarmup + o.static_frames);
        FrameView view = src.view();
        view.mv = zero_mv;
        if (has_jitter) {
            const capture::Frame& j = cap.inputs[(last + 1 + size_t(i)) % cap.inputs.size()];
            view.jitter_x = j.jitter_x;
            view.jitter_y = j.jitter_y;
        } else {
            const uint32_t h = uint32_t(last + 1 + size_t(i)) % 16 + 1;
            view.jitter_x = halton(h, 2) - 0.5f;
            view.jitter_y = halton(h, 3) - 0.5f;
        }
        for (const std::string& m : o.methods) {
            ImageRGBA img;
            if (is_engine_sr(m)) {
                FGSR_TRY(sessions[m]->submit(session_view(sessions[m]->format(), view)));
                auto out = sessions[m]->super_resolved();
                if (!out) return out.error();
                img = std::move(out->color);
            } else {
                img =
                    spatial_upscale(lr, rep.width, rep.height, resample_of(m), view.jitter_x, view.jitter_y);
            }
            if (i >= kWarmup) FGSR_TRY(acc[m].add(img));
        }
    }
    for (const std::string& m : o.methods) rep.methods[m].stability_std = acc[m].mean_std();
    rep.static_frames = size_t(o.static_frames);
    return {};
}

} // namespace

ImageRGBA spatial_upscale(const ImageRGBA& lr, uint32_t out_w, uint32_t out_h, Resample kind, float jitter_x,
                          float jitter_y) {
    // Output pixel q sees the scene at LR position (q + 0.5) / s; the LR frame sampled the scene at
    // pixel centres + jitter, so the LR image coordinate of that point is (q + 0.5) / s - jitter.
    std::vector<glm::vec4> src(size_t(lr.width) * lr.height);
    std::memcpy(src.data(), lr.rgba.data(), src.size() * 16);
    ImageRGBA out{out_w, out_h, std::vector<float>(size_t(out_w) * out_h * 4)};
    const float sx = float(lr.width) / float(out_w), sy = float(lr.height) / float(out_h);
    for (uint32_t y = 0; y < out_h; ++y) {
        // One row at a time through the engine's resampler (shift chosen per row and column).
        for (uint32_t x = 0; x < out_w; ++x) {
            const glm::vec2 pos((float(x) + 0.5f) * sx - jitter_x, (float(y) + 0.5f) * sy - jitter_y);
            const glm::vec4 c = ref::resample_at(src, lr.width, lr.height, pos, kind);
            for (int k = 0; k < 4; ++k)
                out.rgba[(size_t(y) * out_w + x) * 4 + size_t(k)] = std::max(c[k], 0.f);
        }
    }
    return out;
}

Result<EvalReport> run_eval_sr(const EvalOptions& o, capture::Capture cap) {
    for (const std::string& m : o.methods)
        if (!is_engine_sr(m) && m != "bilinear" && m != "bicubic")
            return make_error(Errc::invalid_argument,
                              "unknown method '" + m + "' for sr (methods: " + kSrMethods + ")");
    if (cap.hr_reference.size() != cap.inputs.size() || cap.hr_reference.empty())
        return make_error(Errc::empty_input, "capture '" + cap.name +
                                                 "' has no high-resolution reference per frame "
                                                 "(sr needs e.g. blender/orbit-sr or mobfgsr-bunker --lr)");
    const uint32_t out_w = cap.hr_reference[0].width, out_h = cap.hr_reference[0].height;
    const float scale = float(out_w) / float(cap.format.width);
    if (std::abs(float(out_h) / float(cap.format.height) - scale) > 1e-3f)
        return make_error(Errc::unsupported, "reference size " + std::to_string(out_w) + "x" +
                                                 std::to_string(out_h) +
                                                 " is not a uniform scale of the input size");

    size_t frames = cap.inputs.size();
    if (o.max_frames > 0) frames = std::min(frames, size_t(o.max_frames));
    EvalReport rep = new_report(cap, "sr", 0.f, frames, out_w, out_h, o.methods);

    std::unique_ptr<Engine> engine;
    auto made = make_sessions(o, cap.format, sr_params_for(o, scale, false), engine, rep);
    if (!made) return made.error();
    auto& sessions = *made;
    if (o.out) FGSR_TRY(make_out_dirs(*o.out, o.methods));
    VectorReference reference(cap.format);
    for (size_t k = 0; k < frames; ++k) {
        if (o.progress)
            std::fprintf(stderr, "[eval] %s sr: frame %zu/%zu\n", cap.name.c_str(), k + 1, frames);
        FrameView view = cap.inputs[k].view();
        const ImageRGBA lr = capture::decode_color(cap.format, cap.inputs[k]);
        for (const std::string& m : o.methods) {
            MethodScore& score = rep.methods[m];
            ImageRGBA img;
            if (is_engine_sr(m)) {
                FGSR_TRY(sessions[m]->submit(session_view(sessions[m]->format(), view)));
                auto out = sessions[m]->super_resolved();
                if (!out) return out.error();
                add_timing(score, timed(*sessions[m], *out));
                img = std::move(out->color);
            } else {
                img = spatial_upscale(lr, out_w, out_h, resample_of(m), view.jitter_x, view.jitter_y);
            }
            FGSR_TRY(score_image(score, img, cap.hr_reference[k]));
            if (o.out) FGSR_TRY(capture::write_png(*o.out / m / fmt::format("{:04d}.png", k + 1), img));
        }
        if (o.out)
            FGSR_TRY(capture::write_png(*o.out / "reference" / fmt::format("{:04d}.png", k + 1),
                                        cap.hr_reference[k]));
        FGSR_TRY(score_vectors(cap.inputs[k], reference, sessions, rep));
    }
    // The input's aliasing measure, which decides Params::sr_disagree, sr_sharp_current, the
    // spatial upsample's kernel and ISR / ESR's clip width (before the stability stretch, which
    // jitters unjittered captures).
    if (o.progress)
        for (const std::string& m : o.methods)
            if (is_engine_sr(m)) {
                const Session& s = *sessions[m];
                const float a = s.input_aliasing();
                if (a < 0.f)
                    std::fprintf(stderr, "[eval] %s sr: input aliasing not measured\n", cap.name.c_str());
                else if (!measures_antialiased(a))
                    std::fprintf(stderr, "[eval] %s sr: input aliasing %.2f (aliased: B-spline spatial upsample)\n",
                                 cap.name.c_str(), a);
                else
                    std::fprintf(stderr, "[eval] %s sr: input aliasing %.2f (antialiased%s)\n", cap.name.c_str(), a,
                                 s.input_jittered() ? ", jittered" : ": less history where it disagrees");
                break;
            }
    if (o.static_frames > 0 && frames > 0) FGSR_TRY(measure_stability(o, cap, frames - 1, sessions, rep));
    finish_means(rep);
    if (o.out) FGSR_TRY(write_metrics_json(rep, *o.out));
    return rep;
}

} // namespace fgsr::cli

namespace fgsr::cli {

// Modes isr / esr: frames generated at output resolution between (or after) inputs, scored against
// the high-resolution reference at the generated instant; consecutive captures run at half rate.
// Baselines `bilinear` / `bicubic`: frame generation at input resolution, then spatial upscaling.
Result<EvalReport> run_eval_joint(const EvalOptions& o, capture::Capture cap) {
    const bool extrap = o.mode == EvalMode::esr;
    for (const std::string& m : o.methods)
        if (!is_engine_sr(m) && m != "bilinear" && m != "bicubic")
            return make_error(Errc::invalid_argument, "unknown method '" + m + "' for " +
                                                          (extrap ? "esr" : "isr") +
                                                          " (methods: " + kSrMethods + ")");
    FGSR_TRY(evaluate_at_half_rate(cap, o.progress));
    if (cap.hr_ground_truth.empty() || cap.hr_reference.size() != cap.inputs.size())
        return make_error(Errc::empty_input, "capture '" + cap.name +
                                                 "' has no high-resolution reference between inputs "
                                                 "(isr/esr need e.g. blender/orbit-sr)");
    if (std::abs(o.alpha - 0.5f) > 1e-6f)
        return make_error(Errc::invalid_argument,
                          "references exist only halfway between inputs; use --alpha 0.5");
    const uint32_t out_w = cap.hr_ground_truth[0].width, out_h = cap.hr_ground_truth[0].height;
    const float scale = float(out_w) / float(cap.format.width);
    const std::vector<size_t> targets = skip_first(
        halfway_targets(cap.inputs, cap.hr_ground_truth.size(), extrap, 0), o.skip_targets, o.max_frames);
    if (targets.empty())
        return make_error(Errc::empty_input, "capture '" + cap.name + "' has too few frames");

    EvalReport rep =
        new_report(cap, extrap ? "esr" : "isr", o.alpha, targets.size(), out_w, out_h, o.methods);

    std::unique_ptr<Engine> engine;
    auto made = make_sessions(o, cap.format, sr_params_for(o, scale, true), engine, rep);
    if (!made) return made.error();
    auto& sessions = *made;
    auto lr_engine = eval_engine(o, engine, rep);
    if (!lr_engine) return lr_engine.error();
    auto lr_session = (*lr_engine)->create_session(cap.format, o.params); // for the spatial baselines
    if (!lr_session) return lr_session.error();

    if (o.out) FGSR_TRY(make_out_dirs(*o.out, o.methods));
    const size_t last_input = targets.back() + (extrap ? 0 : 1);
    size_t next = 0;
    VectorReference reference(cap.format);
    for (size_t i = 0; i <= last_input && next < targets.size(); ++i) {
        for (auto& [name, s] : sessions) FGSR_TRY(s->submit(session_view(s->format(), cap.inputs[i].view())));
        FGSR_TRY((*lr_session)->submit(cap.inputs[i].view()));
        FGSR_TRY(score_vectors(cap.inputs[i], reference, sessions, rep));
        const size_t k = targets[next];
        if (i != (extrap ? k : k + 1)) continue;
        ++next;
        if (o.progress)
            std::fprintf(stderr, "[eval] %s %s: frame %zu/%zu\n", cap.name.c_str(), rep.mode.c_str(), next,
                         targets.size());
        const float a[] = {o.alpha};
        std::optional<ImageRGBA> lr_frame;
        bool lr_cut = false; // frame generation at input resolution restarted at a cut
        for (const std::string& m : o.methods) {
            MethodScore& score = rep.methods[m];
            ImageRGBA img;
            if (is_engine_sr(m)) {
                auto out = extrap ? sessions[m]->extrapolate(a) : sessions[m]->interpolate(a);
                if (!out && restarted_at_cut(*sessions[m])) { // the newest frame, upscaled
                    ++score.scene_cuts;
                    auto sr = sessions[m]->super_resolved();
                    if (!sr) return sr.error();
                    img = std::move(sr->color);
                } else if (!out) {
                    return out.error();
                } else {
                    add_timing(score, timed(*sessions[m], (*out)[0]));
                    img = std::move((*out)[0].color);
                }
            } else {
                if (!lr_frame) {
                    auto out = extrap ? (*lr_session)->extrapolate(a) : (*lr_session)->interpolate(a);
                    if (!out && restarted_at_cut(**lr_session)) {
                        // Frame generation took the pair for a scene cut: the newer or older input,
                        // as `repeat` and eval's interp / extrap do.
                        lr_frame = capture::decode_color(cap.format,
                                                         cap.inputs[extrap || o.alpha > 0.5f ? i : i - 1]);
                        lr_cut = true;
                    } else if (!out) {
                        return out.error();
                    } else {
                        lr_frame = std::move((*out)[0].color);
                    }
                }
                if (lr_cut) ++score.scene_cuts;
                img = spatial_upscale(*lr_frame, out_w, out_h, resample_of(m), 0.f, 0.f);
            }
            FGSR_TRY(score_image(score, img, cap.hr_ground_truth[k]));
            if (o.out) FGSR_TRY(capture::write_png(*o.out / m / fmt::format("{:04d}.png", k + 1), img));
        }
        if (o.out)
            FGSR_TRY(capture::write_png(*o.out / "reference" / fmt::format("{:04d}.png", k + 1),
                                        cap.hr_ground_truth[k]));
    }
    finish_means(rep);
    if (o.out) FGSR_TRY(write_metrics_json(rep, *o.out));
    return rep;
}

} // namespace fgsr::cli
