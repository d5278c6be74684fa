// Resampling LUTs: file format, the shipped tables, and the acceptance test of issue 3 (six-fold
// repeated resampling on held-back images: learned LUT vs bilinear vs bicubic).
#include <fgsr/cli/lut_model.hpp> // the trainer's model (header-only)
#include <fgsr/cli/lut_train.hpp>

#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/reference.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <random>

namespace {

using namespace fgsr;
using namespace fgsr::cli::lutmodel;

const std::filesystem::path kShipped =
    std::filesystem::path(__FILE__).parent_path().parent_path() / "daemon/engine/luts";
constexpr float kScales[] = {1.5f, 2.f, 3.f, 4.f};

std::string shipped_name(float s) {
    return s == 1.5f ? "sr_x1.5.lut" : "sr_x" + std::to_string(int(s)) + ".lut";
}

std::filesystem::path temp_file(const std::string& name) {
    return std::filesystem::temp_directory_path() /
           ("fgsr_test_lut_" + std::to_string(::getpid()) + "_" + name);
}

std::vector<char> read_all(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void write_all(const std::filesystem::path& p, const std::vector<char>& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

Lut random_lut(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-0.3f, 0.7f);
    Lut l;
    l.scale = 2.f;
    l.weights.resize(kLutSize);
    for (float& w : l.weights) w = u(rng);
    return l;
}

RgbImage random_image(uint32_t w, uint32_t h, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    RgbImage im{w, h, std::vector<float>(size_t(w) * h * 3)};
    for (float& v : im.rgb) v = u(rng);
    return im;
}

} // namespace

TEST(Lut, FileRoundTripAndMalformedFiles) {
    Lut l = random_lut(3);
    force_identity_phase(l); // loading applies it (fgsr/engine/lut.hpp)
    const auto p = temp_file("rt.lut");
    ASSERT_TRUE(save_lut(p, l));
    auto back = load_lut(p);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->scale, l.scale);
    EXPECT_EQ(back->weights, l.weights);
    const std::vector<char> good = read_all(p);
    ASSERT_EQ(good.size(), 24 + kLutSize * 4);

    std::vector<char> bad = good;
    bad[0] = 'X'; // magic
    write_all(p, bad);
    EXPECT_FALSE(load_lut(p));
    bad = good;
    bad.pop_back(); // one byte short
    write_all(p, bad);
    EXPECT_FALSE(load_lut(p));
    bad = good;
    bad.insert(bad.end(), 4, 0); // one weight too many
    write_all(p, bad);
    EXPECT_FALSE(load_lut(p));
    bad = std::vector<char>(good.begin(), good.begin() + 10); // truncated header
    write_all(p, bad);
    EXPECT_FALSE(load_lut(p));
    for (float v : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        bad = good;
        std::memcpy(bad.data() + 24 + 4 * 777, &v, 4);
        write_all(p, bad);
        EXPECT_FALSE(load_lut(p));
    }
    bad = good;
    const uint32_t levels = 16;
    std::memcpy(bad.data() + 8, &levels, 4);
    write_all(p, bad);
    EXPECT_FALSE(load_lut(p));
    std::filesystem::remove(p);
    EXPECT_FALSE(load_lut(p)); // missing file
    Lut short_lut = l;
    short_lut.weights.resize(100);
    EXPECT_FALSE(save_lut(p, short_lut));
}

TEST(Lut, ShippedTablesAreTheDefaultsAndSumToOne) {
    for (float s : kScales) {
        SCOPED_TRACE(s);
        const Lut d = default_lut(s);
        EXPECT_EQ(d.scale, s);
        ASSERT_EQ(d.weights.size(), kLutSize);
        EXPECT_NE(d.weights, catmull_rom_lut(s).weights) << "default_lut fell back to Catmull-Rom";
        const auto file = kShipped / shipped_name(s);
        if (std::filesystem::exists(file)) {
            auto l = load_lut(file);
            ASSERT_TRUE(l) << l.error().message;
            EXPECT_EQ(l->weights, d.weights) << file << " differs from the embedded table (re-run cmake)";
        } else {
            ADD_FAILURE() << file << " is missing";
        }
        double worst = 0;
        for (size_t bin = 0; bin < size_t(kLutLevels) * kLutLevels; ++bin) {
            double sum = 0;
            for (size_t k = 0; k < kLutTaps; ++k) sum += d.weights[bin * kLutTaps + k];
            worst = std::max(worst, std::abs(sum - 1));
        }
        EXPECT_LT(worst, 1e-3);
    }
}

