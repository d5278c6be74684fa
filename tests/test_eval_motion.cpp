// Motion in `fgsr eval` (fgsr/cli/eval_motion.hpp): the colour-only method fgsr-colour in the
// JSON, the EPE reference (a session given the capture's vectors scores 0 against it), and
// --vectors-from with the capture's own vectors written as .flo files (EPE 0) or malformed ones.
#include "engine_fixture.hpp"
#include "run_process.hpp"

#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/eval.hpp>
#include <fgsr/cli/eval_motion.hpp>

#include <fgsr/capture/flow_io.hpp>
#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/synthetic.hpp>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace fgsr::test {
namespace {

ProcessRun run_fgsr(const std::string& args) {
    return run_process(std::string(FGSR_BIN_DIR) + "/fgsr " + args);
}

nlohmann::json eval_json(const std::string& args) {
    ProcessRun r = run_fgsr("eval --quiet --json " + args);
    EXPECT_EQ(r.status, 0) << args;
    return nlohmann::json::parse(r.out, nullptr, false);
}

bool finite_number(const nlohmann::json& v) {
    return v.is_number() && std::isfinite(v.get<double>());
}

// A scratch directory per test, removed at the end.
class EvalMotion : public testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("fgsr-test-eval-motion-" + std::to_string(::getpid()) + "-" +
                testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // The built-in capture's vectors of inputs 1.. in the internal convention, as .flo files.
    void write_capture_flow(const capture::Capture& cap) {
        for (size_t k = 1; k < cap.inputs.size(); ++k) {
            const ref::InternalFrame f = ref::ingest(cap.format, cap.inputs[k].view());
            ASSERT_TRUE(f.has_mv) << k;
            capture::FlowField flow;
            flow.width = f.width;
            flow.height = f.height;
            for (const glm::vec2& v : f.mv) {
                flow.xy.push_back(v.x);
                flow.xy.push_back(v.y);
            }
            ASSERT_TRUE(capture::write_flo(dir_ / fmt::format("{:04d}.flo", k), flow));
        }
    }
    std::filesystem::path dir_;
};

TEST_F(EvalMotion, ColourMethodIsInTheJsonWithFiniteFigures) {
    for (const char* mode : {"interp", "extrap"}) {
        // The default method list has fgsr-colour.
        nlohmann::json j = eval_json(std::string("--capture builtin --frames 3 --mode ") + mode);
        ASSERT_FALSE(j.is_discarded()) << mode;
        ASSERT_TRUE(j["methods"].contains("fgsr-colour")) << j.dump();
        const nlohmann::json& c = j["methods"]["fgsr-colour"];
        for (const char* key : {"psnr", "ssim", "ms", "epe"})
            EXPECT_TRUE(finite_number(c[key])) << mode << " " << key << " = " << c[key];
        EXPECT_GT(c["psnr"].get<double>(), 15.0) << mode;
        EXPECT_GT(c["ms"].get<double>(), 0.0) << mode;
        // The builtin scene moves; no estimate matches the analytic vectors to the last bit, so an
        // EPE of exactly 0 would mean the scoring compared a field with itself.
        EXPECT_GT(c["epe"].get<double>(), 0.0) << mode;
        EXPECT_FALSE(j["methods"]["fgsr"].contains("epe")) << "fgsr gets the capture's vectors";
    }
    // The table names the method and the EPE column.
    ProcessRun t = run_fgsr("eval --quiet --capture builtin --frames 2 --methods fgsr,fgsr-colour");
    ASSERT_EQ(t.status, 0);
    EXPECT_NE(t.out.find("fgsr-colour"), std::string::npos) << t.out;
    EXPECT_NE(t.out.find("EPE px"), std::string::npos) << t.out;
}

// The reference scored against a session that holds the capture's own vectors: 0 on every frame
// with vectors; a session without them (colour only: zero vectors until the engine estimates)
// scores the mean motion of the visible pixels, > 0 on a moving scene.
TEST_F(EvalMotion, ReferenceSessionScoresZeroAgainstItself) {
    auto cap = cli::load_capture_spec("builtin", false, 5);
    ASSERT_TRUE(cap) << cap.error().message;
    // The given vectors as the capture has them: the dilate stage's edge rule moves them at depth
    // edges on purpose (shaders/dilate.h).
    Params keep;
    keep.dilate_edges = 0.f;
    auto given = engine().create_session(cap->format, keep);
    ASSERT_TRUE(given) << given.error().message;
    auto colour = engine().create_session(cli::colour_only(cap->format));
    ASSERT_TRUE(colour) << colour.error().message;
    cli::VectorReference reference(cap->format);
    cli::MethodScore self, est;
    for (const capture::Frame& f : cap->inputs) {
        ASSERT_TRUE((*given)->submit(f.view()));
        ASSERT_TRUE((*colour)->submit(cli::session_view((*colour)->format(), f.view())));
        ASSERT_TRUE(reference.add_frame(f.view()));
        ASSERT_TRUE(reference.score(**given, self));
        ASSERT_TRUE(reference.score(**colour, est));
    }
    ASSERT_EQ(self.epe.size(), cap->inputs.size() - 1) << "every input after the first is scored";
    for (double e : self.epe) EXPECT_NEAR(e, 0.0, 1e-6);
    ASSERT_EQ(est.epe.size(), self.epe.size());
    for (double e : est.epe) EXPECT_TRUE(std::isfinite(e) && e >= 0.0) << e;
    // Session views of a colour-only session carry neither vectors nor depth.
    const FrameView v = cli::session_view((*colour)->format(), cap->inputs[1].view());
    EXPECT_TRUE(v.mv.empty());
    EXPECT_TRUE(v.depth.empty());
    EXPECT_FALSE(v.color.empty());
    expect_no_validation_errors();
}

TEST_F(EvalMotion, VectorsFromTheCapturesOwnFlowScoreZero) {
    auto cap = cli::load_capture_spec("builtin");
    ASSERT_TRUE(cap) << cap.error().message;
    write_capture_flow(*cap);
    nlohmann::json j =
        eval_json("--capture builtin --frames 4 --methods fgsr,blend --vectors-from " + dir_.string());
    ASSERT_FALSE(j.is_discarded());
    const nlohmann::json& f = j["methods"]["fgsr"];
    ASSERT_TRUE(finite_number(f["epe"])) << f.dump();
    EXPECT_NEAR(f["epe"].get<double>(), 0.0, 1e-4);
    EXPECT_TRUE(finite_number(f["psnr"])) << f.dump();
    // The vectors are right, the depth is withheld: still far better than a blend.
    EXPECT_GT(f["psnr"].get<double>(), j["methods"]["blend"]["psnr"].get<double>() + 3.0) << j.dump();

    // Vectors scaled by 1.5: the EPE is half the mean vector length, > 0.
    for (size_t k = 1; k < cap->inputs.size(); ++k) {
        const std::filesystem::path p = dir_ / fmt::format("{:04d}.flo", k);
        auto flow = capture::read_flo(p);
        ASSERT_TRUE(flow);
        for (float& v : flow->xy) v *= 1.5f;
        ASSERT_TRUE(capture::write_flo(p, *flow));
    }
    nlohmann::json s =
        eval_json("--capture builtin --frames 4 --methods fgsr --vectors-from " + dir_.string());
    ASSERT_FALSE(s.is_discarded());
    EXPECT_GT(s["methods"]["fgsr"]["epe"].get<double>(), 0.1) << s.dump();
}

TEST_F(EvalMotion, OutWritesTheScoredVectorsForVectorsFrom) {
    // eval --out writes fgsr-colour's vectors and the capture's, in --vectors-from's layout.
    const std::filesystem::path out = dir_ / "out";
    nlohmann::json a = eval_json("--capture builtin --frames 3 --methods fgsr-colour --out " + out.string());
    ASSERT_FALSE(a.is_discarded());
    const double epe = a["methods"]["fgsr-colour"]["epe"].get<double>();
    EXPECT_GT(epe, 0.0);
    ASSERT_TRUE(std::filesystem::exists(out / "fgsr-colour" / "flow" / "0001.flo"));
    ASSERT_TRUE(std::filesystem::exists(out / "reference" / "flow" / "0001-visible.png"));
    // The capture's own vectors, fed back, score zero.
    nlohmann::json r = eval_json("--capture builtin --frames 3 --methods fgsr --vectors-from " +
                                 (out / "reference" / "flow").string());
    ASSERT_FALSE(r.is_discarded());
    EXPECT_NEAR(r["methods"]["fgsr"]["epe"].get<double>(), 0.0, 1e-4) << r.dump();
    // The estimated vectors, fed back, score what fgsr-colour reported for them.
    nlohmann::json c = eval_json("--capture builtin --frames 3 --methods fgsr --vectors-from " +
                                 (out / "fgsr-colour" / "flow").string());
    ASSERT_FALSE(c.is_discarded());
    EXPECT_NEAR(c["methods"]["fgsr"]["epe"].get<double>(), epe, 1e-4) << c.dump();
}

TEST_F(EvalMotion, VectorsFromRefusesBadFlowFiles) {
    auto cap = cli::load_capture_spec("builtin");
    ASSERT_TRUE(cap) << cap.error().message;
    write_capture_flow(*cap);
    const std::string args = "eval --quiet --capture builtin --frames 2 --methods fgsr --vectors-from ";
    // A truncated file.
    std::filesystem::resize_file(dir_ / "0002.flo", std::filesystem::file_size(dir_ / "0002.flo") - 4);
    ProcessRun r = run_fgsr(args + dir_.string() + " 2>&1");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("0002.flo"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("truncated"), std::string::npos) << r.out;
    // A field of another size.
    capture::FlowField small{4, 4, std::vector<float>(32, 0.f)};
    ASSERT_TRUE(capture::write_flo(dir_ / "0002.flo", small));
    r = run_fgsr(args + dir_.string() + " 2>&1");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("4x4"), std::string::npos) << r.out;
    // A missing file, and a directory that does not exist.
    std::filesystem::remove(dir_ / "0001.flo");
    r = run_fgsr(args + dir_.string() + " 2>&1");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("0001.flo"), std::string::npos) << r.out;
    r = run_fgsr(args + (dir_ / "nowhere").string() + " 2>&1");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("not a directory"), std::string::npos) << r.out;
    // Only frame generation takes it.
    r = run_fgsr("eval --quiet --mode sr --capture builtin --vectors-from " + dir_.string() + " 2>&1");
    EXPECT_NE(r.status, 0);
}

