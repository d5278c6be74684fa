// `fgsr calibrate`: the search on known functions (header-only, called directly), and the real
// binary on the built-in capture (few frames, small searches) for the never-worse guarantee and
// --write-defaults.
#include "run_process.hpp"
#include <fgsr/cli/calibrate.hpp> // maximise_coordinates is header-only

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

using fgsr::cli::maximise_coordinates;
using fgsr::cli::SearchDim;
using fgsr::cli::SearchOptions;

using fgsr::test::run_process;

nlohmann::json calibrate_json(const std::string& args) {
    fgsr::test::ProcessRun r =
        run_process(std::string(FGSR_BIN_DIR) + "/fgsr calibrate --quiet --json " + args);
    EXPECT_EQ(r.status, 0) << args;
    return nlohmann::json::parse(r.out, nullptr, false);
}

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The C++ literal calibrate writes for a fitted value.
std::string literal(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    std::string s = buf;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return s + "f";
}

TEST(Calibrate, SearchFindsMaximumOfLogScaled1D) {
    // Peak at x = 0.0173 on a log axis [1e-3, 1], start far away.
    int calls = 0;
    auto f = [&](const std::vector<double>& x) {
        ++calls;
        const double d = std::log(x[0]) - std::log(0.0173);
        return -d * d;
    };
    auto r = maximise_coordinates(f, {{"t", 1e-3, 1.0, true}}, {0.5});
    ASSERT_EQ(r.x.size(), 1u);
    EXPECT_NEAR(std::log(r.x[0]), std::log(0.0173), 0.05); // within 5 %
    EXPECT_GE(r.value, r.start_value);
    EXPECT_EQ(r.evaluations, calls); // each distinct point evaluated once
    EXPECT_LE(calls, 40);
    EXPECT_FALSE(r.flat[0]);
}

TEST(Calibrate, SearchFindsMaximumOfCoupled2D) {
    // Concave quadratic with a cross term; the maximum (0.3, 1.4) is inside the box.
    auto f = [](const std::vector<double>& x) {
        const double u = x[0] - 0.3, v = x[1] - 1.4;
        return 5.0 - u * u - 2.0 * v * v - 0.8 * u * v;
    };
    SearchOptions o;
    o.rounds = 4;
    o.golden = 10;
    o.min_gain = 1e-9;
    auto r = maximise_coordinates(f, {{"a", 0.0, 1.0, false}, {"b", 0.0, 2.0, false}}, {0.9, 0.1}, o);
    EXPECT_NEAR(r.x[0], 0.3, 0.02);
    EXPECT_NEAR(r.x[1], 1.4, 0.02);
    EXPECT_NEAR(r.value, 5.0, 1e-3);
}

TEST(Calibrate, SearchNeverLeavesABetterStartAndDetectsFlatParameters) {
    // Start at the maximum of a function with plateaus: the result stays there.
    auto step = [](const std::vector<double>& x) {
        return std::abs(x[0] - 0.4) < 0.01 ? 1.0 : (x[0] < 0.4 ? 0.0 : 0.5);
    };
    auto r = maximise_coordinates(step, {{"s", 0.0, 1.0, false}}, {0.4});
    EXPECT_DOUBLE_EQ(r.x[0], 0.4);
    EXPECT_DOUBLE_EQ(r.value, 1.0);
    // A coordinate with no effect is marked flat and keeps its start value; the other is fitted.
    auto g = [](const std::vector<double>& x) { return -(x[0] - 0.7) * (x[0] - 0.7); };
    auto r2 = maximise_coordinates(g, {{"x", 0.0, 1.0, false}, {"unused", 0.01, 1.0, true}}, {0.1, 0.13});
    EXPECT_NEAR(r2.x[0], 0.7, 0.02);
    EXPECT_DOUBLE_EQ(r2.x[1], 0.13);
    EXPECT_FALSE(r2.flat[0]);
    EXPECT_TRUE(r2.flat[1]);
    // Quantisation: only quantised points are evaluated and returned.
    auto r3 = maximise_coordinates(g, {{"x", 0.0, 1.0, false}}, {0.1}, {},
                                   [](size_t, double v) { return std::round(v * 100.0) / 100.0; });
    EXPECT_DOUBLE_EQ(r3.x[0], 0.7);
}

