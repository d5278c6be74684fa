// `fgsr eval`: scores generated frames against ground truth, method by method, on the same frames.
#pragma once

#include <fgsr/capture/capture.hpp>
#include <fgsr/engine/engine.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::cli {

enum class EvalMode { interp, extrap, sr, isr, esr };

// "extrap", "sr", "isr", "esr" -> that mode; anything else -> interp (--mode is checked by CLI11).
EvalMode parse_eval_mode(const std::string& name);

struct EvalOptions {
    std::string capture = "builtin"; // a capture directory, or "builtin" (generated synthetic scene)
    EvalMode mode = EvalMode::interp;
    float alpha = 0.5f;
    // fgsr-colour: the engine with the capture's vectors and depth withheld (fgsr/cli/eval_motion.hpp).
    std::vector<std::string> methods{"fgsr", "fgsr-colour", "linear", "blend", "repeat"};
    std::optional<std::filesystem::path> out; // generated frames (EXR + PNG) and metrics.json
    bool json = false;
    bool prefer_lr = false; // Mob-FGSR captures: LR_Inputs instead of HR_Inputs
    int max_frames = 0;     // 0: every frame the capture allows
    // sr: frames of the static stretch the temporal-stability figure is measured over (0: none);
    // see run_eval_sr.
    int static_frames = 16;
    DeviceOptions device;
    Params params; // method `fgsr` runs these as given; `linear` forces MotionModel::linear, the SR
                   // methods fgsr-bilinear / fgsr-bicubic their history resampling
    bool progress = true;
    // interp, extrap, isr, esr: leave out the first targets (e.g. 1: the pair whose frame 0 has no
    // vectors, so uniform acceleration falls back to uniform velocity there); max_frames counts
    // the targets after them.
    int skip_targets = 0;
    // interp / extrap: the vectors of the inputs come from DIR/%04d.flo instead of the capture and
    // the depth is withheld (replace_vectors_from, fgsr/cli/eval_motion.hpp); the engine methods
    // then also report the EPE of those vectors against the capture's.
    std::optional<std::filesystem::path> vectors_from;
    // Not owned; when set, evaluated instead of loading `capture` (must outlive run_eval).
    const capture::Capture* preloaded = nullptr;
    // Not owned; when set, sessions are made on it instead of a new engine (`device` unused).
    Engine* engine = nullptr;
};

struct MethodScore {
    std::vector<double> psnr, ssim; // per generated frame
    double mean_psnr = 0, mean_ssim = 0;
    double mean_ms = 0;                    // engine GPU milliseconds per generated frame (0 for baselines)
    double median_ms = 0;                  // ... their median (one slow frame moves the mean, not this)
    std::map<std::string, double> pass_ms; // mean per pass over the frames it ran for (its runs' sum)
    // Every timed engine call (one per generated frame): total and per-pass GPU milliseconds.
    std::vector<double> ms_samples;
    std::map<std::string, std::vector<double>> pass_samples;
    // Temporal stability (sr): mean per-pixel standard deviation of the display values over the
    // static stretch (capture::TemporalStd); negative when not measured.
    double stability_std = -1;
    // Per pass that classifies tiles (Params::skip_tiles): tiles skipped and tiles in total, summed.
    std::map<std::string, std::pair<uint64_t, uint64_t>> pass_tiles;
    // End-point error of the method's vectors against the capture's, per scored input frame, in
    // pixels (fgsr/cli/eval_motion.hpp); scores_vectors: the method is scored on its vectors
    // (colour-only methods; every engine method with vectors_from).
    std::vector<double> epe;
    double mean_epe = 0;
    bool scores_vectors = false;
    // Engine methods: generated frames the session refused because it detected a scene cut
    // in the newest input (restarted_at_cut, fgsr/cli/eval_motion.hpp); the nearest input is
    // scored in their place and they are not timed.
    size_t scene_cuts = 0;
};

