#include <fgsr/cli/lut_train.hpp>

#include <fgsr/cli/capture_spec.hpp>
#include <fgsr/cli/cli_util.hpp>

#include <fgsr/cli/lut_model.hpp>

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/synthetic.hpp>
#include <fgsr/engine/reference.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <thread>

namespace fgsr::cli {

namespace {

using namespace lutmodel;

// Training / evaluation image size (output pixels) of one repeated-resampling sequence.
constexpr uint32_t kCrop = 128;
// Output size (pixels, square) of one SR loop; a whole number of LR pixels at x1.5, 2, 3 and 4.
constexpr uint32_t kSrCrop = 96;
// B-spline segments per phase axis of the LUT parametrisation.
constexpr int kSegments = 8;
constexpr int kBasis = kSegments + 3;
// Fraction of training sequences using the paper's +-1/2 pixel shifts.
constexpr double kHalfProb = 0.25;

// A high-resolution source: history images are box-filtered from it (make_history_image).
struct Source {
    std::string name;
    RgbImage hi;
    uint32_t k = 1; // hi is k x the output resolution
};

// Runs f(i) for i in [0, n) on `threads` threads (each index exactly once).
void parallel_for(size_t n, int threads, const std::function<void(size_t)>& f) {
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t i; (i = next.fetch_add(1)) < n;) f(i);
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads && size_t(t) < n; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
}

// Uniform cubic B-spline basis on [0, 1] (kSegments segments) at the LUT bin phases bin / L:
// phi[bin * kBasis + a].
std::vector<double> bspline_basis() {
    std::vector<double> phi(size_t(kLutLevels) * kBasis, 0.0);
    for (uint32_t b = 0; b < kLutLevels; ++b) {
        const double u = double(b) / kLutLevels * kSegments;
        const int s = std::min(int(u), kSegments - 1);
        const double t = u - s;
        const double w[4] = {(1 - t) * (1 - t) * (1 - t) / 6, (3 * t * t * t - 6 * t * t + 4) / 6,
                             (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6, t * t * t / 6};
        for (int i = 0; i < 4; ++i) phi[size_t(b) * kBasis + size_t(s + i)] = w[i];
    }
    return phi;
}

// LUT of the parameters: w = w0 + sum_{a,b} c[tap][b][a] phi(fy)[b] phi(fx)[a], then each phase's
// 16 weights shifted equally so that they sum to exactly 1 (up to float rounding), and phase (0, 0)
// set to the identity as the engine does on loading.
std::vector<float> lut_of(const std::vector<float>& w0, const std::vector<double>& c,
                          const std::vector<double>& phi) {
    std::vector<float> w(kLutSize);
    for (uint32_t by = 0; by < kLutLevels; ++by)
        for (uint32_t bx = 0; bx < kLutLevels; ++bx) {
            double v[16], sum = 0;
            for (size_t k = 0; k < 16; ++k) {
                double d = w0[(size_t(by) * kLutLevels + bx) * 16 + k];
                for (int b = 0; b < kBasis; ++b) {
                    const double pb = phi[size_t(by) * kBasis + size_t(b)];
                    if (pb == 0) continue;
                    for (int a = 0; a < kBasis; ++a)
                        d += c[(k * kBasis + size_t(b)) * kBasis + size_t(a)] * pb *
                             phi[size_t(bx) * kBasis + size_t(a)];
                }
                v[k] = d;
                sum += d;
            }
            for (size_t k = 0; k < 16; ++k)
                w[(size_t(by) * kLutLevels + bx) * 16 + k] = float(v[k] - (sum - 1) / 16);
        }
    // Phase (0, 0) is the identity in every table the engine loads (fgsr::force_identity_phase).
    Lut l{1.f, std::move(w)};
    force_identity_phase(l);
    return std::move(l.weights);
}

// Gradient of the parameters from the gradient of the LUT: through the sum-to-one projection,
// symmetrised under transposition of the phase (fx, fy, i, j) -> (fy, fx, j, i), through the basis.
std::vector<double> param_grad(const std::vector<double>& gw, const std::vector<double>& phi) {
    std::vector<double> g(kLutSize, 0.0);
    for (size_t bin = 1; bin < size_t(kLutLevels) * kLutLevels; ++bin) { // bin 0 is fixed (identity)
        double mean = 0;
        for (size_t k = 0; k < 16; ++k) mean += gw[bin * 16 + k];
        mean /= 16;
        for (size_t k = 0; k < 16; ++k) g[bin * 16 + k] = gw[bin * 16 + k] - mean;
    }
    std::vector<double> gs(kLutSize);
    for (uint32_t by = 0; by < kLutLevels; ++by)
        for (uint32_t bx = 0; bx < kLutLevels; ++bx)
            for (size_t j = 0; j < 4; ++j)
                for (size_t i = 0; i < 4; ++i)
                    gs[(size_t(by) * kLutLevels + bx) * 16 + j * 4 + i] =
                        0.5 * (g[(size_t(by) * kLutLevels + bx) * 16 + j * 4 + i] +
                               g[(size_t(bx) * kLutLevels + by) * 16 + i * 4 + j]);
    // gc[k][b][a] = sum_{by,bx} gs[by][bx][k] phi[by][b] phi[bx][a], separably.
    std::vector<double> t(size_t(kLutLevels) * 16 * kBasis, 0.0); // [by][k][a]
    for (uint32_t by = 0; by < kLutLevels; ++by)
        for (uint32_t bx = 0; bx < kLutLevels; ++bx)
            for (size_t k = 0; k < 16; ++k)
                for (int a = 0; a < kBasis; ++a)
                    t[(size_t(by) * 16 + k) * kBasis + size_t(a)] +=
                        gs[(size_t(by) * kLutLevels + bx) * 16 + k] * phi[size_t(bx) * kBasis + size_t(a)];
    std::vector<double> gc(16 * size_t(kBasis) * kBasis, 0.0);
    for (uint32_t by = 0; by < kLutLevels; ++by)
        for (size_t k = 0; k < 16; ++k)
            for (int b = 0; b < kBasis; ++b)
                for (int a = 0; a < kBasis; ++a)
                    gc[(k * kBasis + size_t(b)) * kBasis + size_t(a)] +=
                        t[(size_t(by) * 16 + k) * kBasis + size_t(a)] * phi[size_t(by) * kBasis + size_t(b)];
    return gc;
}

// SSIM of `out` against `ref` (both cropped by `m` from images `full_w` wide), per RGB channel on
// display values, summed over the channels. Writes -dSSIM/d(linear value) / divisor into `g`
// (the full-size gradient) at the cropped pixels.
double ssim_rgb_with_grad(const RgbImage& out, const RgbImage& ref, int m, uint32_t full_w, double divisor,
                          std::vector<float>& g) {
    const size_t n = size_t(out.width) * out.height;
    double ssim_sum = 0;
    for (int c = 0; c < 3; ++c) {
        std::vector<double> a(n), r(n), grad;
        for (size_t i = 0; i < n; ++i) {
            a[i] = display_value(out.rgb[i * 3 + size_t(c)]);
            r[i] = display_value(ref.rgb[i * 3 + size_t(c)]);
        }
        ssim_sum += ssim_with_grad(a, r, out.width, out.height, &grad);
        for (uint32_t y = 0; y < out.height; ++y)
            for (uint32_t x = 0; x < out.width; ++x) {
                const size_t i = size_t(y) * out.width + x;
                const size_t p = ((size_t(y) + size_t(m)) * full_w + x + size_t(m)) * 3 + size_t(c);
                g[p] = float(-grad[i] / divisor * display_slope(out.rgb[i * 3 + size_t(c)]));
            }
    }
    return ssim_sum;
}

// Loss (1 - mean SSIM over RGB, display values) of one six-fold sequence on `img`, adding the
// gradient with respect to the LUT to gw.
double sequence_loss(const RgbImage& img, const ShiftSequence& q, const std::vector<float>& lut,
                     std::vector<double>& gw) {
    std::vector<RgbImage> chain(kSteps + 1);
    chain[0] = img;
    for (int k = 0; k < kSteps; ++k)
        chain[size_t(k) + 1] = lut_resample(chain[size_t(k)], q.shift[size_t(k)], lut);
    const int m = q.margin;
    const RgbImage out = crop(chain[kSteps], m), gt = crop(img, m, q.total);
    std::vector<float> g(img.rgb.size(), 0.f);
    const double ssim_sum = ssim_rgb_with_grad(out, gt, m, img.width, 3, g);
    for (int k = kSteps; k >= 1; --k) {
        std::vector<float> gprev;
        if (k > 1) gprev.assign(img.rgb.size(), 0.f);
        lut_resample_backward(chain[size_t(k) - 1], q.shift[size_t(k) - 1], lut, g, gw,
                              k > 1 ? &gprev : nullptr);
        g = std::move(gprev);
    }
    return 1 - ssim_sum / 3;
}

// Loss (1 - mean SSIM over RGB and frames 1 .. kSrFrames - 1, display values, interior) of one SR
// loop against its antialiased targets, adding the gradient with respect to the LUT to gw.
double sr_loop_loss(const SrLoop& l, const std::vector<float>& lut, float a, float b,
                    std::vector<double>& gw) {
    const std::array<RgbImage, kSrFrames> out = sr_loop_forward(l, lut, a, b);
    std::array<std::vector<float>, kSrFrames> g;
    const int m = l.margin;
    constexpr double kScored = kSrFrames - 1;
    double ssim_sum = 0;
    for (int t = 0; t < kSrFrames; ++t) {
        g[size_t(t)].assign(out[size_t(t)].rgb.size(), 0.f);
        if (t == 0) continue; // the spatial upsample: no history, no LUT
        const RgbImage o = crop(out[size_t(t)], m), r = crop(l.target[size_t(t)], m);
        ssim_sum += ssim_rgb_with_grad(o, r, m, l.out_w, 3 * kScored, g[size_t(t)]);
    }
    sr_loop_backward(l, out, std::move(g), lut, a, b, gw);
    return 1 - ssim_sum / (3 * kScored);
}

RgbImage sub_image(const RgbImage& im, uint32_t x0, uint32_t y0, uint32_t w, uint32_t h) {
    RgbImage o{w, h, std::vector<float>(size_t(w) * h * 3)};
    for (uint32_t y = 0; y < h; ++y)
        std::copy_n(&im.rgb[((size_t(y0) + y) * im.width + x0) * 3], size_t(w) * 3,
                    &o.rgb[size_t(y) * w * 3]);
    return o;
}

// Synthetic scenes: training seeds 1..3 at four instants, held back seed 101 at two instants.
constexpr uint32_t kSynW = 480, kSynH = 270, kSynK = 4;

Source synthetic_source(uint32_t seed, double t) {
    capture::SceneOptions so;
    so.width = kSynW * kSynK;
    so.height = kSynH * kSynK;
    so.seed = seed;
    so.supersample = 1; // the history filter integrates >= kSynK^2 samples per output pixel
    capture::SyntheticScene scene(so);
    return Source{fmt::format("synthetic seed {} t {}", seed, t), from_rgba(scene.render_color(t)), kSynK};
}

// Images of a capture directory: high-resolution references when present, else the inputs (for
// Mob-FGSR captures: HR_Inputs). The last one is held back, up to 4 others spread over the rest
// train.
Result<std::pair<std::vector<Source>, std::vector<Source>>> capture_sources(const std::string& dir) {
    auto c = load_capture_spec(dir);
    if (!c) return c.error();
    std::vector<ImageRGBA> frames = c->hr_reference;
    if (frames.empty())
        for (const capture::Frame& f : c->inputs) frames.push_back(capture::decode_color(c->format, f));
    if (frames.size() < 2) return make_error(Errc::empty_input, dir + ": fewer than 2 frames");
    std::pair<std::vector<Source>, std::vector<Source>> r;
    const size_t train = std::min<size_t>(4, frames.size() - 1);
    for (size_t i = 0; i < train; ++i) {
        const size_t f = i * (frames.size() - 1) / train;
        r.first.push_back(Source{fmt::format("{} frame {}", dir, f), from_rgba(frames[f]), 2});
    }
    r.second.push_back(
        Source{fmt::format("{} frame {}", dir, frames.size() - 1), from_rgba(frames.back()), 2});
    return r;
}

struct EvalImage {
    std::string name;
    RgbImage img;
};

// Six-fold repeated resampling of every image with every method through ref::resample_image (the
// engine's CPU reference), scored on the interior against the exact result.
std::map<std::string, std::map<std::string, MethodFigures>>
evaluate(const std::vector<EvalImage>& images, const std::vector<float>& lut, float scale, int threads) {
    std::vector<std::pair<std::string, ShiftSequence>> seqs{{"half", half_pixel_sequence()}};
    std::mt19937_64 rng(12345);
    for (int i = 0; i < 4; ++i) seqs.push_back({"random", random_sequence(rng, 0.0)});
    const std::vector<float> cr = catmull_rom_lut(scale).weights;
    struct Method {
        const char* name;
        Resample kind;
        const std::vector<float>* table;
    };
    const Method methods[] = {{"lut", Resample::lut, &lut},
                              {"bilinear", Resample::bilinear, nullptr},
                              {"bicubic", Resample::catmull_rom, nullptr},
                              {"catmull_rom_lut", Resample::lut, &cr}};
    constexpr size_t kMethods = std::size(methods);
    const size_t jobs = images.size() * seqs.size() * kMethods;
    std::vector<double> ssim(jobs), psnr(jobs);
    parallel_for(jobs, threads, [&](size_t job) {
        const Method& me = methods[job % kMethods];
        const auto& [proto, q] = seqs[(job / kMethods) % seqs.size()];
        const RgbImage& im = images[job / kMethods / seqs.size()].img;
        std::vector<glm::vec4> v = to_vec4(im);
        for (const glm::vec2& s : q.shift)
            v = ref::resample_image(v, im.width, im.height, s, me.kind,
                                    me.table ? std::span<const float>(*me.table) : std::span<const float>{});
        const ImageRGBA out = to_rgba(crop(from_vec4(v, im.width, im.height), q.margin));
        const ImageRGBA gt = to_rgba(crop(im, q.margin, q.total));
        auto s = capture::ssim(out, gt);
        auto p = capture::psnr(out, gt);
        ssim[job] = s ? *s : 0;
        psnr[job] = p ? *p : 0;
    });
    std::map<std::string, std::map<std::string, MethodFigures>> fig;
    std::map<std::string, size_t> count;
    for (size_t job = 0; job < jobs; ++job) {
        const std::string& proto = seqs[(job / kMethods) % seqs.size()].first;
        MethodFigures& f = fig[proto][methods[job % kMethods].name];
        f.ssim += ssim[job];
        f.psnr += psnr[job];
        if (job % kMethods == 0) ++count[proto];
    }
    for (auto& [proto, ms] : fig)
        for (auto& [name, f] : ms) {
            f.ssim /= double(count[proto]);
            f.psnr /= double(count[proto]);
        }
    return fig;
}

// SR loops (lutmodel::SrLoop) on held-back sources with each history resampling, scored (PSNR,
// SSIM, display values, interior) on frames 1 .. kSrFrames - 1 against the antialiased targets:
// four fixed loops per source (velocities (0.37, -1.21), (1.5, 0.5), (-0.25, 0.125), (-1.8, -1.3)),
// with input noise `noise` (lutmodel::make_sr_loop).
std::map<std::string, MethodFigures> evaluate_sr_loops(const std::vector<const Source*>& sources,
                                                       const std::vector<float>& lut, float scale, float a,
                                                       float b, float noise, int threads) {
    const glm::vec2 vel[] = {{0.37f, -1.21f}, {1.5f, 0.5f}, {-0.25f, 0.125f}, {-1.8f, -1.3f}};
    const std::pair<const char*, Resample> methods[] = {
        {"lut", Resample::lut}, {"bilinear", Resample::bilinear}, {"bicubic", Resample::catmull_rom}};
    const size_t loops = sources.size() * std::size(vel);
    std::vector<std::array<MethodFigures, 3>> fig(loops);
    parallel_for(loops, threads, [&](size_t i) {
        const Source& src = *sources[i / std::size(vel)];
        const glm::vec2 v = vel[i % std::size(vel)];
        const double ow = double(src.hi.width / src.k), oh = double(src.hi.height / src.k);
        const glm::dvec2 origin((ow - kSrCrop) / 2 - 4.0 * v.x, (oh - kSrCrop) / 2 - 4.0 * v.y);
        const SrLoop l = make_sr_loop(src.hi, src.k, scale, kSrCrop, origin, v, uint32_t(i % 16), noise, i);
        for (size_t m = 0; m < std::size(methods); ++m) {
            const auto out = sr_loop_forward(l, lut, a, b, methods[m].second);
            for (int t = 1; t < kSrFrames; ++t) {
                const ImageRGBA o = to_rgba(crop(out[size_t(t)], l.margin)),
                                r = to_rgba(crop(l.target[size_t(t)], l.margin));
                const auto ps = capture::psnr(o, r);
                const auto ss = capture::ssim(o, r);
                fig[i][m].psnr += (ps ? *ps : 0.0) / (kSrFrames - 1);
                fig[i][m].ssim += (ss ? *ss : 0.0) / (kSrFrames - 1);
            }
        }
    });
    std::map<std::string, MethodFigures> r;
    for (size_t m = 0; m < std::size(methods); ++m)
        for (size_t i = 0; i < loops; ++i) {
            r[methods[m].first].psnr += fig[i][m].psnr / double(loops);
            r[methods[m].first].ssim += fig[i][m].ssim / double(loops);
        }
    return r;
}

// Three history footprints per source: 1 (converged), (1 + S) / 2 and S output pixels.
std::vector<double> footprints(float scale) {
    return {1.0, (1.0 + scale) / 2, double(scale)};
}

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

std::string git_commit() {
    std::string out;
    if (FILE* p = popen("git rev-parse HEAD 2>/dev/null", "r")) {
        char buf[64];
        while (std::fgets(buf, sizeof buf, p)) out += buf;
        pclose(p);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out;
}

} // namespace

Result<LutTrainReport> run_lut_train(const LutTrainOptions& o) {
    if (!std::isfinite(o.scale) || o.scale < 1.f || o.scale > 8.f)
        return make_error(Errc::invalid_argument, fmt::format("scale {} outside [1, 8]", o.scale));
    if (o.iterations < 0) return make_error(Errc::invalid_argument, "iterations must be >= 0");
    if (o.batch < 1) return make_error(Errc::invalid_argument, "batch must be >= 1");
    if (o.sr_batch < 0) return make_error(Errc::invalid_argument, "sr-batch must be >= 0");
    if (!(o.sr_weight >= 0) || !std::isfinite(o.sr_weight))
        return make_error(Errc::invalid_argument, "sr-weight must be finite and >= 0");
    // The engine's ranges (fgsr::validate), less a = 0 (no current samples: nothing to train).
    if (!(o.sr_a > 0.f && o.sr_a <= 1.f) || !(std::isfinite(o.sr_b) && o.sr_b >= 0.f))
        return make_error(Errc::invalid_argument, "sr-a must lie in (0, 1], sr-b be finite and >= 0");
    if (!(o.sr_noise >= 0.f && o.sr_noise <= 4.f))
        return make_error(Errc::invalid_argument, "sr-noise must lie in [0, 4]");
    if (o.threads < 1) return make_error(Errc::invalid_argument, "threads must be >= 1");
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    auto say = [&](const std::string& s) {
        if (o.progress) std::fprintf(stderr, "[lut-train] %s\n", s.c_str());
    };

    // ---- data --------------------------------------------------------------------------------
    std::vector<Source> train, held;
    const std::vector<std::string> inputs = o.images.empty() ? std::vector<std::string>{"builtin"} : o.images;
    for (const std::string& in : inputs) {
        if (parse_capture_spec(in).builtin || in == "synthetic") {
            say("rendering the synthetic scene (training seeds 1-3, held-back seed 101)");
            std::vector<std::pair<uint32_t, double>> specs;
            for (uint32_t seed = 1; seed <= 3; ++seed)
                for (double t : {0.5, 3.0, 5.5, 8.0}) specs.push_back({seed, t});
            specs.push_back({101, 2.0});
            specs.push_back({101, 7.0});
            std::vector<Source> made(specs.size());
            parallel_for(specs.size(), 1,
                         [&](size_t i) { made[i] = synthetic_source(specs[i].first, specs[i].second); });
            for (size_t i = 0; i < made.size(); ++i)
                (specs[i].first == 101 ? held : train).push_back(std::move(made[i]));
        } else {
            say("loading " + in);
            auto r = capture_sources(in);
            if (!r) return r.error();
            for (Source& s : r->first) train.push_back(std::move(s));
            for (Source& s : r->second) held.push_back(std::move(s));
        }
    }
    if (train.empty()) return make_error(Errc::empty_input, "no training images");

    LutTrainReport rep;
    const std::vector<double> fps = footprints(o.scale);
    std::vector<RgbImage> train_images; // every source at every footprint
    for (const Source& s : train) {
        rep.training_images.push_back(s.name);
        for (double f : fps) {
            RgbImage h = make_history_image(s.hi, s.k, f);
            if (h.width >= 64 && h.height >= 64) train_images.push_back(std::move(h));
        }
    }
    if (train_images.empty())
        return make_error(Errc::empty_input, "every training image is smaller than 64x64");
    std::vector<EvalImage> eval_images;
    for (const Source& s : held) {
        rep.held_back_images.push_back(s.name);
        for (double f : {1.0, double(o.scale)}) {
            RgbImage h = make_history_image(s.hi, s.k, f);
            if (h.width >= 64 && h.height >= 64)
                eval_images.push_back({fmt::format("{} footprint {}", s.name, f), std::move(h)});
        }
    }
    say(fmt::format("{} training images ({} sources x {} history footprints), {} held-back images, {:.1f} s",
                    train_images.size(), train.size(), fps.size(), eval_images.size(), elapsed()));

    // ---- training: Adam on the B-spline coefficients ------------------------------------------
    const std::vector<float> w0 = catmull_rom_lut(o.scale).weights;
    const std::vector<double> phi = bspline_basis();
    const size_t np = 16 * size_t(kBasis) * kBasis;
    std::vector<double> c(np, 0.0), m1(np, 0.0), m2(np, 0.0);
    std::vector<float> lut = lut_of(w0, c, phi);
    constexpr double kLr = 2e-3, kBeta1 = 0.9, kBeta2 = 0.999, kEps = 1e-8;
    // One sequence (crop of a training image + shift sequence) drawn from (seed, step, slot) only.
    auto draw = [&](uint32_t seed, uint32_t step, uint32_t slot, ShiftSequence& q) {
        std::seed_seq ss{seed, step, slot};
        std::mt19937_64 rng(ss);
        const RgbImage& im =
            train_images[std::uniform_int_distribution<size_t>(0, train_images.size() - 1)(rng)];
        const uint32_t cw = std::min(kCrop, im.width), ch = std::min(kCrop, im.height);
        const uint32_t x0 = std::uniform_int_distribution<uint32_t>(0, im.width - cw)(rng);
        const uint32_t y0 = std::uniform_int_distribution<uint32_t>(0, im.height - ch)(rng);
        q = random_sequence(rng, kHalfProb);
        return sub_image(im, x0, y0, cw, ch);
    };
    // One SR loop drawn from (seed, step, slot) only: a training source, a crop of kSrCrop output
    // pixels, a camera velocity (80%: uniform in [-2, 2]^2 output pixels per frame, 20%: in
    // [-1/2, 1/2]^2; multiples of 2^-10), a start in the jitter cycle and the input noise (half of
    // the loops none, the others uniform in [0, sr_noise]).
    std::vector<const Source*> sr_sources;
    for (const Source& s : train) {
        const double reach = 2.0 * kSrFrames + 4;
        if (s.hi.width / s.k >= kSrCrop + 2 * reach && s.hi.height / s.k >= kSrCrop + 2 * reach)
            sr_sources.push_back(&s);
    }
    if (o.sr_batch > 0 && sr_sources.empty())
        return make_error(Errc::empty_input, "no training image is large enough for SR loops");
    auto draw_sr = [&](uint32_t seed, uint32_t step, uint32_t slot) {
        std::seed_seq ss{seed, step, slot, 0x5111u};
        std::mt19937_64 rng(ss);
        const Source& src = *sr_sources[std::uniform_int_distribution<size_t>(0, sr_sources.size() - 1)(rng)];
        std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
        const double vmax = p(rng) < 0.2 ? 0.5 : 2.0;
        auto quant = [](double v) { return float(std::round(v * 1024.0) / 1024.0); };
        const glm::vec2 v(quant(u(rng) * vmax), quant(u(rng) * vmax));
        const double reach = 2.0 * kSrFrames + 2;
        const double ow = double(src.hi.width / src.k), oh = double(src.hi.height / src.k);
        const glm::dvec2 origin(reach + p(rng) * (ow - kSrCrop - 2 * reach),
                                reach + p(rng) * (oh - kSrCrop - 2 * reach));
        const uint32_t jitter_start = std::uniform_int_distribution<uint32_t>(0, 15)(rng);
        const float noise = p(rng) < 0.5 ? 0.f : float(p(rng) * o.sr_noise);
        return make_sr_loop(src.hi, src.k, o.scale, kSrCrop, origin, v, jitter_start, noise, rng());
    };
    // Fixed validation batch (training images, other crops and shifts): the loss reported.
    constexpr size_t kValidation = 32;
    const size_t sr_validation = o.sr_batch > 0 ? kValidation / 2 : 0;
    struct Loss {
        double total = 0, sixfold = 0, sr = 0;
    };
    auto validation_loss = [&](const std::vector<float>& table) {
        std::vector<double> l(kValidation + sr_validation);
        parallel_for(l.size(), o.threads, [&](size_t b) {
            std::vector<double> unused(kLutSize, 0.0);
            if (b < kValidation) {
                ShiftSequence q;
                const RgbImage img = draw(o.seed ^ 0x5eedu, 0xffffffffu, uint32_t(b), q);
                l[b] = sequence_loss(img, q, table, unused);
            } else {
                l[b] = sr_loop_loss(draw_sr(o.seed ^ 0x5eedu, 0xffffffffu, uint32_t(b)), table, o.sr_a,
                                    o.sr_b, unused);
            }
        });
        Loss r;
        for (size_t b = 0; b < l.size(); ++b)
            (b < kValidation ? r.sixfold : r.sr) +=
                l[b] / double(b < kValidation ? kValidation : sr_validation);
        r.total = r.sixfold + (sr_validation ? o.sr_weight * r.sr : 0.0);
        return r;
    };
    const Loss start = validation_loss(lut);
    rep.initial_loss = start.total;
    rep.initial_sixfold = start.sixfold;
    rep.initial_sr = start.sr;
    say(fmt::format(
        "validation loss of the Catmull-Rom start {:.5f} (six-fold 1-SSIM {:.5f}, SR loops 1-SSIM "
        "{:.5f})",
        start.total, start.sixfold, start.sr));
    std::vector<double> losses;
    for (int it = 0; it < o.iterations; ++it) {
        const size_t jobs = size_t(o.batch) + size_t(o.sr_batch);
        std::vector<std::vector<double>> gws(jobs);
        std::vector<double> loss(jobs);
        parallel_for(jobs, o.threads, [&](size_t b) {
            gws[b].assign(kLutSize, 0.0);
            if (b < size_t(o.batch)) {
                ShiftSequence q;
                const RgbImage img = draw(o.seed, uint32_t(it), uint32_t(b), q);
                loss[b] = sequence_loss(img, q, lut, gws[b]);
            } else {
                loss[b] =
                    sr_loop_loss(draw_sr(o.seed, uint32_t(it), uint32_t(b)), lut, o.sr_a, o.sr_b, gws[b]);
            }
        });
        std::vector<double> gw(kLutSize, 0.0);
        double l = 0;
        for (size_t b = 0; b < jobs; ++b) {
            const double wgt = b < size_t(o.batch) ? 1.0 / o.batch : o.sr_weight / o.sr_batch;
            l += loss[b] * wgt;
            for (size_t i = 0; i < kLutSize; ++i) gw[i] += gws[b][i] * wgt;
        }
        losses.push_back(l);
        const std::vector<double> gc = param_grad(gw, phi);
        // Cosine decay to 5% of the initial rate.
        const double lr =
            kLr * (0.05 + 0.95 * 0.5 * (1 + std::cos(3.14159265358979 * it / std::max(1, o.iterations))));
        const double bc1 = 1 - std::pow(kBeta1, it + 1), bc2 = 1 - std::pow(kBeta2, it + 1);
        for (size_t i = 0; i < np; ++i) {
            m1[i] = kBeta1 * m1[i] + (1 - kBeta1) * gc[i];
            m2[i] = kBeta2 * m2[i] + (1 - kBeta2) * gc[i] * gc[i];
            c[i] -= lr * (m1[i] / bc1) / (std::sqrt(m2[i] / bc2) + kEps);
        }
        lut = lut_of(w0, c, phi);
        if (o.progress && ((it + 1) % 50 == 0 || it + 1 == o.iterations)) {
            const size_t n = std::min<size_t>(50, losses.size());
            double recent = 0;
            for (size_t i = losses.size() - n; i < losses.size(); ++i) recent += losses[i] / double(n);
            const bool val = (it + 1) % 200 == 0 || it + 1 == o.iterations;
            std::fprintf(
                stderr, "[lut-train] step %d/%d  batch loss (last %zu) %.5f%s  lr %.2e  %.1f s\n", it + 1,
                o.iterations, n, recent,
                val ? [&] {
                    const Loss v = validation_loss(lut);
                    return fmt::format("  validation {:.5f} (six-fold {:.5f}, SR {:.5f})", v.total, v.sixfold, v.sr);
                }().c_str()
                    : "",
                lr, elapsed());
        }
    }
    const Loss end = validation_loss(lut);
    rep.final_loss = end.total;
    rep.final_sixfold = end.sixfold;
    rep.final_sr = end.sr;
    rep.lut.scale = o.scale;
    rep.lut.weights = lut;

    // ---- evaluation ---------------------------------------------------------------------------
    if (!eval_images.empty()) {
        say(fmt::format("evaluating on {} held-back images", eval_images.size()));
        rep.figures = evaluate(eval_images, lut, o.scale, o.threads);
    }
    std::vector<const Source*> held_sr;
    for (const Source& s : held)
        if (s.hi.width / s.k >= kSrCrop + 40 && s.hi.height / s.k >= kSrCrop + 40) held_sr.push_back(&s);
    if (!held_sr.empty()) {
        say(fmt::format("SR loops on {} held-back sources", held_sr.size()));
        rep.figures["sr_loop"] = evaluate_sr_loops(held_sr, lut, o.scale, o.sr_a, o.sr_b, 0.f, o.threads);
        if (o.sr_noise > 0.f)
            rep.figures["sr_loop_noisy"] =
                evaluate_sr_loops(held_sr, lut, o.scale, o.sr_a, o.sr_b, o.sr_noise, o.threads);
    }
    rep.seconds = elapsed();

    if (!o.out.empty()) {
        FGSR_TRY(save_lut(o.out, rep.lut));
        std::filesystem::path js = o.out;
        js.replace_extension(".json");
        std::ofstream f(js, std::ios::trunc);
        f << lut_train_json(o, rep);
        if (!f) return make_error(Errc::io, js.string() + ": write failed");
    }
    return rep;
}

std::string lut_train_json(const LutTrainOptions& o, const LutTrainReport& r) {
    nlohmann::ordered_json j;
    j["command"] = o.command_line;
    j["scale"] = o.scale;
    j["date"] = utc_now();
    j["commit"] = git_commit();
    j["training_images"] = r.training_images;
    j["held_back_images"] = r.held_back_images;
    j["history_footprints"] = footprints(o.scale);
    j["iterations"] = o.iterations;
    j["batch"] = o.batch;
    j["seed"] = o.seed;
    j["model"] =
        fmt::format("Catmull-Rom LUT + per-tap cubic B-spline surface over the phase ({0}x{0} coefficients "
                    "per tap), projected to sum 1 per phase, symmetric under transposition; Adam lr 2e-3 "
                    "cosine-decayed, {1}x{1} crops, {2}% of sequences with +-1/2 px shifts",
                    kBasis, kCrop, int(kHalfProb * 100));
    j["loss"] =
        "1 - SSIM (display sRGB values, 11x11 Gaussian sigma 1.5, RGB mean) of six-fold repeated resampling "
        "with sub-pixel shifts summing to whole pixels, against the first image translated by that sum; plus "
        "sr_loops.weight x (1 - SSIM) of the sr pass (CPU reference, Eq. 2 with sr_a, sr_b, colour-box "
        "clamp) "
        "over 8-frame loops of a translating camera with Halton-jittered point-sampled input, frames 1-7 "
        "against the box-filtered (antialiased) output-resolution scene";
    j["sr_loops"] = {{"per_step", o.sr_batch}, {"weight", o.sr_weight},   {"frames", kSrFrames},
                     {"crop", kSrCrop},        {"noise_max", o.sr_noise}, {"sr_a", o.sr_a},
                     {"sr_b", o.sr_b}};
    j["validation_loss_start"] = r.initial_loss; // Catmull-Rom LUT
    j["validation_loss_final"] = r.final_loss;
    j["validation_sixfold_start"] = r.initial_sixfold;
    j["validation_sixfold_final"] = r.final_sixfold;
    j["validation_sr_loops_start"] = r.initial_sr;
    j["validation_sr_loops_final"] = r.final_sr;
    j["seconds"] = r.seconds;
    nlohmann::ordered_json fig = nlohmann::ordered_json::object();
    for (const auto& [proto, ms] : r.figures)
        for (const auto& [name, f] : ms) fig[proto][name] = {{"ssim", f.ssim}, {"psnr", f.psnr}};
    j["held_back_figures"] = fig;
    return j.dump(2) + "\n";
}

CLI::App* add_lut_train_command(CLI::App& app, LutTrainOptions& o) {
    auto* cmd =
        app.add_subcommand("lut-train", "Learn the SR history resampling LUT for one scale factor (six-fold "
                                        "repeated resampling and SR loops, 1-SSIM loss)");
    cmd->add_option("--scale", o.scale, "Upscaling factor the table is for (1.5, 2, 3, 4)")
        ->capture_default_str();
    cmd->add_option(
           "--images", o.images,
           "Training images: capture directories and/or 'builtin' (the synthetic scene); default builtin. "
           "Each capture's last frame is held back")
        ->delimiter(',');
    cmd->add_option("--out", o.out, "Write FILE.lut and FILE.json (provenance)");
    cmd->add_option("--iterations", o.iterations, "Adam steps")->capture_default_str();
    cmd->add_option("--batch", o.batch, "Sequences per step")->capture_default_str();
    cmd->add_option("--sr-batch", o.sr_batch, "SR loops per step (0: the six-fold objective alone)")
        ->capture_default_str();
    cmd->add_option("--sr-weight", o.sr_weight, "Weight of the SR-loop loss")->capture_default_str();
    cmd->add_option("--sr-a", o.sr_a, "Eq. 2 a of the SR loops")->capture_default_str();
    cmd->add_option("--sr-noise", o.sr_noise,
                    "Largest relative noise of SR-loop input samples (half the loops are noise-free)")
        ->capture_default_str();
    cmd->add_option("--sr-b", o.sr_b, "Eq. 2 b of the SR loops")->capture_default_str();
    cmd->add_option("--seed", o.seed, "Seed of crops and shifts")->capture_default_str();
    cmd->add_option("--threads", o.threads, "Worker threads")->capture_default_str();
    cmd->add_flag("!--quiet", o.progress, "No progress on stderr");
    return cmd;
}

int lut_train_main(LutTrainOptions& o, int argc, char** argv) {
    o.command_line = command_line_of(argc, argv);
    auto r = run_lut_train(o);
    if (!r) return report_error(r.error());
    std::printf(
        "scale %g: validation loss %.5f -> %.5f (six-fold 1-SSIM %.5f -> %.5f, SR loops 1-SSIM %.5f -> "
        "%.5f) in %.1f s\n",
        double(o.scale), r->initial_loss, r->final_loss, r->initial_sixfold, r->final_sixfold, r->initial_sr,
        r->final_sr, r->seconds);
    for (const auto& [proto, ms] : r->figures) {
        if (proto.starts_with("sr_loop"))
            std::printf("SR loops%s (held back):\n", proto == "sr_loop" ? "" : ", noisy input");
        else
            std::printf("six-fold, %s shifts (held back):\n", proto.c_str());
        for (const auto& [name, f] : ms)
            std::printf("  %-16s SSIM %.4f  PSNR %.2f dB\n", name.c_str(), f.ssim, f.psnr);
    }
    if (!o.out.empty()) std::printf("wrote %s and its .json\n", o.out.c_str());
    return 0;
}

} // namespace fgsr::cli