// A colour-only frame's time adds the motion passes of its newest input's submit as passes of
// their own; eval's fgsr-colour reports them in pass_ms, and its ms is larger than its generate
// call's passes alone by their sum.
TEST(EvalMotionTiming, MotionPassesAddToTheFrame) {
    GeneratedFrame f;
    f.gpu_ms = 10.0;
    PassTiming splat, luma, match;
    splat.name = "splat";
    splat.ms = 10.0;
    luma.name = "luma";
    luma.ms = 1.25;
    match.name = "match";
    match.ms = 2.5;
    f.passes = {splat};
    const GeneratedFrame g = cli::with_motion_timings(f, {luma, match});
    EXPECT_DOUBLE_EQ(g.gpu_ms, 13.75);
    ASSERT_EQ(g.passes.size(), 3u);
    EXPECT_EQ(g.passes[1].name, "luma");
    EXPECT_EQ(g.passes[2].name, "match");
    cli::MethodScore score;
    cli::add_timing(score, g);
    EXPECT_DOUBLE_EQ(score.pass_ms["match"], 2.5);
    // A pass that ran twice for one frame (colour_agree's two fields) is one sample, its runs' sum,
    // as fgsrd's records count it.
    GeneratedFrame twice = g;
    twice.passes.push_back(splat);
    cli::MethodScore both;
    cli::add_timing(both, twice);
    EXPECT_EQ(both.pass_samples["splat"], std::vector<double>{20.0});
    EXPECT_EQ(both.pass_samples["match"], std::vector<double>{2.5});

    nlohmann::json j = eval_json(
        "--capture builtin --frames 2 --no-skip-tiles --methods fgsr-colour"); // every pass every frame
    ASSERT_FALSE(j.is_discarded());
    const nlohmann::json& c = j["methods"]["fgsr-colour"];
    double motion = 0, all = 0;
    for (const char* pass : {"luma", "match", "flow", "polish"}) {
        ASSERT_TRUE(c["pass_ms"].contains(pass)) << c.dump();
        motion += c["pass_ms"][pass].get<double>();
    }
    for (const auto& [name, ms] : c["pass_ms"].items()) all += ms.get<double>();
    EXPECT_GT(motion, 0.0);
    EXPECT_NEAR(c["ms"].get<double>(), all, 1e-6 * all) << "ms is the sum of every pass, motion included";
}