// What the trainer optimises is what the engine runs: lut_resample equals ref::resample_image.
TEST(Lut, TrainerForwardModelEqualsReference) {
    const Lut l = random_lut(7);
    const RgbImage im = random_image(37, 29, 11);
    const std::vector<glm::vec4> v = to_vec4(im);
    for (glm::vec2 s :
         {glm::vec2(0.f), glm::vec2(0.5f), glm::vec2(-0.5f, 0.25f), glm::vec2(0.3137f, -0.77f),
          glm::vec2(-3.9f, 2.03125f), glm::vec2(1.0f / 64, 31.0f / 32), glm::vec2(12.5f, -40.f)}) {
        const RgbImage mine = lut_resample(im, s, l.weights);
        const std::vector<glm::vec4> ref =
            ref::resample_image(v, im.width, im.height, s, Resample::lut, l.weights);
        float worst = 0;
        for (size_t i = 0; i < ref.size(); ++i)
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::abs(mine.rgb[i * 3 + size_t(c)] - ref[i][c]));
        EXPECT_LE(worst, 1e-6f) << "shift " << s.x << "," << s.y;
    }
}

// The analytic gradients the trainer uses agree with finite differences, and its SSIM is
// capture::ssim's.
TEST(Lut, TrainerGradients) {
    const Lut l = random_lut(5);
    const RgbImage im = random_image(16, 14, 9);
    const glm::vec2 s(0.37f, -0.61f);
    const RgbImage gout = random_image(16, 14, 10);
    std::vector<double> gw(kLutSize, 0.0);
    std::vector<float> gsrc(im.rgb.size(), 0.f);
    lut_resample_backward(im, s, l.weights, gout.rgb, gw, &gsrc);
    auto objective = [&](const RgbImage& src, const std::vector<float>& w) {
        const RgbImage o = lut_resample(src, s, w);
        double sum = 0;
        for (size_t i = 0; i < o.rgb.size(); ++i) sum += double(o.rgb[i]) * gout.rgb[i];
        return sum;
    };
    // Linear in both: exact up to rounding with a large step.
    for (size_t k : {size_t(0), size_t(5000), size_t(16383)}) {
        std::vector<float> w = l.weights;
        w[k] += 1.f;
        EXPECT_NEAR(objective(im, w) - objective(im, l.weights), gw[k], 1e-3) << k;
    }
    for (size_t p : {size_t(0), size_t(100), size_t(im.rgb.size() - 1)}) {
        RgbImage im2 = im;
        im2.rgb[p] += 1.f;
        EXPECT_NEAR(objective(im2, l.weights) - objective(im, l.weights), gsrc[p], 1e-3) << p;
    }

    const uint32_t w = 20, h = 17;
    const RgbImage a = random_image(w, h, 1), b = random_image(w, h, 2);
    std::vector<double> da(size_t(w) * h), db(size_t(w) * h), grad;
    for (size_t i = 0; i < da.size(); ++i) da[i] = 0.3 + 0.4 * a.rgb[i * 3], db[i] = 0.3 + 0.4 * b.rgb[i * 3];
    const double s0 = ssim_with_grad(da, db, w, h, &grad);
    ImageRGBA ia{w, h, std::vector<float>(size_t(w) * h * 4)}, ib = ia;
    for (size_t i = 0; i < da.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            // Linear values whose display values are da / db.
            auto lin = [](double d) {
                return float(d <= 0.04045 ? d / 12.92 : std::pow((d + 0.055) / 1.055, 2.4));
            };
            ia.rgba[i * 4 + size_t(c)] = lin(da[i]);
            ib.rgba[i * 4 + size_t(c)] = lin(db[i]);
        }
    auto ref_ssim = capture::ssim(ia, ib);
    ASSERT_TRUE(ref_ssim);
    EXPECT_NEAR(s0, *ref_ssim, 1e-4);
    for (size_t i : {size_t(0), size_t(45), size_t(170), size_t(w * h - 1)}) {
        std::vector<double> d2 = da;
        d2[i] += 1e-6;
        EXPECT_NEAR((ssim_with_grad(d2, db, w, h, nullptr) - s0) / 1e-6, grad[i], 1e-4) << i;
    }
}

