// `fgsr bench` and the quality presets: what can fail without timing. The Pareto front on
// hand-made points, the memory-traffic formula on a known size, the presets' Params against what
// presets.hpp claims, and a --quick run of the real binary (CSV rows and finite numbers).
#include "run_process.hpp"
#include <fgsr/cli/bench.hpp> // median, pareto_front, parse_resolution, frame_bytes are inline

#include <fgsr/engine/presets.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using fgsr::cli::pareto_front;
using fgsr::cli::ParetoPoint;

TEST(Bench, MedianOddEvenEmpty) {
    EXPECT_EQ(fgsr::cli::median({5, 1, 3}), 3);
    EXPECT_EQ(fgsr::cli::median({4, 1, 3, 2}), 2.5);
    EXPECT_TRUE(std::isnan(fgsr::cli::median({})));
}

TEST(Bench, ParetoFrontOfHandMadePoints) {
    // ms, PSNR: a fast/poor, b slow/good, c dominated by a (slower and worse), d dominated by b
    // (same time, worse), e equal to b (both stay), f NaN (never on the front, dominates nothing).
    const std::vector<ParetoPoint> pts{{10, 30}, {20, 35}, {12, 29}, {20, 34}, {20, 35}, {NAN, 40}, {15, 33}};
    const std::vector<bool> front = pareto_front(pts);
    const std::vector<bool> expected{true, true, false, false, true, false, true};
    EXPECT_EQ(front, expected);
}

TEST(Bench, ParetoFrontSinglePointAndTies) {
    EXPECT_EQ(pareto_front({{5, 20}}), std::vector<bool>{true});
    // Same accuracy: only the fastest; same time: only the most accurate.
    EXPECT_EQ(pareto_front({{5, 20}, {6, 20}, {5, 19}}), (std::vector<bool>{true, false, false}));
    EXPECT_TRUE(pareto_front({}).empty());
    // Within the PSNR tolerance (0.01 dB by default) the faster point wins; beyond it both stay.
    EXPECT_EQ(pareto_front({{5, 30.000}, {6, 30.005}}), (std::vector<bool>{true, false}));
    EXPECT_EQ(pareto_front({{5, 30.000}, {6, 30.005}}, 0.0), (std::vector<bool>{true, true}));
    EXPECT_EQ(pareto_front({{5, 30.00}, {6, 30.02}}), (std::vector<bool>{true, true}));
}

TEST(Bench, ResolutionNames) {
    auto r = fgsr::cli::parse_resolution("720p");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->width, 1280u);
    EXPECT_EQ(r->height, 720u);
    EXPECT_EQ(fgsr::cli::parse_resolution("540p")->width, 960u);
    EXPECT_EQ(fgsr::cli::parse_resolution("2160p")->width, 3840u);
    EXPECT_EQ(fgsr::cli::parse_resolution("640x360")->height, 360u);
    EXPECT_FALSE(fgsr::cli::parse_resolution("720"));
    EXPECT_FALSE(fgsr::cli::parse_resolution("0p"));
    EXPECT_FALSE(fgsr::cli::parse_resolution("20000x10"));
    EXPECT_FALSE(fgsr::cli::parse_resolution("-5p"));
}

