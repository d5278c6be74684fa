// `fgsr calibrate` (paper section 4, "Parameters calibration"): fits T_D and T_B (frame
// generation) and a, b (super resolution, Eq. 2) on captures by a derivative-free search on the
// evaluation metric of `fgsr eval`, and can rewrite daemon/engine/include/fgsr/engine/defaults.hpp.
//
// The search (maximise_coordinates, header-only so that tests use it directly) is a coordinate
// ascent: per parameter a grid over its range (log-spaced for thresholds), then golden-section
// refinement in the bracket around the best grid point; later rounds repeat on a narrowing window
// around the current point. A candidate replaces the current point only when it scores strictly
// higher, so the result is never worse than the start.
#pragma once

#include <fgsr/cli/eval.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace fgsr::cli {

// One searched coordinate: range [lo, hi] (lo > 0 when log).
struct SearchDim {
    std::string name;
    double lo = 0, hi = 1;
    bool log = false; // search in log(x)
};

struct SearchOptions {
    int rounds = 2;         // coordinate-ascent rounds (>= 1)
    int grid = 9;           // grid points over the full range in round 1 (>= 2); later rounds use 5
    int golden = 6;         // golden-section iterations after each grid (>= 0)
    double min_gain = 1e-4; // a round that improves less than this ends the search
};

struct SearchResult {
    std::vector<double> x; // best point (start when nothing scored higher)
    double value = 0;      // f(x)
    double start_value = 0;
    int evaluations = 0;    // calls of f (distinct points)
    std::vector<bool> flat; // per dimension: every grid value of round 1 scored the same (no effect)
};

namespace detail {

inline double to_unit(const SearchDim& d, double x) {
    x = std::clamp(x, d.lo, d.hi);
    if (d.hi <= d.lo) return 0;
    return d.log ? (std::log(x) - std::log(d.lo)) / (std::log(d.hi) - std::log(d.lo))
                 : (x - d.lo) / (d.hi - d.lo);
}

inline double from_unit(const SearchDim& d, double u) {
    u = std::clamp(u, 0.0, 1.0);
    return d.log ? std::exp(std::log(d.lo) + u * (std::log(d.hi) - std::log(d.lo)))
                 : d.lo + u * (d.hi - d.lo);
}

} // namespace detail

// Maximises f over the box `dims` from `start` (clamped into the box). `quantise` (optional) maps
// a coordinate value to the value actually evaluated and reported (e.g. rounding to the digits
// written out); points are cached after quantisation, so f is never called twice on one point.
inline SearchResult maximise_coordinates(const std::function<double(const std::vector<double>&)>& f,
                                         const std::vector<SearchDim>& dims, std::vector<double> start,
                                         const SearchOptions& opt = {},
                                         const std::function<double(size_t, double)>& quantise = {}) {
    const size_t n = dims.size();
    start.resize(n, 0.0);
    auto q = [&](size_t i, double v) {
        v = std::clamp(v, dims[i].lo, dims[i].hi);
        return quantise ? quantise(i, v) : v;
    };
    std::map<std::vector<double>, double> cache;
    SearchResult r;
    auto eval = [&](const std::vector<double>& x) {
        auto it = cache.find(x);
        if (it != cache.end()) return it->second;
        double v = f(x);
        if (!std::isfinite(v)) v = -std::numeric_limits<double>::infinity();
        cache.emplace(x, v);
        ++r.evaluations;
        return v;
    };
    for (size_t i = 0; i < n; ++i) start[i] = q(i, start[i]);
    r.x = start;
    r.value = r.start_value = eval(start);
    r.flat.assign(n, false);
    if (n == 0) return r;

    const int rounds = std::max(opt.rounds, 1), golden = std::max(opt.golden, 0);
    double window = 1.0; // half-width of the searched interval in unit coordinates (round 1: all)
    for (int round = 0; round < rounds; ++round) {
        const double round_start = r.value;
        for (size_t i = 0; i < n; ++i) {
            if (r.flat[i]) continue;
            const SearchDim& d = dims[i];
            double lo_v = std::numeric_limits<double>::infinity(), hi_v = -lo_v;
            // Scores x with coordinate i set to u (unit); moves the current point on a strict gain.
            auto try_u = [&](double u) {
                std::vector<double> x = r.x;
                x[i] = q(i, detail::from_unit(d, u));
                const double v = eval(x);
                lo_v = std::min(lo_v, v);
                hi_v = std::max(hi_v, v);
                if (v > r.value) {
                    r.value = v;
                    r.x = x;
                }
                return v;
            };
            const double uc = detail::to_unit(d, r.x[i]);
            const double a = round == 0 ? 0.0 : std::max(0.0, uc - window);
            const double b = round == 0 ? 1.0 : std::min(1.0, uc + window);
            const int points = std::max(round == 0 ? opt.grid : 5, 2);
            const double step = (b - a) / double(points - 1);
            double best_u = uc, best_v = r.value;
            lo_v = hi_v = r.value;
            for (int k = 0; k < points; ++k) {
                const double u = a + step * double(k);
                const double v = try_u(u);
                if (v > best_v) {
                    best_v = v;
                    best_u = u;
                }
            }
            if (round == 0 && hi_v - lo_v <= 1e-12 * std::max(1.0, std::abs(hi_v))) {
                r.flat[i] = true; // no grid value changed f: leave this coordinate alone
                continue;
            }
            // Golden-section search in the bracket around the best grid point.
            double lo = std::max(0.0, best_u - step), hi = std::min(1.0, best_u + step);
            const double g = (std::sqrt(5.0) - 1.0) / 2.0;
            double c = hi - g * (hi - lo), e = lo + g * (hi - lo);
            double fc = golden > 0 ? try_u(c) : 0, fe = golden > 1 ? try_u(e) : 0;
            for (int it = 2; it < golden; ++it) {
                if (fc >= fe) { // maximum in [lo, e]
                    hi = e;
                    e = c;
                    fe = fc;
                    c = hi - g * (hi - lo);
                    fc = try_u(c);
                } else { // maximum in [c, hi]
                    lo = c;
                    c = e;
                    fc = fe;
                    e = lo + g * (hi - lo);
                    fe = try_u(e);
                }
            }
        }
        window = round == 0 ? 2.0 / double(std::max(opt.grid, 2) - 1) : window / 2.0;
        if (round > 0 && r.value - round_start < opt.min_gain) break;
    }
    return r;
}