// eval reports the median GPU time of the generated frames beside their mean: one slow frame (a
// pipeline compiled at its first dispatch, a neighbour's build) moves the mean, not the median.
TEST(EvalMotionTiming, MedianOfTheFramesBesideTheMean) {
    for (const std::vector<double>& ms :
         {std::vector<double>{1.0, 10.0, 3.0}, std::vector<double>{1.0, 10.0, 3.0, 5.0}}) {
        cli::EvalReport r;
        r.method_order = {"fgsr"};
        cli::MethodScore& s = r.methods["fgsr"];
        for (double v : ms) {
            GeneratedFrame f;
            f.gpu_ms = v;
            cli::add_timing(s, f);
            s.psnr.push_back(30.0);
            s.ssim.push_back(0.9);
        }
        cli::finish_means(r);
        const double mean = ms.size() == 3 ? 14.0 / 3.0 : 19.0 / 4.0, median = ms.size() == 3 ? 3.0 : 4.0;
        EXPECT_DOUBLE_EQ(r.methods["fgsr"].mean_ms, mean);
        EXPECT_DOUBLE_EQ(r.methods["fgsr"].median_ms, median);
        const nlohmann::json j = nlohmann::json::parse(cli::report_json(r, false));
        EXPECT_DOUBLE_EQ(j["methods"]["fgsr"]["ms"].get<double>(), mean);
        EXPECT_DOUBLE_EQ(j["methods"]["fgsr"]["ms_median"].get<double>(), median);
    }
}