TEST(Bench, FrameBytesOnKnownSize) {
    // 100x50 = 5000 pixels. Fused quadratic interpolation: splat R 32 W 32, generate R 48 W 16 per
    // pixel (bench.hpp formula) = 128 B/px.
    fgsr::Params p = fgsr::preset_params(fgsr::Preset::balanced);
    auto b = fgsr::cli::frame_bytes(fgsr::cli::EvalMode::interp, p, 100, 50);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_EQ(b[0].pass, "splat");
    EXPECT_EQ(b[0].read, 32u * 5000);
    EXPECT_EQ(b[0].written, 32u * 5000);
    EXPECT_EQ(b[1].pass, "generate");
    EXPECT_EQ(b[1].read, 48u * 5000);
    EXPECT_EQ(b[1].written, 16u * 5000);
    EXPECT_EQ(fgsr::cli::total_bytes(b), 128u * 5000);
    // Linear motion reads no frame-0 vectors / depth (12 B/px less); extrapolation no frame 0.
    p.motion = fgsr::MotionModel::linear;
    EXPECT_EQ(fgsr::cli::total_bytes(fgsr::cli::frame_bytes(fgsr::cli::EvalMode::extrap, p, 100, 50)),
              (20u + 32 + 36 + 16) * 5000);
    // Separate passes of interpolation with holes: splat 64 + refine 48 + disocc 48 + warp 80 + blend 60.
    p = fgsr::preset_params(fgsr::Preset::balanced);
    p.separate_passes = true;
    auto sep = fgsr::cli::frame_bytes(fgsr::cli::EvalMode::interp, p, 100, 50);
    ASSERT_EQ(sep.size(), 5u);
    EXPECT_EQ(fgsr::cli::total_bytes(sep), (64u + 48 + 48 + 80 + 60) * 5000);
    // SR 2x: 24 B per input pixel + 32 B per output pixel.
    EXPECT_EQ(fgsr::cli::total_bytes(fgsr::cli::frame_bytes(fgsr::cli::EvalMode::sr, p, 100, 50, 200, 100)),
              24u * 5000 + 32u * 20000);
}

TEST(Presets, MapToTheParamsTheyClaim) {
    // What presets.hpp's comment promises, field by field.
    const fgsr::Params perf = *fgsr::preset_params("performance");
    EXPECT_EQ(perf.motion, fgsr::MotionModel::linear);
    EXPECT_EQ(perf.resample, fgsr::Resample::bilinear);
    EXPECT_FALSE(perf.fill_gaps);
    EXPECT_TRUE(perf.fill_holes);
    EXPECT_EQ(perf.blend, fgsr::BlendMode::select);
    EXPECT_FALSE(perf.dilate_mvs);
    EXPECT_FALSE(perf.separate_passes);
    EXPECT_TRUE(perf.fast_motion);

    const fgsr::Params bal = *fgsr::preset_params("balanced");
    EXPECT_EQ(bal.motion, fgsr::MotionModel::quadratic);
    EXPECT_EQ(bal.resample, fgsr::Resample::bilinear);
    EXPECT_TRUE(bal.fill_gaps);
    EXPECT_TRUE(bal.fill_holes);
    EXPECT_EQ(bal.blend, fgsr::BlendMode::mix);
    EXPECT_FALSE(bal.dilate_mvs);
    EXPECT_FALSE(bal.separate_passes);
    EXPECT_FALSE(bal.fast_motion);

    const fgsr::Params q = *fgsr::preset_params("quality");
    EXPECT_EQ(q.motion, fgsr::MotionModel::quadratic);
    EXPECT_EQ(q.resample, fgsr::Resample::lut);
    EXPECT_TRUE(q.fill_gaps);
    EXPECT_TRUE(q.fill_holes);
    EXPECT_EQ(q.blend, fgsr::BlendMode::mix);
    EXPECT_TRUE(q.dilate_mvs);
    EXPECT_FALSE(q.separate_passes);
    EXPECT_FALSE(q.fast_motion);
    EXPECT_TRUE(q.accel_depth_motion); // as the default Params (docs/ACCURACY.md, changes 21, 23)
    EXPECT_FALSE(bal.accel_depth_motion);
    EXPECT_FALSE(perf.accel_depth_motion);
    EXPECT_EQ(perf.warp_kernel, fgsr::WarpKernel::bilinear); // the cubic's reads cost (change 39)
    EXPECT_EQ(bal.warp_kernel, fgsr::WarpKernel::automatic);
    EXPECT_EQ(q.warp_kernel, fgsr::WarpKernel::automatic);
    EXPECT_TRUE(fgsr::Params{}.accel_depth_motion);

    // Calibrated thresholds and the scene-cut check in every preset.
    for (const fgsr::Params& p : {perf, bal, q}) {
        EXPECT_TRUE(p.vector_cuts);
        EXPECT_EQ(p.t_depth, fgsr::defaults::t_depth);
        EXPECT_EQ(p.sr_a, fgsr::defaults::sr_a);
        EXPECT_EQ(p.scale, 1.f);
    }
    auto bad = fgsr::preset_params("fastest");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("fastest"), std::string::npos);
}

