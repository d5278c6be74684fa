// The in-process feeder of the numerical stress cases (run_on_engine, fgsr/capture/stress.hpp): each
// step handed to an fgsr::Engine session, outputs checked (stress_checks.hpp) and, for small
// frames, compared with the CPU reference (fgsr/engine/reference.hpp).
#include "stress_internal.hpp"

#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/stress_checks.hpp>
#include <fgsr/engine/color.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

namespace fgsr::stress {

namespace {

using namespace detail;

// Why generation is refused after a reset (Session::interpolate / extrapolate).
constexpr const char* kResetReason = "needs two submitted frames";

struct CpuState {
    ref::InternalFrame f0, f1;
    size_t frames = 0; // submitted since the last reset
    std::vector<glm::vec4> hr_prev, hr_new;
    bool hr_valid = false;
    float jitter_x = 0, jitter_y = 0;
};

class Runner {
  public:
    Runner(Engine& e, const Case& c, CaseResult& r) : engine_(e), c_(c), r_(r), checks_(r) {}

    bool fail(std::string why) { return checks_.fail(std::move(why)); }
    bool check_values(std::span<const float> v, const std::string& what) {
        return checks_.check_values(v, what);
    }
    bool check_image(const ImageRGBA& img, const std::string& what) { return checks_.check_image(img, what); }
    bool check_cpu(const std::vector<glm::vec4>& v, const std::string& what) {
        return check_values(std::span<const float>(&v[0][0], v.size() * 4), what + " (CPU reference)");
    }

    bool session_rejected() {
        auto s = engine_.create_session(c_.format, c_.params);
        if (s)
            return fail("create_session accepted; expected a rejection mentioning '" + c_.reject_session +
                        "'");
        const Error& e = s.error();
        r_.rejections.push_back(std::string(errc_name(e.code)) + ": " + e.message);
        if (!contains_nocase(e.message, c_.reject_session))
            return fail("rejection reason '" + e.message + "' does not mention '" + c_.reject_session + "'");
        // The engine keeps serving: a good session, two frames, one interpolation.
        auto good = engine_.create_session(format_of(16, 16));
        if (!good) return fail("a good session after the rejection failed: " + good.error().message);
        for (int k = 0; k < 2; ++k) {
            Frame fr = encode((*good)->format(), content(16, 16, k, {1.f, 1.f}));
            auto sub = (*good)->submit(fr.view());
            if (!sub) return fail("a good frame after the rejection failed: " + sub.error().message);
        }
        const float a = 0.5f;
        auto g = (*good)->interpolate(std::span<const float>(&a, 1));
        if (!g) return fail("interpolation after the rejection failed: " + g.error().message);
        return check_image((*g)[0].color, "interpolation after the rejection");
    }

