// build/bin/fgsr: command-line front end of the fgsr engine.
#include <fgsr/cli/bench.hpp>
#include <fgsr/cli/calibrate.hpp>
#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/cli_util.hpp>
#include <fgsr/cli/eval.hpp>
#include <fgsr/cli/lut_train.hpp>
#include <fgsr/cli/probe.hpp>
#include <fgsr/cli/replay.hpp>
#include <fgsr/cli/report.hpp>
#include <fgsr/cli/stress.hpp>

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/presets.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

namespace {

using fgsr::cli::split_list;

int fail(const fgsr::Error& e) {
    return fgsr::cli::report_error(e);
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"fgsr: frame generation and super resolution (Mob-FGSR on Vulkan)"};
    app.require_subcommand(1);

    // fgsr eval
    fgsr::cli::EvalOptions eo;
    std::string mode = "interp", methods = "fgsr,fgsr-colour,linear,blend,repeat", out_dir, vectors_from;
    auto* eval = app.add_subcommand(
        "eval", "Score generated frames against ground truth, side by side with baselines");
    eval->add_option(
            "--capture", eo.capture,
            "Capture directory (Blender, Mob-FGSR PNG or fgsr format), or 'builtin' for the generated "
            "synthetic scene")
        ->capture_default_str();
    eval->add_option("--mode", mode, "interp, extrap, sr, isr or esr")
        ->check(CLI::IsMember({"interp", "extrap", "sr", "isr", "esr"}))
        ->capture_default_str();
    eval->add_option("--alpha", eo.alpha, "Generated instant: alpha (interp) or 1+alpha (extrap)")
        ->capture_default_str();
    eval->add_option("--methods", methods,
                     "Comma-separated: fgsr, fgsr-colour (vectors and depth withheld: motion from colour), "
                     "linear, blend, repeat; sr, isr, esr: fgsr, fgsr-colour, fgsr-bilinear, fgsr-bicubic, "
                     "bilinear, bicubic")
        ->capture_default_str();
    eval->add_option("--vectors-from", vectors_from,
                     "interp, extrap: read input k's vectors from FLOWDIR/%04d.flo (Middlebury .flo, pixels, "
                     "y down, to input k-1) instead of the capture's, withhold the depth, and report the EPE "
                     "of those vectors against the capture's");
    eval->add_option("--out", out_dir, "Write generated frames (EXR and PNG) and metrics.json here");
    eval->add_flag("--json", eo.json, "Print one JSON object on stdout");
    eval->add_flag("--lr", eo.prefer_lr, "Mob-FGSR captures: use LR_Inputs (960x540) instead of HR_Inputs");
    eval->add_option("--frames", eo.max_frames, "Evaluate at most this many frames (0: all)");
    eval->add_option("--static-frames", eo.static_frames,
                     "sr: frames of the static stretch for the temporal-stability figure (0: none)")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    eval->add_option("--device", eo.device.device,
                     "Vulkan device index or name substring (default: FGSR_DEVICE, "
                     "else first GPU, else lavapipe)");
    eval->add_option("--t-depth", eo.params.t_depth, "T_D: relative depth difference for disocclusion")
        ->capture_default_str();
    eval->add_option("--sr-a", eo.params.sr_a, "SR: weight of the current samples (Eq. 2, a)")
        ->capture_default_str();
    eval->add_option("--sr-b", eo.params.sr_b, "SR: sample weight fall-off with distance (Eq. 2, b)")
        ->capture_default_str();
    eval->add_option("--sr-clip", eo.params.sr_clip,
                     "ISR, ESR on input that measures aliased: clip the warped history to mean +- this many "
                     "standard deviations of the input frame's 3x3 neighbourhood (0: no clipping)")
        ->capture_default_str();
    eval->add_option("--sr-clip-antialiased", eo.params.sr_clip_antialiased,
                     "ISR, ESR on input that measures antialiased: the same clip's width (its neighbourhood "
                     "is low-passed; 0: no clipping)")
        ->capture_default_str();
    eval->add_option(
            "--sr-disagree", eo.params.sr_disagree,
            "SR: on antialiased input without jitter, lower the history's weight by this factor of its "
            "disagreement with the new samples (0: off)")
        ->capture_default_str();
    eval->add_option("--sr-depth-motion", eo.params.sr_depth_motion,
                     "SR: the history's depth test expects the depth change the local motion implies "
                     "(false: the plain relative test)")
        ->capture_default_str();
    eval->add_option("--sr-noise-average", eo.params.sr_noise_average,
                     "SR: on input that measures aliased, fewer new samples where they scatter about the "
                     "history like noise (false: Eq. 2's a everywhere)")
        ->capture_default_str();
    eval->add_option(
            "--sr-sharp-current", eo.params.sr_sharp_current,
            "SR: on input that measures antialiased, the current samples' term of Eq. 2 is the "
            "Catmull-Rom upsample of the input (false: the samples' tent weights, as on aliased input)")
        ->capture_default_str();
    eval->add_option("--sr-noise-kernel", eo.params.sr_noise_kernel,
                     "SR: on input that measures aliased, the LUT's history read moves towards the cubic "
                     "B-spline where the samples scatter like noise and the history is smoother (false: "
                     "the LUT everywhere)")
        ->capture_default_str();
    eval->add_option("--dilate-bright", eo.params.dilate_bright,
                     "With vectors and depth in linear colour: pixels next to over-white ones (luminance "
                     "above this) take their depth and vector when those lie in front (0: off)")
        ->capture_default_str();
    eval->add_option("--dilate-edges", eo.params.dilate_edges,
                     "With vectors and depth: the pixel behind a depth edge takes the front's depth and vector "
                     "where the previous frame's colour differs by less than this ratio times under its own "
                     "vector (0: off)")
        ->capture_default_str();
    eval->add_flag("--correct-vectors", eo.params.correct_vectors,
                   "interp, extrap, isr, esr: method fgsr also estimates motion from colour and replaces the "
                   "capture's vector where the colour follows the estimate by far better (moving shadows)");
    eval->add_flag(
        "--colour-agree", eo.params.colour_agree,
        "interp, extrap, isr, esr: method fgsr also generates from motion estimated from colour and takes "
        "that frame where it explains the colour and the capture's vectors do not (moving shadows); "
        "on by default and in --preset quality, --colour-agree=false turns it off");
    eval->add_option("--correct-ratio", eo.params.correct_ratio,
                     "--correct-vectors: the estimate's colour cost must be below this times the given one's")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    eval->add_option("--correct-margin", eo.params.correct_margin,
                     "--correct-vectors: ... minus this margin (display luma)")
        ->capture_default_str();
    eval->add_option("--correct-depth", eo.params.correct_depth,
                     "--correct-vectors: only where the depth at the given vector's previous position is "
                     "within this relative difference (inf: anywhere)")
        ->capture_default_str();
    eval->add_option(
            "--correct-front", eo.params.correct_front,
            "--correct-vectors: ... and no nearer than the pixel by more than this relative difference "
            "(there the mismatch is uncovered background; inf: any)")
        ->capture_default_str();
    eval->add_flag("--fast-motion", eo.params.fast_motion,
                   "fgsr-colour: estimate motion without refining the estimate (session flag "
                   "FGSR_SESSION_FAST_MOTION; about half the motion passes' time)");
    eval->add_option("--motion-consensus", eo.params.motion_consensus,
                     "fgsr-colour: the consensus of unambiguous blocks on the coarse levels of the block "
                     "matching (false: each block keeps its own best match)")
        ->capture_default_str();
    std::string lut_file;
    eval->add_option("--lut", lut_file,
                     "SR: history resampling table (.lut file, fgsr lut-train) instead of the shipped one");
    eval->add_flag("--dilate", eo.params.dilate_mvs,
                   "SR: depth-informed motion-vector dilation (frontmost of 3x3)");
    bool no_denoise = false;
    eval->add_flag("--no-denoise", no_denoise, "SR: no pre-filter of noisy input (shaders/denoise.h)");
    eval->add_option("--denoise-strength", eo.params.denoise_strength,
                     "SR: pre-filter range in estimated noise sigmas")
        ->capture_default_str();
    eval->add_option("--noise-floor", eo.params.noise_floor,
                     "SR: estimated noise (in --denoise-gamma's units) at or below which input is not filtered")
        ->capture_default_str();
    eval->add_option("--denoise-gamma", eo.params.denoise_gamma,
                     "SR: measure noise relative to the local brightness to this power (0: linear units, 1: a "
                     "fraction of the brightness)")
        ->capture_default_str();
    eval->add_option("--t-bright", eo.params.t_bright, "T_B: display luma difference for shading change")
        ->capture_default_str();
    std::string blend = "mix";
    std::string resample = "lut", warp_resample = "auto";
    const std::vector<std::string> kernel_names(fgsr::kResampleNames.begin(), fgsr::kResampleNames.end());
    bool no_gaps = false, no_holes = false, quiet = false, separate = false;
    eval->add_option("--blend", blend,
                     "Where both warped frames agree: 'mix' (alpha-weighted) or 'select' (the "
                     "temporally closer, paper Eq. 1)")
        ->check(CLI::IsMember({"mix", "select"}))
        ->capture_default_str();
    eval->add_option(
            "--resample", resample,
            "SR: resampling of the sr pass's history (bilinear, catmull_rom or lut; methods fgsr and "
            "fgsr-colour)")
        ->check(CLI::IsMember(kernel_names))
        ->capture_default_str();
    std::vector<std::string> warp_names = kernel_names;
    warp_names.push_back("auto");
    eval->add_option("--warp-resample", warp_resample,
                     "ISR, ESR: resampling of the SR outputs at the generated instant (auto: Catmull-Rom "
                     "for ISR on input that measures antialiased, else bilinear; bilinear, catmull_rom "
                     "or lut; methods fgsr and fgsr-colour)")
        ->check(CLI::IsMember(warp_names))
        ->capture_default_str();
    std::string sr_spatial = "auto";
    eval->add_option("--sr-spatial", sr_spatial,
                     "SR: kernel of the spatial upsample (rejected history, first frame): auto (the "
                     "B-spline on aliased input, Catmull-Rom on antialiased), catmull_rom or bspline")
        ->check(CLI::IsMember({"auto", "catmull_rom", "bspline"}))
        ->capture_default_str();
    eval->add_flag("--no-gap-fill", no_gaps, "Disable refinement of splatting gaps");
    eval->add_flag("--no-hole-fill", no_holes, "Disable disocclusion filling");
    eval->add_flag("--separate-passes", separate,
                   "Run refine, disocc, warp and blend as separate passes (per-pass timings; same frames)");
    bool no_skip = false;
    eval->add_flag("--no-skip-tiles", no_skip,
                   "Run every pass over every tile (no per-tile classification; same frames)");
    eval->add_option("--tile", eo.params.tile_size, "Tile side for skipping: 8, 16 or 32 (0: default)")
        ->check(CLI::IsMember({0, 8, 16, 32}));
    eval->add_flag("--quiet", quiet, "No progress on stderr");
    std::string preset;
    eval->add_option("--preset", preset,
                     "Start from a quality preset (performance, balanced, quality; "
                     "fgsr/engine/presets.hpp); the other options given override it")
        ->check(CLI::IsMember({"performance", "balanced", "quality"}));
    std::vector<std::string> eval_switches;
    eval->add_option("--switch", eval_switches,
                     "A switch as `fgsr bench` names it, e.g. cover_edges=off or motion=linear (repeatable; "
                     "applied after the preset and the other options)");
    std::string eval_socket;
    eval->add_option(
        "--socket", eval_socket,
        "Evaluate the fgsr method through fgsrd listening on this socket (fgsr replay's code path)");

