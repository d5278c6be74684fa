#include <fgsr/cli/calibrate.hpp>
#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/cli_util.hpp>

#include <fgsr/capture/synthetic.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <ctime>
#include <fstream>
#include <set>
#include <sstream>
#include <unistd.h>

namespace fgsr::cli {

namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kParamNames[] = {"t_depth", "t_bright", "sr_a", "sr_b"};

// Search ranges. Thresholds span decades (log); a is a mixing weight in (0, 1]; b is the fall-off of
// max(1 - b d, 0) over sample distances d < 1 LR pixel (0: flat weights).
SearchDim dim_of(const std::string& name) {
    if (name == "t_depth") return {name, 1e-3, 1.0, true};
    if (name == "t_bright") return {name, 5e-3, 1.0, true};
    if (name == "sr_a") return {name, 0.02, 1.0, false};
    return {name, 0.0, 2.0, false}; // sr_b
}

// Values are evaluated, reported and written with 4 significant digits.
double round4(double v) {
    return std::stod(fmt::format("{:.4g}", v));
}

std::string literal(double v) {
    std::string s = fmt::format("{:.4g}", v);
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return s + "f";
}

float& param_ref(Params& p, const std::string& name) {
    if (name == "t_depth") return p.t_depth;
    if (name == "t_bright") return p.t_bright;
    if (name == "sr_a") return p.sr_a;
    return p.sr_b;
}

const char* mode_name(EvalMode m) {
    switch (m) {
    case EvalMode::interp:
        return "interp";
    case EvalMode::extrap:
        return "extrap";
    case EvalMode::sr:
        return "sr";
    default:
        return "?";
    }
}

// A capture prepared for one mode family. FG: a truncated (half-rate where needed) copy in fgsr's
// format in a temporary directory, so each evaluation reads only the frames it scores. SR: the
// loaded capture (run_eval_sr takes it directly).
struct FgCase {
    std::string name;
    std::filesystem::path dir;
    std::vector<EvalMode> modes;
};
struct SrCase {
    std::string name;
    capture::Capture cap;
};

class TempDir {
  public:
    TempDir() {
        path_ = std::filesystem::temp_directory_path() / fmt::format("fgsr-calibrate-{}", ::getpid());
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }

  private:
    std::filesystem::path path_;
};

bool jittered(const capture::Capture& c) {
    for (const capture::Frame& f : c.inputs)
        if (f.jitter_x != 0.f || f.jitter_y != 0.f) return true;
    return false;
}

std::string today_utc() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
    return buf;
}

} // namespace