// A cut the capture does not flag (the inputs from 5 on come from another scene): the colour-only
// session detects it and refuses the pair across it; eval shows the nearest input there, counts
// it and carries on (it used to stop the whole evaluation with the refusal). The session with the
// capture's vectors (fgsr, Params::vector_cuts on) detects it too, in ingest's cut stage: scene A's
// vectors do not explain scene B's colour.
TEST(EvalMotionTiming, DetectedCutIsScoredAsTheNearestInput) {
    auto a = cli::load_capture_spec("builtin");
    ASSERT_TRUE(a) << a.error().message;
    capture::SceneOptions other;
    other.seed = 77;
    other.supersample = 1;
    auto b = capture::make_synthetic_capture(other, 11);
    ASSERT_TRUE(b) << b.error().message;
    ASSERT_EQ(b->format.width, a->format.width);
    for (size_t k = 5; k < a->inputs.size(); ++k) {
        // Scene B's colour seen by a camera that also turned around: mirrored rows.
        capture::Frame f = b->inputs[k];
        const size_t row = f.color.size() / b->format.height;
        for (uint32_t y = 0; y < b->format.height; ++y)
            std::copy(b->inputs[k].color.begin() + std::ptrdiff_t(y * row),
                      b->inputs[k].color.begin() + std::ptrdiff_t((y + 1) * row),
                      f.color.end() - std::ptrdiff_t((y + 1) * row));
        a->inputs[k].color = f.color;
    }
    cli::EvalOptions o;
    o.methods = {"fgsr-colour", "fgsr", "blend"};
    o.params.vector_cuts = true;
    o.preloaded = &*a;
    o.engine = &engine();
    o.progress = false;
    auto r = cli::run_eval(o);
    ASSERT_TRUE(r) << r.error().message;
    const cli::MethodScore& c = r->methods.at("fgsr-colour");
    EXPECT_GE(c.scene_cuts, 1u) << "the cut before input 5 is detected";
    EXPECT_LT(c.scene_cuts, 4u) << "and little else";
    EXPECT_EQ(c.psnr.size(), r->frames) << "every frame is scored";
    EXPECT_EQ(c.ms_samples.size(), r->frames - c.scene_cuts) << "refused frames are not timed";
    const nlohmann::json j = nlohmann::json::parse(cli::report_json(*r, false));
    EXPECT_EQ(j["methods"]["fgsr-colour"]["scene_cuts"].get<size_t>(), c.scene_cuts);
    const cli::MethodScore& v = r->methods.at("fgsr");
    EXPECT_EQ(v.scene_cuts, 1u) << "with vectors: the cut before input 5, and nothing else";
    EXPECT_EQ(v.psnr.size(), r->frames);
    EXPECT_EQ(j["methods"]["fgsr"]["scene_cuts"].get<size_t>(), 1u);
    expect_no_validation_errors();
}