// Acceptance (issue 3; paper 4: LUT 0.933, bicubic 0.931, bilinear 0.907): on a synthetic scene
// never used in training (seed 4242), six-fold repeated resampling through the engine's reference
// with the shipped LUT scores a higher SSIM than bilinear and at least bicubic's, for every scale,
// with the paper's +1/2 pixel shifts and with random sub-pixel shifts.
// The trainer's SR-loop gradient (through Eq. 2, the colour-box clamp and the LUT resampling of
// every frame's history) agrees with central finite differences of the engine's CPU reference.
// Eq. 2's (a, b): the paper's calibration, the engine's defaults (b > 1: samples beyond 1 / b get
// weight 0), and a = 0.9 with b = 1.5 (pixels whose samples all weigh 0 at a < 1 still blend).
class LutSrLoop : public testing::TestWithParam<std::pair<float, float>> {};

TEST_P(LutSrLoop, TrainerGradients) {
    const auto [a, b] = GetParam();
    const RgbImage hi = random_image(96, 96, 21);
    const SrLoop loop =
        make_sr_loop(hi, 2, 2.f, 24, glm::dvec2(10.0, 14.0), glm::vec2(0.37f, -0.61f), 3, 0.2f, 5);
    const Lut l = catmull_rom_lut(2.f);
    std::array<std::vector<float>, kSrFrames> g;
    for (int t = 0; t < kSrFrames; ++t) g[size_t(t)] = random_image(24, 24, 100 + uint32_t(t)).rgb;
    auto objective = [&](const std::vector<float>& w) {
        const auto out = sr_loop_forward(loop, w, a, b);
        double sum = 0;
        for (int t = 0; t < kSrFrames; ++t)
            for (size_t i = 0; i < out[size_t(t)].rgb.size(); ++i)
                sum += double(out[size_t(t)].rgb[i]) * g[size_t(t)][i];
        return sum;
    };
    std::vector<double> gw(kLutSize, 0.0);
    sr_loop_backward(loop, sr_loop_forward(loop, l.weights, a, b), g, l.weights, a, b, gw);
    for (double v : gw) ASSERT_TRUE(std::isfinite(v));
    // The velocity's phase is bin (12, 12) on both axes (0.37 and 1 - 0.61 times 32, rounded).
    const size_t bin = (12 * size_t(kLutLevels) + 12) * kLutTaps;
    double largest = 0;
    for (size_t k = 0; k < kLutTaps; ++k) {
        std::vector<float> up = l.weights, down = l.weights;
        up[bin + k] += 1e-3f;
        down[bin + k] -= 1e-3f;
        const double fd = (objective(up) - objective(down)) / 2e-3;
        EXPECT_NEAR(fd, gw[bin + k], 0.02 * std::abs(fd) + 1e-2) << "tap " << k;
        largest = std::max(largest, std::abs(gw[bin + k]));
    }
    EXPECT_GT(largest, 1.0) << "the history must depend on the LUT";
    EXPECT_EQ(gw[0], 0.0); // bin (0, 0) is never read at this velocity
}

INSTANTIATE_TEST_SUITE_P(Lut, LutSrLoop,
                         testing::Values(std::pair{0.66f, 0.81f}, std::pair{defaults::sr_a, defaults::sr_b},
                                         std::pair{0.9f, 1.5f}));