    // fgsr replay
    fgsr::cli::ReplayOptions ro;
    std::string replay_mode = "interp", replay_out, replay_csv;
    bool replay_bench = false;
    fgsr::cli::ReplayBenchOptions rbo;
    std::string bench_sizes = "64x64,1280x720";
    auto* replay = app.add_subcommand(
        "replay",
        "Stream a capture through fgsrd (client library): outputs, telemetry CSV, summary, metrics");
    replay->add_option("--capture", ro.capture, "Capture directory (any format fgsr reads) or 'builtin'")
        ->capture_default_str();
    replay->add_option("--mode", replay_mode, "interp, extrap, sr, isr or esr")
        ->check(CLI::IsMember({"interp", "extrap", "sr", "isr", "esr"}))
        ->capture_default_str();
    replay->add_option("--socket", ro.socket,
                       "fgsrd socket (default: $FGSR_SOCKET, else "
                       "$XDG_RUNTIME_DIR/fgsr/fgsrd.sock)");
    replay->add_option("--fps", ro.fps,
                       "Submit at this many frames per second (default: as fast as possible)");
    replay->add_option("--out", replay_out, "Write the outputs here (eval --out layout, method fgsr)");
    replay->add_option("--telemetry", replay_csv,
                       "Write the presents to this CSV file (PresentMon's columns, then fgsr's; one row per "
                       "displayed frame, in display order)");
    replay->add_option("--alpha", ro.alpha, "Generated instant: alpha (interp) or 1+alpha (extrap)")
        ->capture_default_str();
    replay->add_option("--frames", ro.max_frames, "Replay at most this many targets (0: all)");
    replay->add_flag("--lr", ro.prefer_lr, "Mob-FGSR captures: use LR_Inputs");
    replay->add_flag("--mailbox", ro.mailbox, "Queue policy mailbox (latest wins) instead of fifo");
    replay->add_flag(
        "--correct-vectors", ro.params.correct_vectors,
        "Session flag FGSR_SESSION_CORRECT_MVS: fgsrd corrects the capture's vectors by colour where "
        "shading moves on its own");
    replay->add_flag(
        "--colour-agree", ro.params.colour_agree,
        "Session flag FGSR_SESSION_COLOUR_AGREE: fgsrd also generates each frame from motion estimated "
        "from colour and takes it where shading moves on its own (interp and extrap with vectors; on "
        "by default, as fgsr eval, --colour-agree=false turns it off)");
    replay->add_flag("--bench", replay_bench,
                     "Benchmark the service overhead with spinning off and on (starts two fgsrd unless "
                     "--socket; prints figures)");
    replay->add_option("--bench-sizes", bench_sizes, "Sizes for --bench, WxH,WxH...")->capture_default_str();
    replay->add_option("--bench-frames", rbo.frames, "Submits per size and run for --bench")
        ->check(CLI::Range(3, 100000))
        ->capture_default_str();
    replay->add_option("--bench-runs", rbo.runs, "Runs of each configuration for --bench (medians printed)")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    replay->add_option("--bench-spin-us", rbo.spin_us,
                       "fgsrd --spin-us and FGSR_WAIT_SPIN_US of --bench's 'on' configuration")
        ->check(CLI::Range(0u, 1000u))
        ->capture_default_str();
    bool replay_quiet = false;
    replay->add_flag("--quiet", replay_quiet, "No progress on stderr");