Result<CalibrateReport> run_calibrate(const CalibrateOptions& o) {
    const auto t0 = Clock::now();
    if (o.captures.empty())
        return make_error(Errc::invalid_argument, "no capture given (--capture DIR or builtin)");
    if (o.max_frames < 0) return make_error(Errc::invalid_argument, "--frames must be >= 0");
    for (const std::string& p : o.fit)
        if (std::find(std::begin(kParamNames), std::end(kParamNames), p) == std::end(kParamNames))
            return make_error(Errc::invalid_argument,
                              "unknown parameter '" + p + "' (t_depth, t_bright, sr_a, sr_b)");
    std::vector<EvalMode> fg_modes;
    bool want_sr = false;
    for (const std::string& m : o.modes) {
        if (m == "interp")
            fg_modes.push_back(EvalMode::interp);
        else if (m == "extrap")
            fg_modes.push_back(EvalMode::extrap);
        else if (m == "sr")
            want_sr = true;
        else
            return make_error(Errc::invalid_argument, "unknown mode '" + m + "' (interp, extrap, sr)");
    }
    const auto fitting = [&](const char* p) {
        return std::find(o.fit.begin(), o.fit.end(), p) != o.fit.end();
    };

    CalibrateReport rep;
    rep.metric = o.metric == CalMetric::psnr ? "psnr" : "ssim";
    rep.blend_select = o.start.blend == BlendMode::select;
    Params start = o.start;
    for (const char* n : kParamNames) {
        const SearchDim d = dim_of(n);
        float& v = param_ref(start, n);
        if (!std::isfinite(v))
            return make_error(Errc::invalid_argument, fmt::format("start value of {} is not finite", n));
        v = float(round4(std::clamp(double(v), d.lo, d.hi)));
        rep.params.push_back({n, double(v), double(v), false, false});
    }
    auto log = [&](const std::string& s) {
        if (o.progress) std::fprintf(stderr, "[calibrate] %s\n", s.c_str());
    };
    auto skip = [&](const std::string& cap, const std::string& mode, const std::string& why) {
        rep.skipped.push_back(cap + ": " + mode + ": " + why);
        log("skipping " + cap + " for " + mode + ": " + why);
    };
    const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };

    // ---- Prepare captures.
    TempDir tmp;
    std::vector<FgCase> fg;
    std::vector<SrCase> sr;
    const size_t n = size_t(o.max_frames);
    std::set<std::string> names;
    for (size_t ci = 0; ci < o.captures.size(); ++ci) {
        const std::string& spec = o.captures[ci];
        std::string name = capture_short_name(spec);
        while (names.count(name)) name += "'";
        names.insert(name);
        if (!fg_modes.empty()) {
            log("loading " + spec + " (frame generation)");
            // interp needs inputs 0..N and ground truth 0..N-1, extrap inputs 0..N+1 and ground truth 1..N;
            // half-rate captures need twice the frames.
            auto c = load_capture_spec(spec, false, n ? 2 * n + 4 : capture::kAllFrames);
            if (!c) return c.error();
            std::string why;
            if (jittered(*c)) {
                why =
                    "jittered inputs (a super-resolution capture): no aligned frame-generation ground truth";
            } else if (c->ground_truth_kind == capture::GroundTruth::consecutive) {
                auto h = capture::make_half_rate(*c);
                if (!h)
                    why = "half-rate conversion failed: " + h.error().message;
                else
                    *c = std::move(*h);
            }
            if (why.empty()) {
                if (n) {
                    if (c->inputs.size() > n + 2) c->inputs.resize(n + 2);
                    if (c->ground_truth.size() > n + 1) c->ground_truth.resize(n + 1);
                }
                c->hr_reference.clear();
                c->hr_ground_truth.clear();
                const std::filesystem::path dir = tmp.path() / fmt::format("{}-fg", ci);
                if (auto w = capture::save_fgsr(*c, dir); !w) return w.error();
                fg.push_back({name, dir, fg_modes});
            } else {
                for (EvalMode m : fg_modes) skip(name, mode_name(m), why);
            }
        }
        if (want_sr) {
            log("loading " + spec + " (super resolution)");
            auto c = load_capture_spec(spec, true, n ? n : capture::kAllFrames);
            if (!c) return c.error();
            if (c->hr_reference.empty())
                skip(name, "sr", "no high-resolution reference");
            else
                sr.push_back({name, std::move(*c)});
        }
    }

    // ---- Evaluation: mean fgsr metric over the cases; results per point kept for the report.
    std::optional<Error> failure;
    auto metric_of = [&](const EvalReport& r) {
        const MethodScore& s = r.methods.at("fgsr");
        return o.metric == CalMetric::psnr ? s.mean_psnr : s.mean_ssim;
    };
    auto eval_options = [&](EvalMode m, const Params& p) {
        EvalOptions eo;
        eo.mode = m;
        eo.methods = {"fgsr"};
        eo.max_frames = o.max_frames;
        eo.device = o.device;
        eo.params = p;
        eo.progress = false;
        return eo;
    };
    using Scores = std::map<std::string, double>; // "capture mode" -> metric
    auto eval_fg_case = [&](const FgCase& c, EvalMode m, const Params& p) -> Result<double> {
        EvalOptions eo = eval_options(m, p);
        eo.capture = c.dir.string();
        auto r = run_eval(eo);
        if (!r) return r.error();
        return metric_of(*r);
    };
    auto eval_sr_case = [&](const SrCase& c, const Params& p) -> Result<double> {
        auto r = run_eval_sr(eval_options(EvalMode::sr, p), c.cap);
        if (!r) return r.error();
        return metric_of(*r);
    };
    auto mean = [](const Scores& s) {
        double sum = 0;
        for (const auto& [k, v] : s) sum += v;
        return s.empty() ? 0.0 : sum / double(s.size());
    };
    auto describe = [&](const Params& p, const std::vector<std::string>& which) {
        std::string s;
        for (const std::string& w : which)
            s += fmt::format("{}{}={:.4g}", s.empty() ? "" : " ", w, param_ref(const_cast<Params&>(p), w));
        return s;
    };
    auto report_point = [&](const char* stage, const Params& p, const std::vector<std::string>& which,
                            const Scores& s) {
        std::string detail;
        for (const auto& [k, v] : s) detail += fmt::format("{}{} {:.4f}", detail.empty() ? "" : ", ", k, v);
        log(fmt::format("{} #{} {}: {} {:.4f} ({}) [{:.0f} s]", stage, rep.evaluations, describe(p, which),
                        rep.metric, mean(s), detail, seconds()));
    };

    // Start point: scores every case once; a case that fails is skipped for that mode.
    Scores fg_before, sr_before;
    for (FgCase& c : fg) {
        std::vector<EvalMode> ok;
        for (EvalMode m : c.modes) {
            auto v = eval_fg_case(c, m, start);
            if (!v) {
                skip(c.name, mode_name(m), v.error().message);
                continue;
            }
            fg_before[c.name + " " + mode_name(m)] = *v;
            ok.push_back(m);
        }
        c.modes = ok;
    }
    std::erase_if(fg, [](const FgCase& c) { return c.modes.empty(); });
    std::vector<SrCase> sr_ok;
    for (SrCase& c : sr) {
        auto v = eval_sr_case(c, start);
        if (!v) {
            skip(c.name, "sr", v.error().message);
            continue;
        }
        sr_before[c.name + " sr"] = *v;
        sr_ok.push_back(std::move(c));
    }
    sr = std::move(sr_ok);
    ++rep.evaluations;
    {
        Scores all = fg_before;
        all.insert(sr_before.begin(), sr_before.end());
        report_point("start", start, {"t_depth", "t_bright", "sr_a", "sr_b"}, all);
    }

    // One search stage over `which` (a subset of the parameters) scored on `score`.
    Params current = start;
    auto stage = [&](const char* label, const std::vector<std::string>& which,
                     const std::function<Result<Scores>(const Params&)>& score,
                     const Scores& known_at_current) -> Scores {
        std::map<std::vector<double>, Scores> seen;
        std::vector<SearchDim> dims;
        std::vector<double> x0;
        for (const std::string& w : which) {
            dims.push_back(dim_of(w));
            x0.push_back(round4(double(param_ref(current, w)))); // as the search quantises
        }
        if (!known_at_current.empty()) seen[x0] = known_at_current;
        auto at = [&](const std::vector<double>& x) {
            Params p = current;
            for (size_t i = 0; i < which.size(); ++i) param_ref(p, which[i]) = float(x[i]);
            return p;
        };
        auto f = [&](const std::vector<double>& x) -> double {
            if (failure) return -std::numeric_limits<double>::infinity();
            auto it = seen.find(x);
            if (it == seen.end()) {
                const Params p = at(x);
                auto s = score(p);
                if (!s) {
                    failure = s.error();
                    return -std::numeric_limits<double>::infinity();
                }
                ++rep.evaluations;
                it = seen.emplace(x, std::move(*s)).first;
                report_point(label, p, which, it->second);
            }
            return mean(it->second);
        };
        if (dims.empty()) return known_at_current;
        log(fmt::format("{}: fitting {} on {}", label, fmt::format("{}", fmt::join(which, ", ")),
                        rep.metric));
        SearchResult r =
            maximise_coordinates(f, dims, x0, o.search, [](size_t, double v) { return round4(v); });
        if (failure) return {};
        current = at(r.x);
        for (size_t i = 0; i < which.size(); ++i)
            for (CalParam& cp : rep.params)
                if (cp.name == which[i]) {
                    cp.fitted = r.x[i];
                    cp.searched = true;
                    cp.flat = r.flat[i];
                    if (cp.flat)
                        log(cp.name + ": no value changed the metric; kept " +
                            fmt::format("{:.4g}", cp.start));
                }
        return seen[r.x];
    };

    // Frame generation: T_D, T_B.
    std::vector<std::string> fg_params;
    for (const char* p : {"t_depth", "t_bright"})
        if (fitting(p) && !fg.empty()) fg_params.push_back(p);
    const Scores fg_after = stage(
        "fg", fg_params,
        [&](const Params& p) -> Result<Scores> {
            Scores s;
            for (const FgCase& c : fg)
                for (EvalMode m : c.modes) {
                    auto v = eval_fg_case(c, m, p);
                    if (!v) return v.error();
                    s[c.name + " " + mode_name(m)] = *v;
                }
            return s;
        },
        fg_before);
    if (failure) return *failure;

    // Super resolution: a, b (with the fitted T_D, which also rejects SR history).
    std::vector<std::string> sr_params;
    for (const char* p : {"sr_a", "sr_b"})
        if (fitting(p) && !sr.empty()) sr_params.push_back(p);
    auto sr_score = [&](const Params& p) -> Result<Scores> {
        Scores s;
        for (const SrCase& c : sr) {
            auto v = eval_sr_case(c, p);
            if (!v) return v.error();
            s[c.name + " sr"] = *v;
        }
        return s;
    };
    Scores sr_at_current = sr_before;
    if (!sr.empty() && current.t_depth != start.t_depth) {
        auto s = sr_score(current);
        if (!s) return s.error();
        ++rep.evaluations;
        sr_at_current = *s;
        report_point("sr (fitted t_depth)", current, {"t_depth", "sr_a", "sr_b"}, sr_at_current);
    }
    const Scores sr_after = stage("sr", sr_params, sr_score, sr_at_current);
    if (failure) return *failure;

    // Report per mode.
    for (const char* m : {"interp", "extrap", "sr"}) {
        CalMode cm;
        cm.mode = m;
        const Scores& before = std::string(m) == "sr" ? sr_before : fg_before;
        const Scores& after = std::string(m) == "sr" ? sr_after : fg_after;
        double sb = 0, sa = 0;
        for (const auto& [k, v] : before) {
            const size_t sp = k.rfind(' ');
            if (k.substr(sp + 1) != m) continue;
            const std::string cap = k.substr(0, sp);
            cm.captures.push_back(cap);
            cm.before_by_capture[cap] = v;
            cm.after_by_capture[cap] = after.count(k) ? after.at(k) : v;
            sb += v;
            sa += cm.after_by_capture[cap];
        }
        if (cm.captures.empty()) continue;
        cm.before = sb / double(cm.captures.size());
        cm.after = sa / double(cm.captures.size());
        rep.modes.push_back(std::move(cm));
    }
    rep.seconds = seconds();

    if (o.write_defaults) {
        std::string existing;
        if (std::filesystem::exists(*o.write_defaults)) {
            std::ifstream in(*o.write_defaults, std::ios::binary);
            if (!in) return make_error(Errc::io, "cannot read " + o.write_defaults->string());
            std::stringstream ss;
            ss << in.rdbuf();
            existing = ss.str();
        }
        auto text = defaults_header(o, rep, existing);
        if (!text) return text.error();
        const std::filesystem::path tmp_path = o.write_defaults->string() + ".tmp";
        {
            std::ofstream out(tmp_path, std::ios::binary | std::ios::trunc);
            out << *text;
            if (!out.flush()) return make_error(Errc::io, "cannot write " + tmp_path.string());
        }
        std::error_code ec;
        std::filesystem::rename(tmp_path, *o.write_defaults, ec);
        if (ec)
            return make_error(Errc::io, "cannot write " + o.write_defaults->string() + ": " + ec.message());
        rep.written = *o.write_defaults;
    }
    return rep;
}