    bool run(const RunOptions& options) {
        if (!c_.reject_session.empty()) return session_rejected();
        auto created = engine_.create_session(c_.format, c_.params);
        if (!created) return fail("create_session failed: " + created.error().message);
        Session& s = **created;
        const FrameFormat& f = c_.format;
        const bool sr = s.output_width() != f.width || s.output_height() != f.height;
        const bool cpu = c_.cpu_reference && size_t(f.width) * f.height <= (1u << 14);
        std::vector<float> lut;
        if (cpu && sr) {
            Lut l = c_.params.lut.size() == kLutSize ? Lut{c_.params.scale, c_.params.lut}
                                                     : default_lut(c_.params.scale);
            force_identity_phase(l);
            lut = std::move(l.weights);
        }

        for (size_t i = 0; i < c_.step_count; ++i) {
            if (options.progress && c_.step_count > options.progress_every && i % options.progress_every == 0)
                options.progress(c_.name + ": step " + std::to_string(i) + "/" +
                                 std::to_string(c_.step_count));
            const Step st = c_.step(i);
            const std::string where = step_where(i, st.op);
            ++r_.steps_run;
            std::optional<Error> err;
            std::vector<ImageRGBA> images;
            switch (st.op) {
            case Op::submit: {
                auto rs = s.submit(st.frame.view());
                if (!rs) err = rs.error();
                break;
            }
            case Op::interpolate:
            case Op::extrapolate: {
                auto rg = st.op == Op::interpolate ? s.interpolate(st.alphas) : s.extrapolate(st.alphas);
                if (!rg)
                    err = rg.error();
                else
                    for (GeneratedFrame& g : *rg) images.push_back(std::move(g.color));
                break;
            }
            case Op::super_resolve: {
                auto rs = s.super_resolved();
                if (!rs)
                    err = rs.error();
                else
                    images.push_back(std::move(rs->color));
                break;
            }
            }
            if (st.across_cut) {
                if (!check_across_cut(s, err, images, where)) return false;
                continue;
            }
            if (!st.reject.empty()) {
                if (!err)
                    return fail(where + " was accepted; expected a rejection mentioning '" + st.reject + "'");
                r_.rejections.push_back(std::string(errc_name(err->code)) + ": " + err->message);
                if (!contains_nocase(err->message, st.reject))
                    return fail(where + ": rejection reason '" + err->message + "' does not mention '" +
                                st.reject + "'");
                continue;
            }
            if (err && st.cut_allowed &&
                (contains_nocase(err->message, kResetReason) || s.frames_submitted() == 1)) {
                r_.rejections.push_back(std::string(errc_name(err->code)) + ": " + err->message +
                                        " (content taken for a scene cut)");
                continue;
            }
            if (err) return fail(where + " failed: " + errc_name(err->code) + ": " + err->message);
            for (size_t k = 0; k < images.size(); ++k)
                if (!check_image(images[k], where + " output " + std::to_string(k))) return false;

            if (!checks_.check_repeat_and_drift(st, images, where)) return false;

            if (st.op == Op::submit && cpu && !step_cpu_submit(s, st.frame, sr, lut, where)) return false;
            // Colour-only sessions (and corrected vectors): the estimated or corrected vectors and the
            // depth proxy of every frame are finite.
            if (st.op == Op::submit && !cpu && (!f.has_vectors || !f.has_depth || c_.params.correct_vectors) &&
                !check_ingested(s, where))
                return false;
            if ((st.op == Op::interpolate || st.op == Op::extrapolate) && cpu &&
                !step_cpu_generate(s, st, images, sr, lut, where))
                return false;
        }
        return checks_.check_min_drift(c_.min_drift_db);
    }

    // Step::across_cut: refused as after a reset, or every output is one of the stored frames.
    bool check_across_cut(Session& s, const std::optional<Error>& err, const std::vector<ImageRGBA>& images,
                          const std::string& where) {
        constexpr const char* kReset = kResetReason;
        if (err) {
            r_.rejections.push_back(std::string(errc_name(err->code)) + ": " + err->message);
            // Refused because the session restarted at the cut: the reset's reason, or a session
            // that counts the frame after the cut as its first.
            if (!contains_nocase(err->message, kReset) && s.frames_submitted() != 1)
                return fail(where + " across the scene cut failed: " + err->message + " with " +
                            std::to_string(s.frames_submitted()) + " frames submitted (expected success, '" +
                            kReset + "' or a restart at the cut)");
            return true;
        }
        std::vector<Session::InternalFrameData> frames;
        for (int which : {0, 1}) {
            auto fr = s.read_frame(which);
            if (!fr) return fail(where + ": read_frame: " + fr.error().message);
            frames.push_back(std::move(*fr));
        }
        for (size_t k = 0; k < images.size(); ++k) {
            if (!check_image(images[k], where + " output " + std::to_string(k))) return false;
            double worst[2] = {0, 0};
            for (int which : {0, 1}) {
                const std::vector<float>& ref = frames[size_t(which)].color;
                if (ref.size() != images[k].rgba.size()) {
                    worst[which] = INFINITY;
                    continue;
                }
                for (size_t i = 0; i < ref.size(); i += 4)
                    for (size_t ch = 0; ch < 3; ++ch)
                        worst[which] =
                            std::max(worst[which], std::abs(double(images[k].rgba[i + ch]) - ref[i + ch]) /
                                                       std::max(1.0, std::abs(double(ref[i + ch]))));
            }
            if (std::min(worst[0], worst[1]) > 1e-3)
                return fail(where + " output " + std::to_string(k) +
                            " across the scene cut is neither frame (largest relative difference " +
                            std::to_string(worst[0]) + " to frame 0, " + std::to_string(worst[1]) +
                            " to frame 1): a warp or blend across the cut, and no reset");
        }
        return true;
    }

    // The newest ingested frame (with a colour-only session's estimated vectors and depth proxy) is
    // finite, its depth positive.
    bool check_ingested(Session& s, const std::string& where) {
        auto in = s.read_frame(1);
        if (!in) return fail(where + ": read_frame: " + in.error().message);
        if (!check_values(in->color, where + " ingested colour") ||
            !check_values(in->depth, where + " ingested depth") ||
            !check_values(in->mv, where + " ingested vectors"))
            return false;
        for (float d : in->depth)
            if (!(d > 0.f)) return fail(where + ": ingested depth " + std::to_string(d) + " is not positive");
        return true;
    }