    // fgsr convert
    std::string conv_in, conv_out;
    bool conv_lr = false;
    auto* convert = app.add_subcommand(
        "convert", "Convert any supported capture (or 'builtin') to fgsr's capture format");
    convert->add_option("--capture", conv_in, "Input capture directory or 'builtin'")->required();
    convert->add_option("--out", conv_out, "Output directory")->required();
    convert->add_flag("--lr", conv_lr, "Mob-FGSR captures: use LR_Inputs");
    bool conv_colour_png = false;
    convert->add_flag("--colour-png", conv_colour_png,
                      "Instead of a conversion, write the colour of each input frame of fgsr eval as an "
                      "8-bit sRGB PNG OUT/NNNN.png (NNNN: the input's index from 0000; alpha dropped; "
                      "captures of consecutive frames at half rate: frames 0, 2, 4, ...), for external "
                      "tools such as tools/reference/dis_vectors.py");

    // fgsr lut-train
    fgsr::cli::LutTrainOptions lut_opts;
    auto* lut_train = fgsr::cli::add_lut_train_command(app, lut_opts);

    // fgsr calibrate
    fgsr::cli::CalibrateCli cal;
    auto* calibrate = fgsr::cli::add_calibrate_command(app, cal);

    // fgsr bench
    fgsr::cli::BenchCli bench_cli;
    auto* bench = fgsr::cli::add_bench_command(app, bench_cli);