// lut-train accepts the engine's parameter ranges, its own defaults among them (b = 1.09 was
// refused while the check still said b <= 1), and refuses what the engine refuses.
TEST(Lut, TrainerAcceptsTheEngineRanges) {
    cli::LutTrainOptions o;
    o.iterations = 0; // evaluate the Catmull-Rom start only
    o.progress = false;
    auto r = cli::run_lut_train(o);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->lut.weights.size(), kLutSize);
    for (float bad_b :
         {-0.1f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
        cli::LutTrainOptions b = o;
        b.sr_b = bad_b;
        auto e = cli::run_lut_train(b);
        ASSERT_FALSE(e);
        EXPECT_NE(e.error().message.find("sr-b"), std::string::npos) << e.error().message;
    }
}

TEST(Lut, SixFoldResamplingBeatsBilinearAndMatchesBicubic) {
    constexpr uint32_t kK = 4, kW = 320, kH = 180;
    capture::SceneOptions so;
    so.width = kW * kK;
    so.height = kH * kK;
    so.seed = 4242;
    so.supersample = 1;
    const RgbImage hi = from_rgba(capture::SyntheticScene(so).render_color(4.25));

    std::vector<ShiftSequence> seqs{half_pixel_sequence()};
    std::mt19937_64 rng(777);
    for (int i = 0; i < 2; ++i) seqs.push_back(random_sequence(rng, 0.0));

    struct Figures {
        double ssim[3] = {0, 0, 0}, psnr[3] = {0, 0, 0}; // lut, bilinear, bicubic
    };
    auto run_scale = [&](float scale) {
        std::vector<Figures> per_seq(seqs.size());
        const std::vector<float> lut = default_lut(scale).weights;
        for (double footprint : {1.0, double(scale)}) {
            const RgbImage img = make_history_image(hi, kK, footprint);
            for (size_t qi = 0; qi < seqs.size(); ++qi) {
                const ShiftSequence& q = seqs[qi];
                const ImageRGBA gt = to_rgba(crop(img, q.margin, q.total));
                const Resample kinds[3] = {Resample::lut, Resample::bilinear, Resample::catmull_rom};
                for (int m = 0; m < 3; ++m) {
                    std::vector<glm::vec4> v = to_vec4(img);
                    for (const glm::vec2& s : q.shift)
                        v = ref::resample_image(v, img.width, img.height, s, kinds[m], lut);
                    const ImageRGBA out = to_rgba(crop(from_vec4(v, img.width, img.height), q.margin));
                    per_seq[qi].ssim[m] += capture::ssim(out, gt).value() / 2;
                    per_seq[qi].psnr[m] += capture::psnr(out, gt).value() / 2;
                }
            }
        }
        return per_seq;
    };
    std::vector<std::future<std::vector<Figures>>> jobs;
    for (float s : kScales) jobs.push_back(std::async(std::launch::async, run_scale, s));
    for (size_t si = 0; si < std::size(kScales); ++si) {
        const std::vector<Figures> f = jobs[si].get();
        Figures half = f[0], random;
        for (size_t qi = 1; qi < f.size(); ++qi)
            for (int m = 0; m < 3; ++m) {
                random.ssim[m] += f[qi].ssim[m] / double(f.size() - 1);
                random.psnr[m] += f[qi].psnr[m] / double(f.size() - 1);
            }
        for (const auto& [name, fig] : {std::pair<const char*, Figures>{"half", half}, {"random", random}}) {
            std::printf(
                "[ lut x%-3g %-6s] SSIM lut %.4f bilinear %.4f bicubic %.4f | PSNR lut %.2f bilinear %.2f "
                "bicubic %.2f dB\n",
                double(kScales[si]), name, fig.ssim[0], fig.ssim[1], fig.ssim[2], fig.psnr[0], fig.psnr[1],
                fig.psnr[2]);
            SCOPED_TRACE(std::string(name) + " x" + std::to_string(kScales[si]));
            EXPECT_GT(fig.ssim[0], fig.ssim[1]);
            EXPECT_GE(fig.ssim[0], fig.ssim[2]);
        }
    }
}