    // The ingested frame (GPU) is finite with positive depth; the CPU reference runs ingest and
    // SR on the same frame and its outputs must be finite too.
    bool step_cpu_submit(Session& s, const Frame& fr, bool sr, const std::vector<float>& lut,
                         const std::string& where) {
        auto in = s.read_frame(1);
        if (!in) return fail(where + ": read_frame: " + in.error().message);
        if (!check_values(in->color, where + " ingested colour") ||
            !check_values(in->depth, where + " ingested depth") ||
            !check_values(in->mv, where + " ingested vectors"))
            return false;
        for (float d : in->depth)
            if (!(d > 0.f)) return fail(where + ": ingested depth " + std::to_string(d) + " is not positive");
        const FrameFormat& f = c_.format;
        bool restart = fr.reset || cs_.frames == 0;
        // The engine removes the jitter from vectors that contain it (Session::submit).
        const glm::vec2 offset = c_.params.mvs_contain_jitter && !restart
                                     ? glm::vec2(cs_.jitter_x - fr.jitter_x, cs_.jitter_y - fr.jitter_y)
                                     : glm::vec2(0.f);
        ref::InternalFrame cur = ref::ingest(f, fr.view(), offset);
        gpu::IngestParams ip = params::ingest_params(f, cur.has_mv);
        // The stage reads `cur` (offset applied), not the raw planes; the edge rule the previous
        // frame as the session keeps it (denoised in SR sessions).
        params::set_dilate(ip, f, c_.params, !restart);
        ref::dilate(cur, restart ? nullptr : &cs_.f1, ip);
        if (sr && c_.params.denoise) {
            // The pre-filter with the GPU's range; its estimate must agree with the CPU's up to a
            // histogram bin (log2 rounding at bin edges).
            const ref::DenoiseParams dp = params::denoise_params(f, c_.params);
            const NoiseEstimate cpu = ref::noise_level(cur, dp), gpu = s.last_noise_estimate();
            if (!(std::isfinite(gpu.sigma) && std::isfinite(gpu.range)))
                return fail(where + ": noise estimate is not finite");
            if (cpu.sigma > 0.f && !(std::abs(std::log2(gpu.sigma / cpu.sigma)) <= 0.126f))
                return fail(where + ": noise estimate " + std::to_string(gpu.sigma) + " (GPU) against " +
                            std::to_string(cpu.sigma) + " (CPU)");
            cur.color = ref::denoise(cur, dp, gpu.range);
        }
        // Ingest's cut stage (sessions with vectors, Params::vector_cuts) on the frame as filtered:
        // the share of blocks the frame's vectors leave unmatched must be finite and, on CPU
        // devices, the GPU's (within one block: a SAD at the threshold may round either way). A cut
        // the session found restarts the reference too, and the frame keeps no vectors.
        if (c_.params.vector_cuts && cur.has_mv && !restart && f.has_vectors && !c_.params.correct_vectors) {
            const float gpu = s.last_cut_share();
            if (!(gpu >= 0.f && gpu <= 1.f))
                return fail(where + ": the cut stage's share " + std::to_string(gpu) + " is not in [0, 1]");
            const float cpu = ref::cut_share(ref::cut_stage(cur, cs_.f1));
            const float block = 1.f / float(ref::cut_blocks(f.width, f.height));
            if (engine_.is_cpu_device() && !(std::abs(gpu - cpu) <= block + 1e-6f))
                return fail(where + ": the cut stage's share " + std::to_string(gpu) + " (GPU) against " +
                            std::to_string(cpu) + " (CPU)");
            if (s.last_scene_cut()) {
                restart = true;
                cur.has_mv = false;
            }
        }
        if (fr.reset) cur.has_mv = false; // an announced cut keeps no vectors either
        if (sr) {
            // The session's measure of its input decides Params::sr_disagree and the spatial
            // upsample's kernel (shaders/sr.h steps 5, 6).
            const ref::SrParams p =
                params::sr_params(f, c_.params, s.output_width(), s.output_height(), fr.jitter_x, fr.jitter_y,
                                  !restart && cs_.hr_valid && cur.has_mv, params::input_measure(s));
            if (cs_.hr_new.empty()) cs_.hr_new.assign(size_t(p.hr_width) * p.hr_height, glm::vec4(0.f));
            const std::vector<float>& prev_depth = cs_.frames > 0 ? cs_.f1.depth : cur.depth;
            std::vector<glm::vec4> out = ref::super_resolve(cur, prev_depth, cs_.hr_new, p, lut);
            if (!check_cpu(out, where + " SR")) return false;
            auto gpu = s.super_resolved();
            if (!gpu) return fail(where + ": super_resolved: " + gpu.error().message);
            compare(gpu->color, out);
            cs_.hr_prev = std::move(cs_.hr_new);
            cs_.hr_new = std::move(out);
            cs_.hr_valid = true;
        }
        cs_.f0 = std::move(cs_.f1);
        cs_.f1 = std::move(cur);
        cs_.frames = restart ? 1 : cs_.frames + 1;
        cs_.jitter_x = fr.jitter_x;
        cs_.jitter_y = fr.jitter_y;
        return true;
    }