TEST(Calibrate, FittedDepthThresholdIsNeverWorseThanTheDefaultStart) {
    // T_D on the built-in capture, interpolation only, few frames, a small search.
    nlohmann::json j = calibrate_json(
        "--capture builtin --frames 3 --modes interp --fit t_depth --rounds 1 --grid 5 --golden 3");
    ASSERT_FALSE(j.is_discarded());
    ASSERT_TRUE(j["modes"].contains("interp"));
    const double before = j["modes"]["interp"]["before"], after = j["modes"]["interp"]["after"];
    EXPECT_GT(before, 20.0); // a PSNR in dB
    EXPECT_GE(after, before);
    EXPECT_TRUE(j["params"]["t_depth"]["searched"].get<bool>());
    EXPECT_FALSE(j["params"]["sr_a"]["searched"].get<bool>());
    EXPECT_FALSE(j["modes"].contains("sr")); // not asked for (and builtin has no HR reference)

    // From a bad start (T_D = 1 accepts nearly every depth difference as the same surface) the
    // search improves the metric and moves T_D down.
    nlohmann::json b = calibrate_json("--capture builtin --frames 3 --modes interp --fit t_depth --t-depth 1 "
                                      "--rounds 1 --grid 5 --golden 2");
    ASSERT_FALSE(b.is_discarded());
    EXPECT_GT(b["modes"]["interp"]["after"].get<double>(),
              b["modes"]["interp"]["before"].get<double>() + 0.1);
    EXPECT_LT(b["params"]["t_depth"]["fitted"].get<double>(), 1.0);
}

TEST(Calibrate, WriteDefaultsWritesTheFittedConstants) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("fgsr-test-calibrate-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::filesystem::path fresh = dir / "fresh.hpp", edited = dir / "defaults.hpp";
    // An existing header (the repository's) is edited in place: structure and comments kept.
    const std::filesystem::path src = std::filesystem::path(__FILE__).parent_path().parent_path() /
                                      "daemon/engine/include/fgsr/engine/defaults.hpp";
    ASSERT_TRUE(std::filesystem::exists(src)) << src;
    std::filesystem::copy_file(src, edited);

    const std::string common = "--capture builtin --frames 2 --modes interp --fit t_depth --t-depth 1 "
                               "--rounds 1 --grid 3 --golden 0 ";
    nlohmann::json j = calibrate_json(common + "--write-defaults " + fresh.string());
    ASSERT_FALSE(j.is_discarded());
    EXPECT_EQ(j["written"], fresh.string());
    const double td = j["params"]["t_depth"]["fitted"];
    EXPECT_LT(td, 1.0);
    const std::string h = read_text(fresh);
    EXPECT_NE(h.find("#pragma once"), std::string::npos) << h;
    EXPECT_NE(h.find("namespace fgsr::defaults {"), std::string::npos) << h;
    EXPECT_NE(h.find("inline constexpr float t_depth = " + literal(td) + ";"), std::string::npos) << h;
    for (const char* c : {"t_bright", "sr_a", "sr_b"})
        EXPECT_NE(h.find(std::string("inline constexpr float ") + c + " = "), std::string::npos) << c << "\n"
                                                                                                 << h;
    EXPECT_NE(h.find("// Calibration ("), std::string::npos) << h;
    EXPECT_NE(h.find("): fgsr calibrate "), std::string::npos) << h; // the command line
    EXPECT_NE(h.find("--capture builtin"), std::string::npos) << h;
    EXPECT_NE(h.find("interp"), std::string::npos) << h;

    nlohmann::json k = calibrate_json(common + "--write-defaults " + edited.string());
    ASSERT_FALSE(k.is_discarded());
    const std::string before = read_text(src), e = read_text(edited);
    EXPECT_NE(e.find("inline constexpr float t_depth = " + literal(k["params"]["t_depth"]["fitted"]) + ";"),
              std::string::npos)
        << e;
    // Untouched constants keep their lines; the original comment stays above the record.
    for (const char* c : {"t_bright", "sr_a", "sr_b"}) {
        const std::string key = std::string("inline constexpr float ") + c + " ";
        const size_t p = before.find(key);
        ASSERT_NE(p, std::string::npos) << c;
        const std::string line = before.substr(p, before.find('\n', p) - p);
        EXPECT_NE(e.find(line), std::string::npos) << line << "\n" << e;
    }
    EXPECT_NE(e.find(before.substr(0, before.find('\n'))), std::string::npos);
    EXPECT_LT(e.find("// Calibration ("), e.find("#pragma once"));

    // Compiles: a translation unit including it checks the value (skipped without a compiler).
    if (run_process("command -v c++ >/dev/null 2>&1").status == 0) {
        const std::filesystem::path tu = dir / "check.cpp";
        std::ofstream(tu) << "#include \"" << edited.string()
                          << "\"\nstatic_assert(fgsr::defaults::t_depth == "
                          << literal(k["params"]["t_depth"]["fitted"])
                          << ");\nstatic_assert(fgsr::defaults::sr_b > 0.f);\n";
        EXPECT_EQ(run_process("c++ -std=c++20 -fsyntax-only " + tu.string() + " 2>&1").status, 0);
    }
    std::filesystem::remove_all(dir);
}

} // namespace
