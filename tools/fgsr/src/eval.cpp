#include <fgsr/cli/eval.hpp>

#include <fgsr/cli/bench.hpp> // median
#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/eval_motion.hpp>

#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/color.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>

namespace fgsr::cli {

namespace {

// Engine passes in pipeline order: fused ("generate") or separate.
constexpr const char* kPassOrder[] = {"denoise",     "classify", "sr",     "splat", "generate",
                                      "generate_sr", "refine",   "disocc", "warp",  "blend"};

ImageRGBA lerp(const ImageRGBA& a, const ImageRGBA& b, float t) {
    ImageRGBA out = a;
    for (size_t i = 0; i < out.rgba.size(); ++i) out.rgba[i] = a.rgba[i] + (b.rgba[i] - a.rgba[i]) * t;
    return out;
}

bool is_engine_method(const std::string& m) {
    return m == "fgsr" || m == "linear" || is_colour_method(m);
}

// Pass names of a score: the pipeline order first, then any other (e.g. the motion passes of a
// colour-only session) in name order.
std::vector<std::string> pass_names(const MethodScore& s) {
    std::vector<std::string> out;
    for (const char* p : kPassOrder)
        if (s.pass_ms.count(p)) out.push_back(p);
    for (const auto& [name, ms] : s.pass_ms)
        if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    return out;
}

Result<capture::Capture> load_capture(const EvalOptions& o) {
    if (o.preloaded) return *o.preloaded;
    return load_eval_capture(o);
}

} // namespace

Result<capture::Capture> load_eval_capture(const EvalOptions& o, size_t max_frames) {
    return load_capture_spec(o.capture, o.prefer_lr, max_frames);
}

Result<void> evaluate_at_half_rate(capture::Capture& cap, bool progress, const char* note) {
    if (cap.ground_truth_kind != capture::GroundTruth::consecutive) return {};
    if (progress) std::fprintf(stderr, "%s\n", note);
    auto half = capture::make_half_rate(cap);
    if (!half) return half.error();
    cap = std::move(*half);
    return {};
}

EvalMode parse_eval_mode(const std::string& m) {
    return m == "extrap" ? EvalMode::extrap
           : m == "sr"   ? EvalMode::sr
           : m == "isr"  ? EvalMode::isr
           : m == "esr"  ? EvalMode::esr
                         : EvalMode::interp;
}

Result<void> check_alpha(float alpha, bool extrapolate) {
    if (!std::isfinite(alpha) || alpha <= 0.f || alpha > 1.f || (!extrapolate && alpha >= 1.f))
        return make_error(Errc::invalid_argument,
                          fmt::format("alpha {} is outside {}", alpha, extrapolate ? "(0, 1]" : "(0, 1)"));
    return {};
}

std::vector<size_t> halfway_targets(const std::vector<capture::Frame>& inputs, size_t references,
                                    bool extrapolate, int max_frames) {
    std::vector<size_t> targets;
    for (size_t k = extrapolate ? 1 : 0; k + 1 < inputs.size() && k < references; ++k)
        if (!inputs[extrapolate ? k : k + 1].reset) targets.push_back(k);
    if (max_frames > 0 && targets.size() > size_t(max_frames)) targets.resize(size_t(max_frames));
    return targets;
}

std::vector<size_t> skip_first(std::vector<size_t> targets, int skip, int max_frames) {
    targets.erase(targets.begin(),
                  targets.begin() + std::min<ptrdiff_t>(std::max(skip, 0), ptrdiff_t(targets.size())));
    if (max_frames > 0 && targets.size() > size_t(max_frames)) targets.resize(size_t(max_frames));
    return targets;
}

Result<void> score_image(MethodScore& score, const ImageRGBA& image, const ImageRGBA& reference) {
    auto p = capture::psnr(image, reference);
    if (!p) return p.error();
    auto s = capture::ssim(image, reference);
    if (!s) return s.error();
    score.psnr.push_back(*p);
    score.ssim.push_back(*s);
    return {};
}

void add_timing(MethodScore& score, const GeneratedFrame& frame) {
    score.mean_ms += frame.gpu_ms;
    score.ms_samples.push_back(frame.gpu_ms);
    // One sample per pass and frame: a pass that ran more than once for the frame (colour_agree's
    // two fields) counts its runs' sum, as fgsrd's telemetry records it (fgsr_pass_record.runs).
    std::map<std::string, double> per_frame;
    for (const PassTiming& p : frame.passes) per_frame[p.name] += p.ms;
    for (const auto& [name, ms] : per_frame) {
        score.pass_ms[name] += ms;
        score.pass_samples[name].push_back(ms);
    }
    for (const PassTiming& p : frame.passes) {
        if (p.tiles_total == 0) continue;
        score.pass_tiles[p.name].first += p.tiles_skipped;
        score.pass_tiles[p.name].second += p.tiles_total;
    }
}

void finish_means(EvalReport& report) {
    for (auto& [name, s] : report.methods) {
        const double n = double(s.psnr.size());
        for (double v : s.psnr) s.mean_psnr += v / n;
        for (double v : s.ssim) s.mean_ssim += v / n;
        if (!s.ms_samples.empty()) {
            s.mean_ms /= double(s.ms_samples.size());
            s.median_ms = median(s.ms_samples);
        }
        for (auto& [pass, ms] : s.pass_ms) ms /= double(std::max<size_t>(s.pass_samples[pass].size(), 1));
        for (double v : s.epe) s.mean_epe += v / double(s.epe.size());
    }
}

Result<Engine*> eval_engine(const EvalOptions& o, std::unique_ptr<Engine>& owned, EvalReport& report) {
    if (!o.engine && !owned) {
        auto e = Engine::create(o.device);
        if (!e) return e.error();
        owned = std::move(*e);
    }
    Engine* e = o.engine ? o.engine : owned.get();
    report.device = e->device_name();
    return e;
}

Result<std::map<std::string, std::unique_ptr<Session>>>
make_sessions(const EvalOptions& o, const FrameFormat& format, const SessionParams& params_for,
              std::unique_ptr<Engine>& engine, EvalReport& report) {
    std::map<std::string, std::unique_ptr<Session>> sessions;
    for (const std::string& m : o.methods) {
        std::optional<Params> p = params_for(m);
        if (!p) continue;
        auto e = eval_engine(o, engine, report);
        if (!e) return e.error();
        auto s = (*e)->create_session(is_colour_method(m) ? colour_only(format) : format, *p);
        if (!s) return s.error();
        sessions[m] = std::move(*s);
    }
    return sessions;
}

Result<EvalReport> run_eval(const EvalOptions& o) {
    if (o.vectors_from && o.mode != EvalMode::interp && o.mode != EvalMode::extrap)
        return make_error(Errc::invalid_argument, "--vectors-from applies to --mode interp and extrap only");
    if (o.mode == EvalMode::sr) {
        if (o.progress) std::fprintf(stderr, "[eval] loading %s\n", o.capture.c_str());
        auto loaded = load_capture(o);
        if (!loaded) return loaded.error();
        return run_eval_sr(o, std::move(*loaded));
    }
    if (o.mode == EvalMode::isr || o.mode == EvalMode::esr) {
        if (o.progress) std::fprintf(stderr, "[eval] loading %s\n", o.capture.c_str());
        auto loaded = load_capture(o);
        if (!loaded) return loaded.error();
        return run_eval_joint(o, std::move(*loaded));
    }
    for (const std::string& m : o.methods)
        if (!is_engine_method(m) && m != "blend" && m != "repeat")
            return make_error(Errc::invalid_argument,
                              "unknown method '" + m +
                                  "' (methods: fgsr, fgsr-colour, linear, blend, repeat)");
    const bool extrap = o.mode == EvalMode::extrap;
    FGSR_TRY(check_alpha(o.alpha, extrap));

    if (o.progress) std::fprintf(stderr, "[eval] loading %s\n", o.capture.c_str());
    auto loaded = load_capture(o);
    if (!loaded) return loaded.error();
    capture::Capture cap = std::move(*loaded);
    FGSR_TRY(evaluate_at_half_rate(cap, o.progress));
    // Ground truth exists halfway between inputs only.
    if (std::abs(o.alpha - 0.5f) > 1e-6f)
        return make_error(Errc::invalid_argument,
                          fmt::format("capture '{}' has ground truth only halfway between inputs; "
                                      "use --alpha 0.5",
                                      cap.name));
    const std::vector<size_t> targets = skip_first(
        halfway_targets(cap.inputs, cap.ground_truth.size(), extrap, 0), o.skip_targets, o.max_frames);
    if (targets.empty())
        return make_error(Errc::empty_input, "capture '" + cap.name + "' has too few frames to evaluate");

    // Submit inputs in order; after input k+1 (interp) or k (extrap) generate the target's frame.
    const size_t last_input = targets.back() + (extrap ? 0 : 1);
    std::optional<CaptureVectors> own_vectors; // the capture's, when --vectors-from replaced them
    if (o.vectors_from) {
        auto own = replace_vectors_from(cap, *o.vectors_from, last_input);
        if (!own) return own.error();
        own_vectors = std::move(*own);
    }
    VectorReference reference(own_vectors ? own_vectors->format : cap.format);
    // Vectors that are not the capture's are scored (EPE) and, with --out, written: estimated ones,
    // --vectors-from's, and the corrected ones of --correct-vectors.
    auto scores_vectors = [&](const std::string& m) {
        return is_engine_method(m) && (is_colour_method(m) || o.vectors_from || o.params.correct_vectors);
    };
    const bool any_scores_vectors = std::any_of(o.methods.begin(), o.methods.end(), scores_vectors);

    EvalReport rep = new_report(cap, extrap ? "extrap" : "interp", o.alpha, targets.size(), cap.format.width,
                                cap.format.height, o.methods);

    std::unique_ptr<Engine> engine;
    auto made = make_sessions(
        o, cap.format,
        [&](const std::string& m) -> std::optional<Params> {
            if (!is_engine_method(m)) return std::nullopt;
            Params p = o.params;
            if (m == "linear") p.motion = MotionModel::linear;
            return p;
        },
        engine, rep);
    if (!made) return made.error();
    auto& sessions = *made;

    if (o.out) FGSR_TRY(make_out_dirs(*o.out, o.methods));

    size_t next_target = 0;
    double ingest_sum = 0;
    size_t ingest_count = 0;
    for (size_t i = 0; i <= last_input; ++i) {
        for (auto& [name, s] : sessions) {
            FGSR_TRY(s->submit(session_view(s->format(), cap.inputs[i].view())));
            ingest_sum += s->last_ingest_ms();
            ++ingest_count;
        }
        if (any_scores_vectors) { // the capture's vectors of input i, then each method's against them
            FGSR_TRY(
                reference.add_frame(reference_view(cap.inputs[i], own_vectors ? &*own_vectors : nullptr, i)));
            // With --out, the vectors scored (for --vectors-from and inspection), read once.
            for (auto& [name, s] : sessions) {
                if (!scores_vectors(name)) continue;
                std::vector<float> mv;
                FGSR_TRY(reference.score(*s, rep.methods[name], o.out ? &mv : nullptr));
                if (!mv.empty()) FGSR_TRY(write_vectors(*o.out / name, i, cap.format.width, cap.format.height, mv));
            }
            if (o.out && reference.scorable())
                FGSR_TRY(write_vectors(*o.out / "reference", i, cap.format.width, cap.format.height,
                                       reference.vectors(), reference.visible()));
        }
        if (next_target >= targets.size()) break;
        const size_t k = targets[next_target];
        const size_t newest = extrap ? k : k + 1;
        if (i != newest) continue;
        ++next_target;
        if (o.progress)
            std::fprintf(stderr, "[eval] %s %s: frame %zu/%zu\n", cap.name.c_str(), rep.mode.c_str(),
                         next_target, targets.size());
        const ImageRGBA& gt = cap.ground_truth[k];
        const ImageRGBA i1 = capture::decode_color(cap.format, cap.inputs[newest]);
        const ImageRGBA i0 = capture::decode_color(cap.format, cap.inputs[newest - 1]);
        for (const std::string& m : o.methods) {
            ImageRGBA img;
            MethodScore& score = rep.methods[m];
            if (is_engine_method(m)) {
                const float a[] = {o.alpha};
                auto out = extrap ? sessions[m]->extrapolate(a) : sessions[m]->interpolate(a);
                if (!out && restarted_at_cut(*sessions[m])) {
                    ++score.scene_cuts;
                    img = extrap || o.alpha > 0.5f ? i1 : i0; // as `repeat`
                } else if (!out) {
                    return out.error();
                } else {
                    // A colour-only frame (or one with --correct-vectors) costs the motion
                    // estimation of its newest input too (none is timed otherwise).
                    add_timing(score, with_motion_timings((*out)[0], sessions[m]->last_motion_timings()));
                    img = std::move((*out)[0].color);
                }
            } else if (m == "blend") {
                img = extrap ? i1 : lerp(i0, i1, o.alpha);
            } else { // repeat: the nearest input in time
                img = extrap || o.alpha > 0.5f ? i1 : i0;
            }
            FGSR_TRY(score_image(score, img, gt));
            if (o.out) {
                const std::string stem = fmt::format("{:04d}", k + 1);
                FGSR_TRY(capture::write_png(*o.out / m / (stem + ".png"), img));
                FGSR_TRY(capture::write_exr(*o.out / m / (stem + ".exr"), img));
            }
        }
        if (o.out) FGSR_TRY(capture::write_png(*o.out / "reference" / fmt::format("{:04d}.png", k + 1), gt));
    }
    rep.ingest_ms = ingest_count ? ingest_sum / double(ingest_count) : 0;
    // The input's aliasing measure, which decides WarpKernel::automatic.
    if (o.progress)
        for (const std::string& m : o.methods)
            if (is_engine_method(m)) {
                const float a = sessions[m]->input_aliasing();
                if (a < 0.f)
                    std::fprintf(stderr, "[eval] %s %s: input aliasing not measured\n", cap.name.c_str(),
                                 rep.mode.c_str());
                else
                    std::fprintf(stderr, "[eval] %s %s: input aliasing %.2f (%s)\n", cap.name.c_str(),
                                 rep.mode.c_str(), a,
                                 measures_antialiased(a) ? "antialiased: cubic warp in interpolation"
                                                         : "aliased: bilinear warp");
                break;
            }
    finish_means(rep);
    if (o.out) FGSR_TRY(write_metrics_json(rep, *o.out));
    return rep;
}

Result<void> make_out_dirs(const std::filesystem::path& dir, const std::vector<std::string>& methods) {
    std::error_code ec;
    for (const std::string& m : methods) std::filesystem::create_directories(dir / m, ec);
    std::filesystem::create_directories(dir / "reference", ec);
    if (ec) return make_error(Errc::io, "cannot create " + dir.string() + ": " + ec.message());
    return {};
}

Result<void> write_metrics_json(const EvalReport& r, const std::filesystem::path& dir) {
    const std::filesystem::path path = dir / "metrics.json";
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return make_error(Errc::io, "cannot write " + path.string());
    const std::string js = report_json(r, true);
    const bool ok = std::fwrite(js.data(), 1, js.size(), f) == js.size();
    if (std::fclose(f) != 0 || !ok) return make_error(Errc::io, "cannot write " + path.string());
    return {};
}

EvalReport new_report(const capture::Capture& cap, std::string mode, float alpha, size_t frames,
                      uint32_t width, uint32_t height, std::vector<std::string> methods) {
    EvalReport rep;
    rep.capture = cap.name;
    rep.mode = std::move(mode);
    rep.alpha = alpha;
    rep.frames = frames;
    rep.composed_vectors = cap.composed_vectors;
    rep.width = width;
    rep.height = height;
    rep.method_order = std::move(methods);
    return rep;
}

std::string report_json(const EvalReport& r, bool per_frame) {
    nlohmann::ordered_json j;
    j["capture"] = r.capture;
    j["mode"] = r.mode;
    j["alpha"] = r.alpha;
    j["frames"] = r.frames;
    j["composed_vectors"] = r.composed_vectors;
    j["width"] = r.width;
    j["height"] = r.height;
    j["device"] = r.device;
    j["ingest_ms"] = r.ingest_ms;
    if (r.static_frames > 0) j["static_frames"] = r.static_frames;
    nlohmann::ordered_json methods = nlohmann::ordered_json::object();
    for (const std::string& m : r.method_order) {
        const MethodScore& s = r.methods.at(m);
        nlohmann::ordered_json jm;
        jm["psnr"] = s.mean_psnr;
        jm["ssim"] = s.mean_ssim;
        jm["ms"] = s.mean_ms;
        jm["ms_median"] = s.median_ms;
        if (s.scores_vectors)
            jm["epe"] = s.epe.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(s.mean_epe);
        if (is_engine_method(m)) jm["scene_cuts"] = s.scene_cuts;
        if (s.stability_std >= 0) jm["stability_std"] = s.stability_std;
        if (!s.pass_ms.empty()) {
            nlohmann::ordered_json passes = nlohmann::ordered_json::object();
            for (const std::string& p : pass_names(s)) passes[p] = s.pass_ms.at(p);
            jm["pass_ms"] = passes;
        }
        if (!s.pass_tiles.empty()) { // share of the tiles each pass skipped, over every frame
            nlohmann::ordered_json skipped = nlohmann::ordered_json::object();
            for (const char* p : kPassOrder)
                if (s.pass_tiles.count(p) && p != std::string("classify"))
                    skipped[p] = double(s.pass_tiles.at(p).first) / double(s.pass_tiles.at(p).second);
            jm["skipped_tiles"] = skipped;
        }
        if (per_frame) {
            jm["psnr_per_frame"] = s.psnr;
            jm["ssim_per_frame"] = s.ssim;
            if (s.scores_vectors) jm["epe_per_frame"] = s.epe;
        }
        methods[m] = jm;
    }
    j["methods"] = methods;
    return j.dump(2) + "\n";
}

std::string report_table(const EvalReport& r) {
    std::string s =
        fmt::format("capture {} ({}x{}), mode {}, alpha {}, {} frames{}{}\n", r.capture, r.width, r.height,
                    r.mode, r.alpha, r.frames, r.composed_vectors ? ", composed two-frame vectors" : "",
                    r.device.empty() ? "" : ", device " + r.device);
    s += fmt::format("{:<13} {:>9} {:>7} {:>9} {:>9} {:>8}   per pass (ms, means)\n", "method", "PSNR dB",
                     "SSIM", "GPU ms", "median", "EPE px");
    for (const std::string& m : r.method_order) {
        const MethodScore& ms = r.methods.at(m);
        std::string passes;
        for (const std::string& p : pass_names(ms)) passes += fmt::format("{} {:.2f}  ", p, ms.pass_ms.at(p));
        const std::string epe = !ms.scores_vectors ? ""
                                : ms.epe.empty()   ? "-"
                                                   : fmt::format("{:.3f}", ms.mean_epe);
        s += fmt::format("{:<13} {:>9.2f} {:>7.4f} {:>9.2f} {:>9.2f} {:>8}   {}\n", m, ms.mean_psnr,
                         ms.mean_ssim, ms.mean_ms, ms.median_ms, epe, passes);
        std::string skipped;
        for (const char* p : kPassOrder)
            if (ms.pass_tiles.count(p) && p != std::string("classify"))
                skipped += fmt::format("{} {:.1f}%  ", p,
                                       100.0 * double(ms.pass_tiles.at(p).first) /
                                           double(ms.pass_tiles.at(p).second));
        if (!skipped.empty()) s += fmt::format("{:<13} skipped tiles: {}\n", "", skipped);
        if (ms.scene_cuts > 0)
            s += fmt::format(
                "{:<13} scene cuts detected before {} of the {} frames (the nearest input shown)\n", "",
                ms.scene_cuts, ms.psnr.size());
    }
    if (r.ingest_ms > 0) s += fmt::format("ingest: {:.2f} ms per input frame\n", r.ingest_ms);
    if (r.static_frames > 0) {
        s += fmt::format(
            "temporal stability (mean per-pixel std of display values, {} static frames, last input "
            "repeated, jitter moving):\n ",
            r.static_frames);
        for (const std::string& m : r.method_order)
            if (r.methods.at(m).stability_std >= 0)
                s += fmt::format(" {} {:.5f}", m, r.methods.at(m).stability_std);
        s += "\n";
    }
    return s;
}

} // namespace fgsr::cli