    bool step_cpu_generate(Session& s, const Step& st, const std::vector<ImageRGBA>& images, bool sr,
                           const std::vector<float>& lut, const std::string& where) {
        if (cs_.frames < 2 || images.size() != st.alphas.size()) return true;
        size_t k = 0;
        const bool extrap = st.op == Op::extrapolate;
        for (float a : st.alphas) {
            const ref::GenParams g = params::gen_params(c_.format, c_.params, a, extrap, cs_.f0.has_mv,
                                                        cs_.f1.has_mv, params::input_measure(s));
            std::vector<glm::vec4> out;
            if (sr) {
                const ref::Splat sp = ref::splat(cs_.f0, cs_.f1, g);
                const ref::SrParams p =
                    params::generate_sr_params(c_.format, c_.params, s.output_width(), s.output_height(),
                                               cs_.jitter_x, cs_.jitter_y, extrap, params::input_measure(s));
                out = ref::generate_sr(cs_.f0, cs_.f1, sp, extrap ? cs_.hr_new : cs_.hr_prev, g, p, lut);
            } else {
                out = ref::generate(cs_.f0, cs_.f1, g);
            }
            if (!check_cpu(out, where + " alpha " + std::to_string(a))) return false;
            compare(images[k++], out);
        }
        return true;
    }

    // Largest difference between a GPU output and the CPU reference, relative to max(1, |ref|).
    void compare(const ImageRGBA& gpu, const std::vector<glm::vec4>& cpu) {
        if (gpu.rgba.size() != cpu.size() * 4) return;
        double worst = r_.max_cpu_difference.value_or(0.0);
        for (size_t i = 0; i < cpu.size(); ++i)
            for (int ch = 0; ch < 4; ++ch) {
                const double ref = cpu[i][ch], got = gpu.rgba[4 * i + size_t(ch)];
                worst = std::max(worst, std::abs(got - ref) / std::max(1.0, std::abs(ref)));
            }
        r_.max_cpu_difference = worst;
    }

  private:
    Engine& engine_;
    const Case& c_;
    CaseResult& r_;
    CaseChecks checks_;
    CpuState cs_;
};

} // namespace

CaseResult run_on_engine(Engine& engine, const Case& c, const RunOptions& options) {
    CaseResult r;
    r.name = c.name;
    r.checks = c.checks;
    r.pass = true;
    const uint64_t validation_before = engine.validation_errors();
    const auto t0 = std::chrono::steady_clock::now();
    Runner(engine, c, r).run(options);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // On CPU devices (lavapipe) the GPU passes and the reference run the same code on the same
    // inputs: any difference beyond float rounding means the sanitisation diverged.
    constexpr double kCpuTolerance = 1e-3;
    if (engine.is_cpu_device() && r.pass && r.max_cpu_difference && *r.max_cpu_difference > kCpuTolerance) {
        r.pass = false;
        r.failure = "GPU output and CPU reference differ by " + std::to_string(*r.max_cpu_difference) +
                    " (relative), above " + std::to_string(kCpuTolerance);
    }
    if (c.max_seconds > 0 && r.pass && r.seconds > c.max_seconds) {
        r.pass = false;
        r.failure = "the case took " + std::to_string(r.seconds) + " s, more than its bound of " +
                    std::to_string(c.max_seconds) + " s";
    }
    const uint64_t validation = engine.validation_errors() - validation_before;
    if (validation && r.pass) {
        r.pass = false;
        r.failure = std::to_string(validation) + " Vulkan validation errors (see stderr)";
    }
    return r;
}

} // namespace fgsr::stress