struct EvalReport {
    std::string capture;
    std::string mode;
    float alpha = 0.5f;
    size_t frames = 0;
    bool composed_vectors = false;
    uint32_t width = 0, height = 0;
    std::string device;
    double ingest_ms = 0;     // mean GPU milliseconds of ingest per input frame
    size_t static_frames = 0; // frames the stability figures are measured over (0: none)
    std::vector<std::string> method_order;
    std::map<std::string, MethodScore> methods;
};

Result<EvalReport> run_eval(const EvalOptions& options);

// The capture `options` names ("builtin": the synthetic scene of 11 inputs), at most max_frames
// inputs (capture::kAllFrames: all).
Result<capture::Capture> load_eval_capture(const EvalOptions& options,
                                           size_t max_frames = capture::kAllFrames);

// Frame generation is scored against halfway ground truth: a capture of consecutive frames is
// replaced by its half-rate form (capture::make_half_rate; `note` on stderr when `progress`);
// other captures are left as they are.
Result<void> evaluate_at_half_rate(
    capture::Capture& cap, bool progress,
    const char* note = "[eval] consecutive frames: evaluating at half rate with composed vectors");

// Generated instants lie in (0, 1) between two inputs, in (0, 1] after the last (extrapolation):
// Errc::invalid_argument otherwise.
Result<void> check_alpha(float alpha, bool extrapolate);

// Targets of halfway ground truth: interpolation pair (k, k+1) -> reference k; extrapolation
// pair (k-1, k) -> reference k (instant k + 0.5). Pairs across a scene cut (the second frame has
// reset set) have no target. At most max_frames (0: all).
std::vector<size_t> halfway_targets(const std::vector<capture::Frame>& inputs, size_t references,
                                    bool extrapolate, int max_frames);
// targets without its first `skip` entries, then at most max_frames of them (0: all).
std::vector<size_t> skip_first(std::vector<size_t> targets, int skip, int max_frames);

// Shared by every mode: scores one generated image against its reference (PSNR and SSIM appended
// to `score`), adds a generated frame's engine timings, and turns the sums into means.
Result<void> score_image(MethodScore& score, const ImageRGBA& image, const ImageRGBA& reference);
void add_timing(MethodScore& score, const GeneratedFrame& frame);
void finish_means(EvalReport& report);
// The engine to make sessions on: o.engine, else `owned` (created from o.device on first use).
Result<Engine*> eval_engine(const EvalOptions& o, std::unique_ptr<Engine>& owned, EvalReport& report);
// One engine session per engine method of `methods` (those `params_for` returns a value for);
// colour-only methods get a session of colour_only(format).
using SessionParams = std::function<std::optional<Params>(const std::string& method)>;
Result<std::map<std::string, std::unique_ptr<Session>>>
make_sessions(const EvalOptions& o, const FrameFormat& format, const SessionParams& params_for,
              std::unique_ptr<Engine>& engine, EvalReport& report);
// Mode sr on a loaded capture (eval_sr.cpp).
Result<EvalReport> run_eval_sr(const EvalOptions& options, capture::Capture capture);
// Modes isr / esr on a loaded capture (eval_sr.cpp).
Result<EvalReport> run_eval_joint(const EvalOptions& options, capture::Capture capture);
// Spatial upscale of an LR frame that sampled the scene at pixel centres + jitter (LR pixels).
ImageRGBA spatial_upscale(const ImageRGBA& lr, uint32_t out_w, uint32_t out_h, Resample kind, float jitter_x,
                          float jitter_y);
// The header of a report: capture name and its composed_vectors, mode, alpha, scored frames, the
// size of the scored images and the methods in table order (scores filled in by the caller).
EvalReport new_report(const capture::Capture& cap, std::string mode, float alpha, size_t frames,
                      uint32_t width, uint32_t height, std::vector<std::string> methods);
std::string report_json(const EvalReport& r, bool per_frame);
// eval --out: creates dir/<method> for every method and dir/reference (errors: io, naming dir).
Result<void> make_out_dirs(const std::filesystem::path& dir, const std::vector<std::string>& methods);
// Writes report_json(r, per_frame = true) to dir/metrics.json (eval --out, replay --out).
Result<void> write_metrics_json(const EvalReport& r, const std::filesystem::path& dir);
std::string report_table(const EvalReport& r);

} // namespace fgsr::cli