TEST(Presets, SwitchesApplyAndToggle) {
    fgsr::Params p = *fgsr::preset_params("balanced");
    ASSERT_TRUE(fgsr::apply_switch(p, "motion=linear"));
    EXPECT_EQ(p.motion, fgsr::MotionModel::linear);
    ASSERT_TRUE(fgsr::apply_switch(p, "resample=catmull_rom"));
    EXPECT_EQ(p.resample, fgsr::Resample::catmull_rom);
    ASSERT_TRUE(fgsr::apply_switch(p, "passes=separate"));
    EXPECT_TRUE(p.separate_passes);
    ASSERT_TRUE(fgsr::apply_switch(p, "fill_holes=off"));
    EXPECT_FALSE(p.fill_holes);
    ASSERT_TRUE(fgsr::apply_switch(p, "fast_motion=on"));
    EXPECT_TRUE(p.fast_motion);
    ASSERT_TRUE(fgsr::apply_switch(p, "fast_motion=off"));
    EXPECT_FALSE(p.fast_motion);
    EXPECT_EQ(p.dilate_edges, 0.f); // balanced leaves the edge rule out
    ASSERT_TRUE(fgsr::apply_switch(p, "dilate_edges=on"));
    EXPECT_EQ(p.dilate_edges, fgsr::defaults::dilate_edges);
    EXPECT_FALSE(p.accel_search); // balanced leaves extrapolation's search out
    ASSERT_TRUE(fgsr::apply_switch(p, "accel_search=on"));
    EXPECT_TRUE(p.accel_search);
    EXPECT_FALSE(p.accel_median); // balanced leaves interpolation's median out
    ASSERT_TRUE(fgsr::apply_switch(p, "accel_median=on"));
    EXPECT_TRUE(p.accel_median);
    EXPECT_FALSE(p.accel_depth_motion); // balanced leaves the motion's depth expectation out
    ASSERT_TRUE(fgsr::apply_switch(p, "accel_depth=on"));
    EXPECT_TRUE(p.accel_depth_motion);
    EXPECT_TRUE(p.cover_edges); // balanced has the edge cover
    ASSERT_TRUE(fgsr::apply_switch(p, "cover_edges=off"));
    EXPECT_FALSE(p.cover_edges);
    EXPECT_TRUE(p.vector_cuts); // every preset checks for scene cuts
    ASSERT_TRUE(fgsr::apply_switch(p, "vector_cuts=off"));
    EXPECT_FALSE(p.vector_cuts);
    EXPECT_TRUE(p.motion_consensus); // every preset has the block matching's consensus
    ASSERT_TRUE(fgsr::apply_switch(p, "motion_consensus=off"));
    EXPECT_FALSE(p.motion_consensus);
    EXPECT_EQ(p.warp_kernel, fgsr::WarpKernel::automatic); // balanced chooses the warp by the input
    EXPECT_EQ(fgsr::switch_value(p, "warp"), "auto");
    ASSERT_TRUE(fgsr::apply_switch(p, "warp=cubic"));
    EXPECT_EQ(p.warp_kernel, fgsr::WarpKernel::cubic);
    ASSERT_TRUE(fgsr::apply_switch(p, "warp=bilinear"));
    EXPECT_EQ(p.warp_kernel, fgsr::WarpKernel::bilinear);
    EXPECT_EQ(fgsr::switch_value(p, "warp"), "bilinear");
    const fgsr::Params before = p;
    auto e = fgsr::apply_switch(p, "motion=cubic");
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().message.find("cubic"), std::string::npos);
    EXPECT_FALSE(fgsr::apply_switch(p, "warp=fast"));
    EXPECT_FALSE(fgsr::apply_switch(p, "warp_drive=on"));
    EXPECT_FALSE(fgsr::apply_switch(p, "fill_gaps"));
    EXPECT_EQ(p.motion, before.motion); // errors leave p unchanged
    EXPECT_EQ(p.fill_gaps, before.fill_gaps);

    // From balanced, every toggle changes exactly the switch it names.
    const fgsr::Params base = *fgsr::preset_params("balanced");
    const std::vector<std::string> toggles = fgsr::switch_toggles(base);
    const std::set<std::string> expected{
        "motion=linear",   "resample=catmull_rom", "resample=lut",    "fill_gaps=off",
        "fill_holes=off",  "blend=select",         "dilate_mvs=on",   "denoise=off",
        "passes=separate", "correct_vectors=on",   "fast_motion=on",  "dilate_edges=on",
        "accel_search=on", "accel_median=on",      "accel_depth=on",  "blend_depth=off",
        "cover_edges=off", "hole_frame0=off",      "vector_cuts=off", "motion_consensus=off",
        "colour_agree=on", "warp=bilinear",        "warp=cubic",      "motion_search=off"};
    EXPECT_EQ(std::set<std::string>(toggles.begin(), toggles.end()), expected);
    for (const std::string& t : toggles) {
        fgsr::Params x = base;
        ASSERT_TRUE(fgsr::apply_switch(x, t));
        const std::string key = t.substr(0, t.find('='));
        for (const fgsr::SwitchInfo& s : fgsr::kSwitches)
            if (s.key == key)
                EXPECT_EQ(fgsr::switch_value(x, s.key), t.substr(t.find('=') + 1)) << t;
            else
                EXPECT_EQ(fgsr::switch_value(x, s.key), fgsr::switch_value(base, s.key))
                    << t << " changed " << s.key;
    }
}

