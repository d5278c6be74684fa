// Cost of per-tile skipping (Params::skip_tiles): engine GPU milliseconds per generated (or
// super-resolved) frame of a still scene (identical frames, zero vectors), a partially moving one
// (a small square over a static background) and a fully moving one (the whole image pans) of the
// same size, for interpolation and super resolution, each with skipping on and off, and with
// skipping on for tile sides 8, 16 and 32; and interpolation of scenes whose left quarter, half or
// three quarters pan (the rest still), off and at the default tile side: where skipping stops
// paying (daemon/engine/src/session.hpp, kMinSkipShareCpu).
//
// Usage: fgsr_tiles_bench [width height [repeats [filter]]]   (default 1280 720 7; SR inputs are
// half size; filter: run only the configurations whose label contains it, e.g. "interp", "t16")
// Prints, per configuration, the median over `repeats` rounds of the mean per frame, without and
// with the ingest of the frame's newest input (each generated frame needs one new input), and the
// ratios still / moving and partial / moving within each round (median of the per-round ratios):
// rounds interleave every configuration, so a noisy machine slows them alike. Progress: stderr.
#include <fgsr/engine/engine.hpp>

#include <fmt/core.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace fgsr;

enum class Scene { still, partial, moving, band25, band50, band75 };
const char* name(Scene s) {
    switch (s) {
    case Scene::still:
        return "still";
    case Scene::partial:
        return "partial";
    case Scene::moving:
        return "moving";
    case Scene::band25:
        return "band25";
    case Scene::band50:
        return "band50";
    case Scene::band75:
        return "band75";
    }
    return "?";
}
// Share of the width that pans in a band scene.
float band(Scene s) {
    return s == Scene::band25 ? 0.25f : s == Scene::band50 ? 0.5f : s == Scene::band75 ? 0.75f : 0.f;
}

struct Planes {
    std::vector<glm::vec4> color;
    std::vector<float> depth;
    std::vector<glm::vec2> mv;
    FrameView view() const {
        return FrameView{std::as_bytes(std::span(color)), std::as_bytes(std::span(depth)),
                         std::as_bytes(std::span(mv))};
    }
};

// Frame k of a scene: a procedural texture with depth steps; `moving` pans all of it by 3 px per
// frame; `partial` moves a 64x64 square (at most 4 % of a 720p frame) over the static texture;
// the band scenes pan the columns left of band(scene) x width and keep the others still.
Planes make_frame(Scene scene, uint32_t w, uint32_t h, int k) {
    Planes p;
    const size_t n = size_t(w) * h;
    p.color.resize(n);
    p.depth.resize(n);
    p.mv.assign(n, glm::vec2(0.f));
    const float pan = scene == Scene::moving ? 3.f * float(k) : 0.f;
    const float band_end = band(scene) * float(w);
    const float sq_x = 40.f + 5.f * float(k), sq_y = 40.f, side = 64.f;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool in_band = float(x) + 0.5f < band_end;
            const float u = float(x) + 0.5f + pan + (in_band ? 3.f * float(k) : 0.f), v = float(y) + 0.5f;
            p.color[i] =
                glm::vec4(0.5f + 0.4f * std::sin(0.11f * u), 0.5f + 0.4f * std::cos(0.07f * v + 0.03f * u),
                          (int(u / 16.f) + int(v / 16.f)) % 2 ? 0.8f : 0.2f, 1.f);
            p.depth[i] = 10.f + 10.f * float((int(u / 97.f) + int(v / 61.f)) % 3);
            if (scene == Scene::moving || in_band) p.mv[i] = glm::vec2(3.f, 0.f); // the point was 3 px right
            if (scene == Scene::partial && float(x) + 0.5f >= sq_x && float(x) + 0.5f < sq_x + side &&
                v >= sq_y && v < sq_y + side) {
                p.color[i] = glm::vec4(0.9f, 0.2f, 0.1f, 1.f);
                p.depth[i] = 2.f;
                p.mv[i] = glm::vec2(-5.f, 0.f);
            }
        }
    return p;
}