// isr / esr's `bilinear` / `bicubic` baselines generate at input resolution in a session with
// vectors, which starts afresh at a scene cut it detects (change 22). That pair's baseline frame is
// then the input `repeat` would show, counted as a scene cut, and eval goes on (it stopped with
// "interpolation needs two submitted frames" on an unjittered render with a cut, cut-sraa). Two
// synthetic scenes spliced at the cut, half rate; references the inputs at twice the size.
TEST(EvalJoint, BaselinesTakeTheInputAtADetectedCut) {
    capture::SceneOptions so;
    so.width = 192;
    so.height = 108;
    auto a = capture::make_synthetic_capture(so, 4);
    so.seed = 7;
    auto b = capture::make_synthetic_capture(so, 5);
    ASSERT_TRUE(a && b);
    capture::Capture cap = std::move(*a);
    cap.inputs.insert(cap.inputs.end(), b->inputs.begin() + 1, b->inputs.end()); // B's with vectors
    cap.ground_truth.clear();
    cap.ground_truth_kind = capture::GroundTruth::consecutive;
    for (const capture::Frame& f : cap.inputs) {
        const ImageRGBA lr = capture::decode_color(cap.format, f);
        ImageRGBA hr{2 * lr.width, 2 * lr.height, std::vector<float>(size_t(4) * lr.width * lr.height * 4)};
        for (uint32_t y = 0; y < hr.height; ++y)
            for (uint32_t x = 0; x < hr.width; ++x)
                for (int c = 0; c < 4; ++c)
                    hr.rgba[(size_t(y) * hr.width + x) * 4 + size_t(c)] =
                        lr.rgba[(size_t(y / 2) * lr.width + x / 2) * 4 + size_t(c)];
        cap.hr_reference.push_back(std::move(hr));
    }
    for (const cli::EvalMode mode : {cli::EvalMode::isr, cli::EvalMode::esr}) {
        SCOPED_TRACE(mode == cli::EvalMode::isr ? "isr" : "esr");
        cli::EvalOptions o;
        o.mode = mode;
        o.methods = {"fgsr", "bicubic"};
        o.progress = false;
        auto r = cli::run_eval_joint(o, cap);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->methods.at("bicubic").scene_cuts, 1u);
        EXPECT_EQ(r->methods.at("bicubic").psnr.size(), r->frames);
        for (const double v : r->methods.at("bicubic").psnr) EXPECT_TRUE(std::isfinite(v));
    }
    expect_no_validation_errors();
}