    // fgsr stress
    fgsr::cli::StressCli stress_opts;
    auto* stress = fgsr::cli::add_stress_command(app, stress_opts);

    // fgsr report
    fgsr::cli::ReportCli report_cli;
    auto* report = fgsr::cli::add_report_command(app, report_cli);

    // fgsr probe
    fgsr::cli::ProbeCli probe_cli;
    auto* probe = fgsr::cli::add_probe_command(app, probe_cli);

    // fgsr devices
    auto* devices = app.add_subcommand("devices", "List Vulkan devices");

    CLI11_PARSE(app, argc, argv);

    if (*eval) {
        eo.mode = fgsr::cli::parse_eval_mode(mode);
        eo.params.skip_tiles = !no_skip;
        eo.methods = split_list(methods);
        if (eo.mode != fgsr::cli::EvalMode::interp && eo.mode != fgsr::cli::EvalMode::extrap &&
            !eval->count("--methods"))
            eo.methods = {"fgsr", "fgsr-colour", "fgsr-bilinear", "fgsr-bicubic", "bilinear", "bicubic"};
        if (!out_dir.empty()) eo.out = out_dir;
        if (!vectors_from.empty()) eo.vectors_from = vectors_from;
        if (!preset.empty()) {
            // The preset, then every option that was given on the command line.
            fgsr::Params p = *fgsr::preset_params(preset);
            if (eval->count("--t-depth")) p.t_depth = eo.params.t_depth;
            if (eval->count("--t-bright")) p.t_bright = eo.params.t_bright;
            if (eval->count("--sr-a")) p.sr_a = eo.params.sr_a;
            if (eval->count("--sr-b")) p.sr_b = eo.params.sr_b;
            if (eval->count("--sr-clip")) p.sr_clip = eo.params.sr_clip;
            if (eval->count("--sr-clip-antialiased")) p.sr_clip_antialiased = eo.params.sr_clip_antialiased;
            if (eval->count("--sr-disagree")) p.sr_disagree = eo.params.sr_disagree;
            if (eval->count("--sr-depth-motion")) p.sr_depth_motion = eo.params.sr_depth_motion;
            if (eval->count("--sr-noise-average")) p.sr_noise_average = eo.params.sr_noise_average;
            if (eval->count("--sr-noise-kernel")) p.sr_noise_kernel = eo.params.sr_noise_kernel;
            if (eval->count("--sr-sharp-current")) p.sr_sharp_current = eo.params.sr_sharp_current;
            if (eval->count("--dilate-bright")) p.dilate_bright = eo.params.dilate_bright;
            if (eval->count("--dilate-edges")) p.dilate_edges = eo.params.dilate_edges;
            if (eval->count("--correct-vectors")) p.correct_vectors = true;
            if (eval->count("--colour-agree")) p.colour_agree = eo.params.colour_agree;
            if (eval->count("--correct-ratio")) p.correct_ratio = eo.params.correct_ratio;
            if (eval->count("--correct-margin")) p.correct_margin = eo.params.correct_margin;
            if (eval->count("--correct-depth")) p.correct_depth = eo.params.correct_depth;
            if (eval->count("--correct-front")) p.correct_front = eo.params.correct_front;
            if (eval->count("--dilate")) p.dilate_mvs = true;
            if (eval->count("--fast-motion")) p.fast_motion = true;
            if (eval->count("--motion-consensus")) p.motion_consensus = eo.params.motion_consensus;
            if (eval->count("--denoise-strength")) p.denoise_strength = eo.params.denoise_strength;
            if (eval->count("--noise-floor")) p.noise_floor = eo.params.noise_floor;
            if (eval->count("--denoise-gamma")) p.denoise_gamma = eo.params.denoise_gamma;
            eo.params = p;
        }
        if (no_denoise) eo.params.denoise = false;
        if (preset.empty() || eval->count("--blend"))
            eo.params.blend = blend == "select" ? fgsr::BlendMode::select : fgsr::BlendMode::mix;
        // The names were checked against the kernels' (CLI::IsMember above).
        auto kernel = [](const std::string& k) { return fgsr::resample_from_name(k).value(); };
        if (preset.empty() || eval->count("--resample")) eo.params.resample = kernel(resample);
        if (preset.empty() || eval->count("--warp-resample"))
            eo.params.warp_resample =
                warp_resample == "auto" ? std::nullopt : std::optional<fgsr::Resample>(kernel(warp_resample));
        if (preset.empty() || eval->count("--sr-spatial"))
            eo.params.sr_spatial = sr_spatial == "catmull_rom" ? fgsr::SrSpatial::catmull_rom
                                   : sr_spatial == "bspline"   ? fgsr::SrSpatial::bspline
                                                               : fgsr::SrSpatial::automatic;
        if (preset.empty() || no_gaps) eo.params.fill_gaps = !no_gaps;
        if (preset.empty() || no_holes) eo.params.fill_holes = !no_holes;
        if (preset.empty() || separate) eo.params.separate_passes = separate;
        for (const std::string& sw : eval_switches)
            if (auto r = fgsr::apply_switch(eo.params, sw); !r) return fail(r.error());
        eo.progress = !quiet;
        if (!lut_file.empty()) {
            auto l = fgsr::load_lut(lut_file);
            if (!l) return fail(l.error());
            eo.params.lut = std::move(l->weights);
        }
        if (!eval_socket.empty()) {
            // fgsrd's session description carries only these switches (capture/session_desc.hpp);
            // any other would be dropped on the way and the A/B would compare nothing.
            for (const std::string& sw : eval_switches) {
                const std::string key = sw.substr(0, sw.find('='));
                if (key != "motion" && key != "dilate_mvs" && key != "denoise" && key != "correct_vectors" &&
                    key != "fast_motion" && key != "colour_agree")
                    return fail(fgsr::make_error(
                        fgsr::Errc::invalid_argument,
                        "--switch " + key +
                            " does not reach fgsrd (--socket): the session description carries "
                            "motion, dilate_mvs, denoise, correct_vectors, fast_motion and colour_agree "
                            "only"));
            }
            fgsr::cli::ReplayOptions o;
            o.capture = eo.capture;
            o.mode = eo.mode;
            o.socket = eval_socket;
            o.out = eo.out;
            o.alpha = eo.alpha;
            o.max_frames = eo.max_frames;
            o.prefer_lr = eo.prefer_lr;
            o.progress = eo.progress;
            o.params = eo.params;
            if (eval->count("--methods") && eo.methods != std::vector<std::string>{"fgsr"})
                std::fprintf(stderr, "fgsr eval --socket: evaluating method fgsr only (through fgsrd)\n");
            auto r = fgsr::cli::run_replay(o);
            if (!r) return fail(r.error());
            if (!r->metrics)
                return fail(fgsr::make_error(fgsr::Errc::empty_input, "capture has no references to score"));
            if (eo.json)
                std::fputs(fgsr::cli::report_json(*r->metrics, false).c_str(), stdout);
            else
                std::fputs(fgsr::cli::report_table(*r->metrics).c_str(), stdout);
            return 0;
        }
        auto r = fgsr::cli::run_eval(eo);
        if (!r) return fail(r.error());
        if (eo.json)
            std::fputs(fgsr::cli::report_json(*r, false).c_str(), stdout);
        else
            std::fputs(fgsr::cli::report_table(*r).c_str(), stdout);
        if (eo.out && !eo.json) std::printf("frames and metrics.json written to %s\n", eo.out->c_str());
        return 0;
    }
    if (*replay) {
        ro.mode = fgsr::cli::parse_eval_mode(replay_mode);
        ro.progress = !replay_quiet;
        if (!replay_out.empty()) ro.out = replay_out;
        if (!replay_csv.empty()) ro.telemetry = replay_csv;
        if (replay_bench) {
            auto sizes = fgsr::cli::parse_bench_sizes(bench_sizes);
            if (!sizes) return fail(sizes.error());
            rbo.sizes = *sizes;
            rbo.socket = ro.socket;
            rbo.progress = ro.progress;
            auto b = fgsr::cli::run_replay_bench(rbo);
            return b ? 0 : fail(b.error());
        }
        auto r = fgsr::cli::run_replay(ro);
        if (!r) return fail(r.error());
        std::fputs(fgsr::cli::replay_summary_text(*r).c_str(), stdout);
        return 0;
    }
    if (*convert) {
        auto c = fgsr::cli::load_capture_spec(conv_in, conv_lr);
        if (!c) return fail(c.error());
        if (conv_colour_png) {
            // The inputs fgsr eval feeds the engine: every frame of a halfway capture, the even
            // frames of a consecutive one (make_half_rate's inputs). The displayed colour: decoded to
            // linear as the engine's ingest does, then sRGB-encoded and rounded by write_png
            // (rgba8_srgb inputs give back their bytes).
            const size_t stride = c->ground_truth_kind == fgsr::capture::GroundTruth::consecutive ? 2 : 1;
            std::error_code ec;
            std::filesystem::create_directories(conv_out, ec);
            if (ec)
                return fail(fgsr::make_error(fgsr::Errc::io, conv_out + ": cannot create: " + ec.message()));
            size_t written = 0;
            for (size_t k = 0; k < c->inputs.size(); k += stride, ++written) {
                char name[32];
                std::snprintf(name, sizeof name, "%04zu.png", written);
                auto w = fgsr::capture::write_png(std::filesystem::path(conv_out) / name,
                                                  fgsr::capture::decode_color(c->format, c->inputs[k]));
                if (!w) return fail(w.error());
            }
            std::printf("wrote %zu colour PNGs of '%s'%s to %s\n", written, c->name.c_str(),
                        stride == 2 ? " (half rate: frames 0, 2, 4, ...)" : "", conv_out.c_str());
            return 0;
        }
        auto w = fgsr::capture::save_fgsr(*c, conv_out);
        if (!w) return fail(w.error());
        std::printf("wrote %zu frames of '%s' to %s\n", c->inputs.size(), c->name.c_str(), conv_out.c_str());
        return 0;
    }
    if (*bench) return fgsr::cli::bench_main(bench_cli, bench);
    if (*calibrate) return fgsr::cli::calibrate_main(cal, calibrate, argc, argv);
    if (*lut_train) return fgsr::cli::lut_train_main(lut_opts, argc, argv);
    if (*stress) return fgsr::cli::stress_main(stress_opts);
    if (*report) return fgsr::cli::report_main(report_cli);
    if (*probe) return fgsr::cli::probe_main(probe_cli);
    if (*devices) {
        auto list = fgsr::Engine::list_devices();
        if (!list) return fail(list.error());
        for (const std::string& d : *list) std::printf("%s\n", d.c_str());
        return 0;
    }
    return 0;
}