struct Config {
    std::string label;
    Scene scene;
    bool sr;
    bool skip;
    uint32_t tile;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

} // namespace

int main(int argc, char** argv) {
    const uint32_t w = argc > 2 ? uint32_t(std::atoi(argv[1])) : 1280;
    const uint32_t h = argc > 2 ? uint32_t(std::atoi(argv[2])) : 720;
    const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 7;
    const std::string filter = argc > 4 ? argv[4] : "";
    auto engine = Engine::create();
    if (!engine) {
        std::fprintf(stderr, "engine: %s\n", engine.error().message.c_str());
        return 1;
    }
    std::fprintf(stderr, "device %s, %ux%u, %d rounds\n", (*engine)->device_name().c_str(), w, h, repeats);

    std::vector<Config> configs;
    for (bool sr : {false, true})
        for (Scene s : {Scene::still, Scene::partial, Scene::moving}) {
            configs.push_back({fmt::format("{} {} off", sr ? "sr" : "interp", name(s)), s, sr, false, 0});
            for (uint32_t tile : {8u, 16u, 32u})
                configs.push_back(
                    {fmt::format("{} {} t{}", sr ? "sr" : "interp", name(s), tile), s, sr, true, tile});
        }
    for (Scene s : {Scene::band25, Scene::band50, Scene::band75}) {
        configs.push_back({fmt::format("interp {} off", name(s)), s, false, false, 0});
        configs.push_back({fmt::format("interp {} t16", name(s)), s, false, true, 16});
    }
    std::erase_if(configs, [&](const Config& c) { return c.label.find(filter) == std::string::npos; });
    // Frames per scene: 4 inputs; SR inputs are half size (output w x h).
    std::map<std::pair<Scene, bool>, std::vector<Planes>> frames;
    for (bool sr : {false, true})
        for (Scene s :
             {Scene::still, Scene::partial, Scene::moving, Scene::band25, Scene::band50, Scene::band75})
            if (!sr || band(s) == 0.f)
                for (int k = 0; k < 4; ++k)
                    frames[{s, sr}].push_back(make_frame(s, sr ? w / 2 : w, sr ? h / 2 : h, k));

    std::map<std::string, std::vector<double>> ms;        // per config, per round
    std::map<std::string, std::vector<double>> ms_ingest; // the same with the newest input's ingest
    std::map<std::string, std::vector<double>> skipped;
    std::map<std::string, std::map<std::string, std::vector<double>>> pass_ms; // per config and pass
    for (int round = 0; round < repeats; ++round) {
        std::fprintf(stderr, "round %d/%d\n", round + 1, repeats);
        for (const Config& c : configs) {
            FrameFormat f;
            f.width = c.sr ? w / 2 : w;
            f.height = c.sr ? h / 2 : h;
            f.color_format = ColorFormat::rgba32f_linear;
            f.mv_format = MvFormat::rg32f;
            Params p;
            p.skip_tiles = c.skip;
            p.tile_size = c.tile;
            if (c.sr) p.scale = 2.f;
            auto s = (*engine)->create_session(f, p);
            if (!s) {
                std::fprintf(stderr, "%s: %s\n", c.label.c_str(), s.error().message.c_str());
                return 1;
            }
            double sum = 0, ingest_sum = 0, skip_sum = 0, tiles = 0;
            int count = 0;
            const auto& in = frames[{c.scene, c.sr}];
            for (size_t k = 0; k < in.size(); ++k) {
                FrameView v = in[k].view();
                v.jitter_x = c.sr ? (k % 2 ? 0.25f : -0.25f) : 0.f;
                v.jitter_y = c.sr ? (k / 2 % 2 ? 0.25f : -0.25f) : 0.f;
                if (auto r = (*s)->submit(v); !r) {
                    std::fprintf(stderr, "submit: %s\n", r.error().message.c_str());
                    return 1;
                }
                if (k < 2) continue; // the first frames: no history / no pair yet
                ingest_sum += (*s)->last_ingest_ms();
                std::vector<GeneratedFrame> out;
                if (c.sr) {
                    auto g = (*s)->super_resolved();
                    if (!g) return 1;
                    out.push_back(std::move(*g));
                } else {
                    const float alpha = 0.5f;
                    auto g = (*s)->interpolate(std::span(&alpha, 1));
                    if (!g) return 1;
                    out = std::move(*g);
                }
                for (const GeneratedFrame& g : out) {
                    for (const PassTiming& pt : g.passes) pass_ms[c.label][pt.name].push_back(pt.ms);
                    sum += g.gpu_ms;
                    ++count;
                    for (const PassTiming& pt : g.passes)
                        if (pt.name == (c.sr ? "sr" : "generate") && pt.tiles_total) {
                            skip_sum += pt.tiles_skipped;
                            tiles += pt.tiles_total;
                        }
                }
            }
            ms[c.label].push_back(sum / count);
            ms_ingest[c.label].push_back((sum + ingest_sum) / count);
            skipped[c.label].push_back(tiles > 0 ? skip_sum / tiles : 0.0);
        }
    }
    fmt::print("{}x{} output, {}, median of {} rounds (ms per frame, classify included)\n", w, h,
               (*engine)->device_name(), repeats);
    fmt::print("{:<22} {:>9} {:>10} {:>9}\n", "config", "ms", "+ingest", "skipped");
    for (const Config& c : configs)
        fmt::print("{:<22} {:>9.2f} {:>10.2f} {:>8.1f}%\n", c.label, median(ms[c.label]),
                   median(ms_ingest[c.label]), 100.0 * median(skipped[c.label]));
    fmt::print("per pass (median over rounds and frames, ms):\n");
    for (const Config& c : configs) {
        std::string line;
        for (const auto& [pass, v] : pass_ms[c.label]) line += fmt::format("{} {:.2f}  ", pass, median(v));
        fmt::print("{:<22} {}\n", c.label, line);
    }
    // Median over rounds of a / b within each round; NaN when a configuration was filtered out.
    auto ratio = [&](const std::map<std::string, std::vector<double>>& m, const std::string& a,
                     const std::string& b) {
        if (!m.count(a) || !m.count(b)) return std::nan("");
        std::vector<double> r;
        for (int k = 0; k < repeats; ++k) r.push_back(m.at(a)[size_t(k)] / m.at(b)[size_t(k)]);
        return median(r);
    };
    fmt::print("same-run ratios (median over rounds of the per-round ratio; +ingest: per frame with "
               "the ingest of its new input):\n");
    for (const char* mode : {"interp", "sr"})
        for (const char* cfg : {"off", "t8", "t16", "t32"}) {
            const std::string mv = fmt::format("{} moving {}", mode, cfg);
            const std::string st = fmt::format("{} still {}", mode, cfg);
            const std::string pa = fmt::format("{} partial {}", mode, cfg);
            if (!ms.count(mv)) continue;
            fmt::print("{:<6} {:<4} still/moving {:.3f} (+ingest {:.3f})  partial/moving {:.3f} (+ingest "
                       "{:.3f})\n",
                       mode, cfg, ratio(ms, st, mv), ratio(ms_ingest, st, mv), ratio(ms, pa, mv),
                       ratio(ms_ingest, pa, mv));
        }
    for (const char* mode : {"interp", "sr"})
        for (const char* scene : {"still", "partial", "moving", "band25", "band50", "band75"})
            for (const char* cfg : {"t8", "t16", "t32"}) {
                const std::string on = fmt::format("{} {} {}", mode, scene, cfg);
                const std::string off = fmt::format("{} {} off", mode, scene);
                if (!ms.count(on) || !ms.count(off)) continue;
                fmt::print("{:<6} {:<7} {:<4} on/off {:.3f}\n", mode, scene, cfg, ratio(ms, on, off));
            }
    return 0;
}