// The kernels' names: one per kernel, read back to the same kernel, the "resample" switch's values;
// other names (the method names of fgsr eval, case variants) are none.
TEST(Presets, ResampleNamesRoundTrip) {
    const fgsr::SwitchInfo* info = nullptr;
    for (const fgsr::SwitchInfo& s : fgsr::kSwitches)
        if (s.key == "resample") info = &s;
    ASSERT_NE(info, nullptr);
    std::set<std::string_view> names;
    for (fgsr::Resample r : {fgsr::Resample::bilinear, fgsr::Resample::catmull_rom, fgsr::Resample::lut}) {
        const std::string_view name = fgsr::resample_name(r);
        names.insert(name);
        EXPECT_EQ(fgsr::resample_from_name(name), r) << name;
        EXPECT_NE(std::find(info->values.begin(), info->values.end(), name), info->values.end()) << name;
    }
    EXPECT_EQ(names.size(), 3u);
    for (const char* other : {"", "bicubic", "fgsr-bilinear", "LUT", "lut "})
        EXPECT_FALSE(fgsr::resample_from_name(other)) << other;
}

std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::string line;
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;
    auto split = [](const std::string& s) {
        std::vector<std::string> out;
        std::stringstream ss(s);
        std::string item;
        while (std::getline(ss, item, ',')) out.push_back(item);
        if (!s.empty() && s.back() == ',') out.push_back("");
        return out;
    };
    if (!std::getline(in, line)) return rows;
    header = split(line);
    while (std::getline(in, line)) {
        const std::vector<std::string> cells = split(line);
        EXPECT_EQ(cells.size(), header.size()) << line;
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
        rows.push_back(row);
    }
    return rows;
}

