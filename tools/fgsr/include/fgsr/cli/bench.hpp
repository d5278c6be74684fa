// `fgsr bench`: run time against error. For each capture x mode x configuration (the quality
// presets of fgsr/engine/presets.hpp, each single switch toggled from `balanced`, and `balanced`
// on colour alone: vectors and depth withheld, eval's fgsr-colour) it runs
// `fgsr eval`'s scoring on the same frames and records engine GPU milliseconds (timestamp
// queries, median over frames x repeats, per pass and total) with PSNR / SSIM; then it times the
// engine against resolution (540p .. 2160p synthetic inputs), frames generated per pair, a memcpy
// of the same memory traffic (roofline), and a still scene against a moving one. Writes CSV,
// Markdown and gnuplot plots (see docs/PERFORMANCE.md).
//
// The pure parts (median, Pareto front, resolution names, the memory-traffic formula) are inline
// here so that tests call them directly.
#pragma once

#include <fgsr/cli/eval.hpp>

#include <fgsr/engine/presets.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace fgsr::cli {

// Median (mean of the two middle values for an even count); NaN when xs is empty.
inline double median(std::vector<double> xs) {
    if (xs.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(xs.begin(), xs.end());
    const size_t h = xs.size() / 2;
    return xs.size() % 2 ? xs[h] : 0.5 * (xs[h - 1] + xs[h]);
}

// A configuration measured on one capture and mode: run time (lower is better) and quality
// (PSNR in dB, higher is better).
struct ParetoPoint {
    double ms = 0;
    double psnr = 0;
};

// front[i] is true when no other point dominates point i, i.e. no point is at least as fast and at
// least as accurate and strictly better in one of the two. PSNR differences up to psnr_tolerance
// (dB) count as equal (0.01 dB: far below what is visible, and what separates e.g. gap filling
// on and off on some extrapolated frames). Equal points are all on the front. Points with a
// non-finite coordinate are never on the front and dominate nothing.
inline std::vector<bool> pareto_front(const std::vector<ParetoPoint>& pts, double psnr_tolerance = 0.01) {
    auto finite = [](const ParetoPoint& p) { return std::isfinite(p.ms) && std::isfinite(p.psnr); };
    std::vector<bool> front(pts.size(), false);
    for (size_t i = 0; i < pts.size(); ++i) {
        if (!finite(pts[i])) continue;
        bool dominated = false;
        for (size_t j = 0; j < pts.size() && !dominated; ++j) {
            if (j == i || !finite(pts[j])) continue;
            const ParetoPoint &a = pts[j], &b = pts[i];
            const bool better = a.psnr > b.psnr + psnr_tolerance, as_good = a.psnr >= b.psnr - psnr_tolerance;
            dominated = a.ms <= b.ms && as_good && (a.ms < b.ms || better);
        }
        front[i] = !dominated;
    }
    return front;
}

struct Resolution {
    std::string name; // as given ("720p", "640x360")
    uint32_t width = 0, height = 0;
};

// "<H>p" (16:9: width = H * 16 / 9 rounded to even, e.g. 540p = 960x540, 2160p = 3840x2160) or
// "<W>x<H>"; sizes in [1, kMaxFrameSide]. nullopt for anything else.
inline std::optional<Resolution> parse_resolution(const std::string& s) {
    auto number = [](const std::string& t, uint32_t& v) {
        if (t.empty() || t.size() > 5 || t.find_first_not_of("0123456789") != std::string::npos) return false;
        v = uint32_t(std::stoul(t));
        return v >= 1 && v <= kMaxFrameSide;
    };
    Resolution r{s, 0, 0};
    const size_t x = s.find('x');
    if (x != std::string::npos) {
        if (!number(s.substr(0, x), r.width) || !number(s.substr(x + 1), r.height)) return std::nullopt;
        return r;
    }
    if (s.size() < 2 || s.back() != 'p' || !number(s.substr(0, s.size() - 1), r.height)) return std::nullopt;
    r.width = uint32_t(std::lround(double(r.height) * 16.0 / 9.0 / 2.0)) * 2;
    if (r.width < 1 || r.width > kMaxFrameSide) return std::nullopt;
    return r;
}

// Memory traffic of one pass of one generated frame.
struct PassBytes {
    std::string pass; // the engine's pass name (PassTiming::name)
    uint64_t read = 0, written = 0;
};

// Estimated bytes one generated frame (interp, extrap, isr, esr: one alpha) or one super-resolved
// frame (sr) reads and writes, per pass, from the engine's buffer formats (daemon/engine/src/session.cpp):
// internal colour 8 B/px (4 halves), depth 4, vectors 8 (rg32f), splat keys 8, splat motion 16
// (v0, v1), field 16 + field depth 4 + field state 4, warped colour 16 + warped depth 4 per
// frame, output and SR history 16 (rgba32f). n = width * height input pixels, m = out_width *
// out_height output pixels (SR modes; n otherwise). Every buffer element a pass binds and uses
// for every pixel is counted once (a compulsory-traffic estimate: neighbourhood re-reads are
// assumed cached; lookups made only for gap / hole pixels and the 16 KiB LUT are left out):
//   splat      key clear W 8n; R mv1 8n, depth1 4n; quadratic motion: + R mv0 8n, depth0 4n
//              (frame-0 vector lookups); keys atomicMin R 8n W 8n; motion W 16n
//              -> quadratic R 32n W 32n, linear R 20n W 32n
//   generate   (fused) R keys 8n, motion 16n, colour1 8n, depth1 4n, interp + colour0 8n,
//              depth0 4n; W output 16n -> interp R 48n W 16n, extrap R 36n W 16n
//   refine     R keys 8n, motion 16n; W field 24n
//   disocc     (fill_holes) R field 24n, W field 24n
//   warp       R field 16n, colour 8n + depth 4n per frame (2); W warped 20n per frame (2)
//              -> R 40n W 40n
//   blend      (interp) R warped 40n, state 4n; W output 16n
//   sr         R colour 8n, depth 4n, mv 8n, previous depth 4n, history 16m; W output 16m
//   generate_sr  R keys 8n, motion 16n, colour1 8n, depth1 4n (isr + colour0 8n, depth0 4n),
//              history 16m; W output 16m
inline std::vector<PassBytes> frame_bytes(EvalMode mode, const Params& p, uint32_t width, uint32_t height,
                                          uint32_t out_width = 0, uint32_t out_height = 0) {
    const uint64_t n = uint64_t(width) * height;
    const uint64_t m = out_width && out_height ? uint64_t(out_width) * out_height : n;
    if (mode == EvalMode::sr) return {{"sr", 24 * n + 16 * m, 16 * m}};
    const bool interp = mode == EvalMode::interp || mode == EvalMode::isr;
    std::vector<PassBytes> out;
    out.push_back({"splat", p.motion == MotionModel::quadratic ? 32 * n : 20 * n, 32 * n});
    const uint64_t frame_reads = interp ? 48 * n : 36 * n; // keys, motion, colour and depth
    if (mode == EvalMode::isr || mode == EvalMode::esr) {
        out.push_back({"generate_sr", frame_reads + 16 * m, 16 * m});
    } else if (!p.separate_passes) {
        out.push_back({"generate", frame_reads, 16 * n});
    } else {
        out.push_back({"refine", 24 * n, 24 * n});
        if (p.fill_holes) out.push_back({"disocc", 24 * n, 24 * n});
        out.push_back({"warp", 40 * n, 40 * n});
        if (interp) out.push_back({"blend", 44 * n, 16 * n});
    }
    return out;
}

inline uint64_t total_bytes(const std::vector<PassBytes>& passes) {
    uint64_t t = 0;
    for (const PassBytes& b : passes) t += b.read + b.written;
    return t;
}

// ----- fgsr bench -----

struct BenchOptions {
    // Capture specs: "builtin", a directory, or "DIR@lr" (Mob-FGSR LR_Inputs). Empty: the built-in
    // synthetic scene, then shared/captures' blender/toss-fg, blender/orbit-sr and mobfgsr-bunker
    // (HR; LR for sr) where present.
    std::vector<std::string> captures;
    std::filesystem::path shared_captures = "../shared/captures"; // where the default captures live
    std::vector<std::string> modes{"interp", "extrap", "sr", "isr", "esr"};
    std::vector<std::string> presets{"performance", "balanced", "quality"};
    bool toggles = true; // also each single switch toggled from balanced
    // Also "balanced+colour": balanced with the capture's vectors and depth withheld (eval's
    // fgsr-colour: motion estimated from colour; its time includes the motion passes of the newest
    // input's submit, its row the EPE of the estimated vectors).
    bool colour = true;
    std::vector<std::string> resolutions{"540p", "720p", "1080p", "2160p"};
    std::vector<int> alpha_counts{1, 2, 4, 8}; // frames generated per pair (one call)
    int repeats = 5;                           // engine calls per generated frame (timing)
    int frames = 3;                            // generated frames per capture and mode
    std::filesystem::path out = "bench";
    bool quick = false;      // builtin only, 1 frame, 2 repeats, 180p, 1 and 2 alphas (for tests)
    bool still_only = false; // only still against moving at the headline resolution (no captures,
                             // scaling, roofline or frames per pair)
    // Also a run of consecutive moving calls on one session at the headline resolution (at least
    // 64 calls: the adaptive tile classification counted in the mean).
    bool moving_run = true;
    bool plots = true;
    DeviceOptions device;
    bool progress = true;
};

// One capture x mode x configuration.
struct BenchRow {
    std::string capture, mode;
    std::string config;             // preset name, or "balanced+key=value"
    std::string preset;             // the preset it starts from
    std::string toggle;             // "key=value" or empty
    uint32_t width = 0, height = 0; // output size
    size_t frames = 0, samples = 0;
    double ms = 0, ms_mean = 0;            // median / mean over samples
    std::map<std::string, double> pass_ms; // median per pass
    double psnr = 0, ssim = 0;             // mean over frames
    // Rows that run the motion passes (balanced+colour; correct_vectors=on): ms includes those of
    // the newest input's submit, motion_ms is their median alone; epe the mean EPE in pixels of the
    // estimated or corrected vectors (NaN elsewhere).
    bool colour_only = false;
    bool motion = false;
    double motion_ms = 0;
    double epe = std::numeric_limits<double>::quiet_NaN();
    uint64_t bytes = 0;  // frame_bytes estimate per generated frame
    bool pareto = false; // on the front of its capture and mode
};

// Balanced interpolation at one resolution (synthetic scene).
struct ScaleRow {
    Resolution res;
    double ms = 0; // median per generated frame
    std::map<std::string, double> pass_ms;
    uint64_t bytes = 0;
    double copy_ms = 0; // median memcpy time of the same traffic (bytes / 2 copied)
};

struct AlphaRow {
    int count = 0; // frames generated by one call
    double ms = 0; // median of the call's total GPU time
    // Per pass: the median, over the calls that ran it, of its total time in the call; and how
    // many calls ran it (tile classification runs in some calls only).
    std::map<std::string, double> pass_ms;
    std::map<std::string, size_t> pass_calls;
};

struct BenchReport {
    std::string device;
    std::vector<BenchRow> rows;
    std::vector<std::string> skipped; // captures or modes not run, with the reason
    std::vector<ScaleRow> scaling;
    Resolution headline; // for frames per pair and still vs moving
    std::vector<AlphaRow> alphas;
    // Still against moving, balanced interpolation at the headline resolution, each sample on a
    // fresh pair (a new input submitted before the call): the interpolate() call alone, and per
    // frame = the new input's ingest + the call (GPU ms, medians).
    double still_ms = 0, moving_ms = 0;
    double still_frame_ms = 0, moving_frame_ms = 0;
    // Consecutive moving calls on one fresh session (balanced interpolation, headline resolution,
    // each on a fresh pair): what the adaptive tile classification costs over a run, where a call
    // that classifies a fully moving frame costs more than one that does not (docs/TILES.md).
    struct MovingRun {
        int calls = 0, classified = 0;
        double mean_ms = 0, max_ms = 0;
        double classified_ms = 0, plain_ms = 0; // medians of the calls that did and did not classify
    } moving_run;
    // Colour only (BenchOptions::colour), balanced interpolation of the moving synthetic scene at
    // the headline resolution, each sample on a fresh pair: the new input's motion passes (at
    // submit; 0 until the engine times them), its ingest and the interpolate call (GPU ms,
    // medians), and the motion passes one by one (issue 12: motion at most 2x the rest).
    struct ColourTiming {
        bool measured = false;
        double motion_ms = 0, ingest_ms = 0, call_ms = 0;
        std::map<std::string, double> motion_pass_ms;
    } colour, colour_fast; // colour_fast: Params::fast_motion (no refinement of the estimate)
    double seconds = 0;
    int repeats = 0, frames = 0;
    unsigned copy_threads = 0;
};

Result<BenchReport> run_bench(const BenchOptions& options);

std::string bench_csv(const BenchReport& r);
std::string bench_markdown(const BenchReport& r);
// bench.csv, bench.md, scaling.csv, alphas.csv; with options.plots, gnuplot data and script,
// time_vs_error.{png,svg} and passes.{png,svg} (skipped with a warning when gnuplot is missing).
Result<void> write_bench_outputs(const BenchOptions& options, const BenchReport& r);

// Median wall time in milliseconds of copying bytes / 2 bytes with memcpy (bytes / 2 read and
// bytes / 2 written: `bytes` of memory traffic), split over `threads` threads, after one warm-up.
double time_copy_ms(uint64_t bytes, int repeats, unsigned threads);

// CLI glue (like calibrate): registers `bench` and runs it; returns the exit code.
struct BenchCli {
    BenchOptions options;
    std::string captures, modes, presets, resolutions, alphas, out;
    bool no_toggles = false, no_plots = false, quiet = false, no_colour = false, no_moving_run = false;
};
CLI::App* add_bench_command(CLI::App& app, BenchCli& c);
int bench_main(BenchCli& c, CLI::App* cmd);

} // namespace fgsr::cli