TEST(EvalMotionCaptures, ColourMethodInSuperResolution) {
    const std::filesystem::path dir = std::filesystem::path(FGSR_SHARED_CAPTURES) / "blender/orbit-sr";
    if (!std::filesystem::exists(dir))
        GTEST_SKIP() << "../shared/captures/blender/orbit-sr not found (captures exist in CI only)";
    nlohmann::json j = eval_json(
        "--mode sr --frames 3 --static-frames 0 --methods fgsr,fgsr-colour --capture " + dir.string());
    ASSERT_FALSE(j.is_discarded());
    const nlohmann::json& c = j["methods"]["fgsr-colour"];
    for (const char* key : {"psnr", "ssim", "ms", "epe"})
        EXPECT_TRUE(finite_number(c[key])) << key << " = " << c[key];
    EXPECT_GT(c["psnr"].get<double>(), 15.0);
}

// eval --out in the super-resolution modes: every method's frames, the reference and metrics.json;
// the PSNR of the written 8-bit frames against the written reference agrees with the reported one
// (up to the 8-bit rounding of both).
TEST(EvalMotionCaptures, OutWritesSuperResolutionFrames) {
    const std::filesystem::path dir = std::filesystem::path(FGSR_SHARED_CAPTURES) / "blender/orbit-sr";
    if (!std::filesystem::exists(dir))
        GTEST_SKIP() << "../shared/captures/blender/orbit-sr not found (captures exist in CI only)";
    const std::filesystem::path out =
        std::filesystem::temp_directory_path() / ("fgsr-eval-out-" + std::to_string(getpid()));
    std::filesystem::remove_all(out);
    for (const char* mode : {"sr", "isr", "esr"}) {
        nlohmann::json j =
            eval_json(fmt::format("--mode {} --frames 2 --static-frames 0 --methods fgsr,bicubic "
                                  "--capture {} --out {}",
                                  mode, dir.string(), out.string()));
        ASSERT_FALSE(j.is_discarded()) << mode;
        std::ifstream mf(out / "metrics.json");
        const nlohmann::json m = nlohmann::json::parse(mf, nullptr, false);
        ASSERT_FALSE(m.is_discarded()) << mode;
        EXPECT_EQ(m["mode"], mode);
        std::vector<std::filesystem::path> refs;
        for (const auto& e : std::filesystem::directory_iterator(out / "reference")) refs.push_back(e.path());
        ASSERT_EQ(refs.size(), 2u) << mode;
        for (const char* method : {"fgsr", "bicubic"}) {
            double sum = 0;
            for (const auto& r : refs) {
                auto a = capture::read_png(out / method / r.filename());
                auto b = capture::read_png(r);
                ASSERT_TRUE(a && b) << mode << " " << method << " " << r.filename();
                ASSERT_EQ(a->rgba.size(), b->rgba.size());
                double se = 0;
                size_t n = 0;
                for (size_t i = 0; i < a->rgba.size(); ++i) {
                    if (i % 4 == 3) continue;
                    const double d = (double(a->rgba[i]) - double(b->rgba[i])) / 255.0;
                    se += d * d;
                    ++n;
                }
                sum += 10.0 * std::log10(1.0 / (se / double(n)));
            }
            EXPECT_NEAR(sum / double(refs.size()), j["methods"][method]["psnr"].get<double>(), 0.1)
                << mode << " " << method;
            EXPECT_NEAR(m["methods"][method]["psnr"].get<double>(),
                        j["methods"][method]["psnr"].get<double>(), 1e-9);
        }
        std::filesystem::remove_all(out);
    }
}

} // namespace
} // namespace fgsr::test