TEST(Bench, QuickRunWritesExpectedCsv) {
    const std::filesystem::path out = std::filesystem::path(testing::TempDir()) / "fgsr_bench_quick";
    std::filesystem::remove_all(out);
    const fgsr::test::ProcessRun r = fgsr::test::run_process(
        std::string(FGSR_BIN_DIR) + "/fgsr bench --quick --no-plots --no-moving-run --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.out;
    {
        std::ifstream in(out / "bench.md");
        const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_NE(md.find("## Still against moving"), std::string::npos) << md;
        EXPECT_EQ(md.find("consecutive calls"), std::string::npos) << "--no-moving-run";
    }
    const auto rows = read_csv(out / "bench.csv");
    // builtin: interp (3 presets + 7 switches that act on it), extrap (no blend switch), and each
    // on colour alone (balanced+colour, balanced+colour+fast_motion=on and +motion_search=off).
    std::set<std::string> got, expected;
    for (const char* c : {"performance", "balanced", "quality", "balanced+motion=linear",
                          "balanced+fill_gaps=off", "balanced+fill_holes=off", "balanced+passes=separate",
                          "balanced+correct_vectors=on", "balanced+colour_agree=on", "balanced+colour",
                          "balanced+colour+fast_motion=on", "balanced+colour+motion_search=off"}) {
        expected.insert(std::string("interp ") + c);
        expected.insert(std::string("extrap ") + c);
    }
    expected.insert("interp balanced+blend=select");
    size_t pareto = 0;
    for (const auto& row : rows) {
        EXPECT_EQ(row.at("capture"), "synthetic-toss");
        got.insert(row.at("mode") + " " + row.at("config"));
        for (const char* k : {"ms_median", "psnr", "ssim", "splat_ms"}) {
            const double v = std::stod(row.at(k));
            EXPECT_TRUE(std::isfinite(v) && v > 0) << k << " = " << row.at(k) << " in " << row.at("config");
        }
        EXPECT_LE(std::stod(row.at("ssim")), 1.0);
        EXPECT_GT(std::stod(row.at("psnr")), 15.0); // generated frames resemble the ground truth
        pareto += row.at("pareto") == "yes";
        // Colour-only rows: the EPE of the estimated vectors and the motion passes' time (0 until
        // the engine times them); corrected-vector rows: the same of the corrected vectors (the
        // synthetic scene's vectors are exact: few pixels change); the others have neither.
        if (row.at("config").starts_with("balanced+colour+") || row.at("config") == "balanced+colour") {
            EXPECT_EQ(row.at("switch"), row.at("config") == "balanced+colour"
                                            ? std::string("input=colour")
                                            : "input=colour " + row.at("config").substr(16));
            const double epe = std::stod(row.at("epe"));
            EXPECT_TRUE(std::isfinite(epe) && epe > 0) << row.at("epe"); // the scene moves
            EXPECT_GE(std::stod(row.at("motion_ms")), 0.0);
        } else if (row.at("config") == "balanced+colour_agree=on" || row.at("config") == "quality") {
            // The colour twin's motion passes are timed (quality agrees since change 41); no
            // vector of its own is scored.
            EXPECT_EQ(row.at("epe"), "");
            EXPECT_GT(std::stod(row.at("motion_ms")), 0.0);
        } else if (row.at("config") == "balanced+correct_vectors=on") {
            const double epe = std::stod(row.at("epe"));
            EXPECT_TRUE(std::isfinite(epe) && epe >= 0 && epe < 0.5) << row.at("epe");
            EXPECT_GT(std::stod(row.at("motion_ms")), 0.0);
        } else {
            EXPECT_EQ(row.at("epe"), "") << row.at("config");
            EXPECT_EQ(row.at("motion_ms"), "") << row.at("config");
        }
    }
    EXPECT_EQ(got, expected);
    EXPECT_EQ(rows.size(), expected.size());
    EXPECT_GE(pareto, 2u); // at least one per mode
    const auto scaling = read_csv(out / "scaling.csv");
    ASSERT_EQ(scaling.size(), 1u);
    EXPECT_EQ(scaling[0].at("width"), "320");
    EXPECT_GT(std::stod(scaling[0].at("x_memcpy")), 0.0);
    EXPECT_EQ(read_csv(out / "alphas.csv").size(), 2u);
    // The frames-per-pair table names each pass with its median and how many of the 2 calls of
    // --quick ran it: splat and generate run in every call, at 1 and 2 frames per call.
    std::ifstream in(out / "bench.md");
    const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t table = md.find("## Frames generated per pair");
    ASSERT_NE(table, std::string::npos) << md;
    for (const char* count : {"\n| 1 | ", "\n| 2 | "}) {
        const size_t row = md.find(count, table);
        ASSERT_NE(row, std::string::npos) << count << " in " << md;
        const std::string line = md.substr(row + 1, md.find('\n', row + 1) - row - 1);
        for (const char* pass : {"generate ", "splat "}) {
            const size_t at = line.find(pass);
            ASSERT_NE(at, std::string::npos) << pass << " in " << line;
            std::stringstream ss(line.substr(at + std::string(pass).size()));
            double ms = 0;
            std::string calls;
            ss >> ms >> calls;
            EXPECT_GT(ms, 0.0) << line;
            EXPECT_EQ(calls.substr(0, 3), "(2)") << line;
        }
    }
    std::filesystem::remove_all(out);
}

// The numbers of a bench.md still-against-moving row "| <label>: A ms | B ms | R |" (A, B, R).
std::vector<double> still_row(const std::string& md, const std::string& label) {
    const size_t at = md.find("| " + label + ": ");
    if (at == std::string::npos) return {};
    std::stringstream ss(md.substr(at + label.size() + 4, md.find('\n', at) - at - label.size() - 4));
    double a = 0, b = 0, r = 0;
    std::string ms1, bar1, ms2, bar2;
    ss >> a >> ms1 >> bar1 >> b >> ms2 >> bar2 >> r;
    if (!ss || ms1 != "ms" || bar1 != "|" || ms2 != "ms" || bar2 != "|") return {};
    return {a, b, r};
}

TEST(Bench, StillOnlyRunsJustStillAgainstMoving) {
    const std::filesystem::path out = std::filesystem::path(testing::TempDir()) / "fgsr_bench_still";
    std::filesystem::remove_all(out);
    const fgsr::test::ProcessRun r = fgsr::test::run_process(
        std::string(FGSR_BIN_DIR) + "/fgsr bench --quick --still-only --no-plots --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_TRUE(read_csv(out / "bench.csv").empty()) << "no capture rows";
    EXPECT_TRUE(read_csv(out / "scaling.csv").empty()) << "no scaling rows";
    EXPECT_TRUE(read_csv(out / "alphas.csv").empty()) << "no frames-per-pair rows";
    std::ifstream in(out / "bench.md");
    const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("## Still against moving (180p"), std::string::npos) << md;
    const std::vector<double> call = still_row(md, "interpolate call");
    const std::vector<double> frame = still_row(md, "per frame (ingest of the new input + call)");
    ASSERT_EQ(call.size(), 3u) << md;
    ASSERT_EQ(frame.size(), 3u) << md;
    for (int k = 0; k < 2; ++k) {
        EXPECT_GT(call[size_t(k)], 0.0);
        // Every sample adds a positive ingest time to its call, so each median grows.
        EXPECT_GT(frame[size_t(k)], call[size_t(k)]) << (k ? "moving" : "still");
    }
    // Motion estimation timed too, by default and fast: at 320x180 the default refines the estimate
    // (a polish pass), the fast setting does not.
    const size_t colour = md.find("## Colour only (180p");
    ASSERT_NE(colour, std::string::npos) << md;
    for (const char* setting : {"\n| default | ", "\n| fast | "}) {
        const size_t at = md.find(setting, colour);
        ASSERT_NE(at, std::string::npos) << setting << " in " << md.substr(colour);
        const std::string line = md.substr(at + 1, md.find('\n', at + 1) - at - 1);
        EXPECT_NE(line.find("match "), std::string::npos) << line;
        EXPECT_EQ(line.find("polish ") != std::string::npos, std::string(setting) == "\n| default | ")
            << line;
    }
    // The moving run (64 calls for --quick): the synthetic scene moves everywhere, so the calls
    // that classify are the first and the probes after 7, 15 and 31 plain calls: 0, 8, 24, 56.
    const size_t run = md.find("## Moving, 64 consecutive calls (180p");
    ASSERT_NE(run, std::string::npos) << md;
    const size_t run_row = md.find("\n| 4 of 64 | ", run);
    ASSERT_NE(run_row, std::string::npos) << md.substr(run);
    std::stringstream rs(md.substr(run_row + 12));
    double probe_ms = 0, plain_ms = 0, mean_ms = 0;
    std::string u1, b1, u2, b2, u3;
    rs >> probe_ms >> u1 >> b1 >> plain_ms >> u2 >> b2 >> mean_ms >> u3;
    ASSERT_TRUE(rs && u1 == "ms" && u2 == "ms" && u3 == "ms") << md.substr(run_row, 120);
    EXPECT_GT(probe_ms, 0.0);
    EXPECT_GT(plain_ms, 0.0);
    EXPECT_GT(mean_ms, 0.0);
    // All three are printed with 2 decimals: the ratio is off by its own rounding (0.005) plus what
    // the rounding of the two times (0.005 each) does to their quotient.
    const auto tolerance = [](double a, double b) { return 0.005 + 0.005 * (1.0 + a / b) / b + 1e-9; };
    EXPECT_NEAR(call[2], call[0] / call[1], tolerance(call[0], call[1]));
    EXPECT_NEAR(frame[2], frame[0] / frame[1], tolerance(frame[0], frame[1]));
    std::filesystem::remove_all(out);
}

} // namespace