// ----- fgsr calibrate -----

enum class CalMetric { psnr, ssim };

struct CalibrateOptions {
    std::vector<std::string> captures; // directories or "builtin"; empty: toss-fg + orbit-sr
    CalMetric metric = CalMetric::psnr;
    int max_frames = 8; // per capture and mode (0: all)
    std::vector<std::string> fit{"t_depth", "t_bright", "sr_a", "sr_b"};
    std::vector<std::string> modes{"interp", "extrap", "sr"};
    Params start; // starting point (the defaults); also the other parameters of every evaluation (blend, ...)
    SearchOptions search;
    std::optional<std::filesystem::path> write_defaults; // header to rewrite
    DeviceOptions device;
    bool progress = true;
    std::string command_line; // recorded in the header
};

struct CalParam {
    std::string name;
    double start = 0, fitted = 0;
    bool searched = false; // part of a search that ran
    bool flat = false;     // searched, but no value changed the metric
};

struct CalMode {
    std::string mode;                  // interp, extrap, sr
    std::vector<std::string> captures; // report names of the captures scored
    double before = 0, after = 0;      // mean fgsr metric at the start / fitted parameters
    std::map<std::string, double> before_by_capture, after_by_capture;
};

struct CalibrateReport {
    std::string metric;
    bool blend_select = false;        // frame generation scored with BlendMode::select
    std::vector<CalParam> params;     // t_depth, t_bright, sr_a, sr_b
    std::vector<CalMode> modes;       // modes with at least one capture
    std::vector<std::string> skipped; // "capture: mode: reason"
    int evaluations = 0;              // parameter points evaluated (each over all captures of a stage)
    double seconds = 0;
    std::optional<std::filesystem::path> written;
};

Result<CalibrateReport> run_calibrate(const CalibrateOptions& options);

// The defaults header for `r` (fitted values of searched, non-flat parameters): `existing` (the
// current header text) with its four constants and calibration comment replaced; when `existing`
// is empty, a new header of the same structure. Errors: invalid_argument if `existing` lacks one
// of the four constants.
Result<std::string> defaults_header(const CalibrateOptions& o, const CalibrateReport& r,
                                    const std::string& existing);

std::string calibrate_table(const CalibrateReport& r);
std::string calibrate_json(const CalibrateReport& r);

// CLI glue (like lut-train): registers `calibrate` and runs it; returns the exit code.
struct CalibrateCli {
    CalibrateOptions options;
    std::string metric = "psnr", fit, modes, write_defaults, blend = "mix";
    bool quiet = false, json = false;
    float t_depth = 0, t_bright = 0, sr_a = 0, sr_b = 0;
};
CLI::App* add_calibrate_command(CLI::App& app, CalibrateCli& c);
int calibrate_main(CalibrateCli& c, CLI::App* cmd, int argc, char** argv);

} // namespace fgsr::cli