Result<std::string> defaults_header(const CalibrateOptions& o, const CalibrateReport& r,
                                    const std::string& existing_text) {
    std::string existing = existing_text;
    if (existing.empty()) {
        existing =
            "// Default algorithm parameters. `fgsr calibrate --write-defaults` rewrites this file with the\n"
            "// values it fits on captures (and records how in the comment below); otherwise they are the\n"
            "// paper's (Mob-FGSR section 4) or were chosen by hand as noted.\n"
            "#pragma once\n"
            "\n"
            "namespace fgsr::defaults {\n"
            "\n";
        for (size_t i = 0; i < std::size(kParamNames); ++i)
            existing += "inline constexpr float " + std::string(kParamNames[i]) + " = " +
                        literal(r.params[i].start) + ";\n";
        existing += "\n"
                    "} // namespace fgsr::defaults\n";
    }

    // The calibration record.
    std::vector<std::string> block;
    block.push_back("// Calibration (" + today_utc() +
                    "): " + (o.command_line.empty() ? "fgsr calibrate" : o.command_line));
    if (r.blend_select) block.push_back("//   frame generation scored with blend mode 'select'");
    {
        std::string caps;
        for (const CalMode& m : r.modes)
            caps += fmt::format("{}{} {}", caps.empty() ? "" : "; ", m.mode, fmt::join(m.captures, ", "));
        block.push_back(
            "//   captures: " + (caps.empty() ? std::string("none") : caps) +
            (o.max_frames ? fmt::format(" (at most {} frames each)", o.max_frames) : std::string()));
    }
    {
        std::string ms;
        for (const CalMode& m : r.modes)
            ms += fmt::format("{}{} {:.4f} -> {:.4f}", ms.empty() ? "" : ", ", m.mode, m.before, m.after);
        block.push_back("//   mean " + r.metric +
                        " of the fgsr method (start -> fitted): " + (ms.empty() ? "none" : ms));
    }
    {
        std::string ps;
        for (const CalParam& p : r.params) {
            std::string what = !p.searched ? "not fitted"
                               : p.flat    ? "no effect on the metric, kept"
                                           : fmt::format("{:.4g} -> {:.4g}", p.start, p.fitted);
            ps += fmt::format("{}{} {}", ps.empty() ? "" : ", ", p.name, what);
        }
        block.push_back("//   " + ps);
    }

    std::vector<std::string> lines;
    {
        std::stringstream ss(existing);
        std::string line;
        while (std::getline(ss, line)) lines.push_back(line);
    }
    // Drop an earlier record, then insert the new one right before `#pragma once`.
    for (size_t i = 0; i < lines.size(); ++i)
        if (lines[i].rfind("// Calibration (", 0) == 0) {
            size_t e = i + 1;
            while (e < lines.size() && lines[e].rfind("//   ", 0) == 0) ++e;
            lines.erase(lines.begin() + long(i), lines.begin() + long(e));
            break;
        }
    auto pragma = std::find_if(lines.begin(), lines.end(),
                               [](const std::string& l) { return l.rfind("#pragma once", 0) == 0; });
    if (pragma == lines.end())
        return make_error(Errc::invalid_argument, "defaults header has no '#pragma once'");
    lines.insert(pragma, block.begin(), block.end());

    for (const CalParam& p : r.params) {
        const std::string key = "inline constexpr float " + p.name + " ";
        auto it = std::find_if(lines.begin(), lines.end(),
                               [&](const std::string& l) { return l.find(key) != std::string::npos; });
        if (it == lines.end())
            return make_error(Errc::invalid_argument, "defaults header lacks the constant " + p.name);
        if (!p.searched || p.flat) continue;
        const size_t indent = it->find(key);
        *it = it->substr(0, indent) + key + "= " + literal(p.fitted) + "; // calibrated (see above)";
    }
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

std::string calibrate_table(const CalibrateReport& r) {
    std::string s = fmt::format("{:<10} {:>10} {:>10}\n", "parameter", "start", "fitted");
    for (const CalParam& p : r.params)
        s += fmt::format("{:<10} {:>10.4g} {:>10.4g}{}\n", p.name, p.start, p.fitted,
                         !p.searched ? "   (not fitted)"
                         : !p.flat   ? ""
                         : p.name == "t_bright" && !r.blend_select
                             ? "   (no effect on the metric: T_B acts only with --blend select)"
                             : "   (no effect on the metric)");
    s += fmt::format("\n{:<8} {:>10} {:>10}  {}\n", "mode", r.metric + " start", r.metric + " fit",
                     "captures (start -> fitted)");
    const char* f = r.metric == "psnr" ? "{:.3f}" : "{:.4f}";
    for (const CalMode& m : r.modes) {
        std::string caps;
        for (const std::string& c : m.captures)
            caps += fmt::format("{}{} {} -> {}", caps.empty() ? "" : ", ", c,
                                fmt::format(fmt::runtime(f), m.before_by_capture.at(c)),
                                fmt::format(fmt::runtime(f), m.after_by_capture.at(c)));
        s += fmt::format("{:<8} {:>10} {:>10}  {}\n", m.mode, fmt::format(fmt::runtime(f), m.before),
                         fmt::format(fmt::runtime(f), m.after), caps);
    }
    if (r.modes.empty()) s += "(no mode could be scored)\n";
    for (const std::string& k : r.skipped) s += "skipped: " + k + "\n";
    s += fmt::format("{} parameter points evaluated in {:.0f} s\n", r.evaluations, r.seconds);
    if (r.written) s += "wrote " + r.written->string() + "\n";
    return s;
}

std::string calibrate_json(const CalibrateReport& r) {
    nlohmann::json j;
    j["metric"] = r.metric;
    j["blend"] = r.blend_select ? "select" : "mix";
    for (const CalParam& p : r.params)
        j["params"][p.name] = {
            {"start", p.start}, {"fitted", p.fitted}, {"searched", p.searched}, {"flat", p.flat}};
    j["modes"] = nlohmann::json::object();
    for (const CalMode& m : r.modes)
        j["modes"][m.mode] = {{"captures", m.captures},
                              {"before", m.before},
                              {"after", m.after},
                              {"before_by_capture", m.before_by_capture},
                              {"after_by_capture", m.after_by_capture}};
    j["skipped"] = r.skipped;
    j["evaluations"] = r.evaluations;
    j["seconds"] = r.seconds;
    if (r.written) j["written"] = r.written->string();
    return j.dump(1) + "\n";
}

CLI::App* add_calibrate_command(CLI::App& app, CalibrateCli& c) {
    CalibrateOptions& o = c.options;
    auto* cmd = app.add_subcommand("calibrate",
                                   "Fit T_D, T_B (frame generation) and a, b (super resolution) on captures "
                                   "by searching on the evaluation metric");
    cmd->add_option(
           "--capture", o.captures,
           "Capture directory or 'builtin' (repeatable). Frame generation is scored on captures with "
           "unjittered inputs (interp, extrap), super resolution on captures with a high-resolution "
           "reference (Mob-FGSR captures: LR_Inputs against HR_Inputs)")
        ->required();
    cmd->add_option("--metric", c.metric, "psnr or ssim (mean over frames of the fgsr method)")
        ->check(CLI::IsMember({"psnr", "ssim"}))
        ->capture_default_str();
    cmd->add_option("--frames", o.max_frames, "At most this many frames per capture and mode (0: all)")
        ->capture_default_str();
    cmd->add_option(
           "--write-defaults", c.write_defaults,
           "Rewrite the defaults header (default path: daemon/engine/include/fgsr/engine/defaults.hpp) with "
           "the fitted values")
        ->expected(0, 1);
    cmd->add_option("--device", o.device.device, "Vulkan device index or name substring");
    cmd->add_option("--fit", c.fit,
                    "Parameters to fit, comma-separated (default: t_depth,t_bright,sr_a,sr_b)");
    cmd->add_option("--modes", c.modes, "Modes to score, comma-separated (default: interp,extrap,sr)");
    cmd->add_option("--blend", c.blend,
                    "Blend mode the frame-generation metric is taken with ('mix', the engine "
                    "default, or 'select': paper Eq. 1; T_B acts only with select)")
        ->check(CLI::IsMember({"mix", "select"}))
        ->capture_default_str();
    cmd->add_option("--t-depth", c.t_depth, "Start value of T_D (default: the current default)");
    cmd->add_option("--t-bright", c.t_bright, "Start value of T_B");
    cmd->add_option("--sr-a", c.sr_a, "Start value of a");
    cmd->add_option("--sr-b", c.sr_b, "Start value of b");
    cmd->add_option("--rounds", o.search.rounds, "Coordinate-ascent rounds")
        ->capture_default_str()
        ->check(CLI::Range(1, 20));
    cmd->add_option("--grid", o.search.grid, "Grid points per parameter in the first round")
        ->capture_default_str()
        ->check(CLI::Range(2, 100));
    cmd->add_option("--golden", o.search.golden, "Golden-section steps after each grid")
        ->capture_default_str()
        ->check(CLI::Range(0, 50));
    cmd->add_flag("--json", c.json, "Print one JSON object on stdout instead of the table");
    cmd->add_flag("--quiet", c.quiet, "No progress on stderr");
    return cmd;
}

int calibrate_main(CalibrateCli& c, CLI::App* cmd, int argc, char** argv) {
    CalibrateOptions& o = c.options;
    const auto& split = split_list;
    o.metric = c.metric == "ssim" ? CalMetric::ssim : CalMetric::psnr;
    if (!c.fit.empty()) o.fit = split(c.fit);
    if (!c.modes.empty()) o.modes = split(c.modes);
    o.start.blend = c.blend == "select" ? BlendMode::select : BlendMode::mix;
    if (cmd->count("--t-depth")) o.start.t_depth = c.t_depth;
    if (cmd->count("--t-bright")) o.start.t_bright = c.t_bright;
    if (cmd->count("--sr-a")) o.start.sr_a = c.sr_a;
    if (cmd->count("--sr-b")) o.start.sr_b = c.sr_b;
    if (cmd->count("--write-defaults"))
        o.write_defaults = c.write_defaults.empty()
                               ? std::filesystem::path("daemon/engine/include/fgsr/engine/defaults.hpp")
                               : std::filesystem::path(c.write_defaults);
    o.progress = !c.quiet;
    o.command_line = command_line_of(argc, argv);
    auto r = run_calibrate(o);
    if (!r) return report_error(r.error());
    std::fputs((c.json ? calibrate_json(*r) : calibrate_table(*r)).c_str(), stdout);
    return 0;
}

} // namespace fgsr::cli
