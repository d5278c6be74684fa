// The colour-only stress cases (add_colour_only_cases, stress_internal.hpp): sessions without
// vectors and depth (FrameFormat::has_vectors / has_depth false, frames with empty vector and depth
// planes), where the engine estimates motion from colour. Content the estimation finds hard: flat
// colour (no texture to match), independent noise per frame (nothing to match), a scene cut the
// client does not flag, and full-frame pans far beyond any search range (216 px per frame at
// 480x270; a diagonal pan of more than a quarter of the frame on both axes). Every output must be
// finite, every submitted frame's estimated vectors and depth proxy finite (depth positive), no
// request may fail except by the engine restarting where it takes the content for a scene cut
// (Step::cut_allowed: noise, fades and pans beyond the search range may be), each case ends within
// max_seconds, and across the unflagged cut the generated frame is one of the two inputs or the
// request is refused as after a reset (Step::across_cut). Three of them also run with zero vectors
// and depth given and corrected by colour (Params::correct_vectors): content where the correction
// has nothing to go by (flat, noise) or where every pixel disagrees with its given vector (the pan).
// Three run at 256x144, where the patch inverse search runs on level 1 (Params::motion_search):
// flat colour that brightens, noise, and a slow pan with non-finite and extreme channels.
// Two run with fast motion estimation too (Params::fast_motion: the vectors without refinement):
// flat colour that brightens and noise, where nothing but the refinement smooths the estimate.
// The same three with zero vectors given run in sessions that also generate from colour-only motion
// (Params::colour_agree: the agree pass, its box by running sums over 32-pixel segments), with noise
// at sizes whose sides are 1, 7, 23, 33 and 65 pixels (no full segment, a partial last one).
#include "stress_internal.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace fgsr::stress::detail {

namespace {

constexpr double kMaxSeconds = 120.0; // lavapipe on 2 shared cores; the largest case takes a few s

// Integer hash of a lattice point (for textures with features at every scale the search sees).
float lattice(int32_t x, int32_t y, uint32_t seed) {
    uint32_t h = uint32_t(x) * 0x8da6b343u ^ uint32_t(y) * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return float(h & 0xffffu) / 65535.f;
}

// A textured world seen through a frame whose top-left corner is at `offset` (world pixels):
// blocks of 3 sizes plus smooth waves, `seed` choosing the scene.
glm::vec4 world(float wx, float wy, uint32_t seed) {
    const int32_t x = int32_t(std::floor(wx)), y = int32_t(std::floor(wy));
    const float fine = lattice(x >> 2, y >> 2, seed), mid = lattice(x >> 4, y >> 4, seed + 1),
                coarse = lattice(x >> 6, y >> 6, seed + 2);
    const float wave = 0.5f + 0.5f * std::sin(0.11f * wx + 0.7f * std::sin(0.031f * wy + float(seed)));
    return glm::vec4(0.15f + 0.6f * (0.5f * fine + 0.5f * wave), 0.1f + 0.7f * mid, 0.2f + 0.6f * coarse,
                     1.f);
}

Frame colour_frame(const FrameFormat& f, const std::vector<glm::vec4>& color) {
    Content c;
    c.w = f.width;
    c.h = f.height;
    c.color = color;
    c.depth.assign(color.size(), 1.f);
    c.mv.assign(color.size(), glm::vec2(0.f));
    Frame fr = encode(f, c, f.has_vectors); // zero vectors where the session has them
    if (!f.has_depth) fr.depth.clear();     // withheld: the session has no depth
    return fr;
}

Frame panned(const FrameFormat& f, glm::vec2 offset, uint32_t seed) {
    std::vector<glm::vec4> color(size_t(f.width) * f.height);
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x)
            color[size_t(y) * f.width + x] = world(float(x) + offset.x, float(y) + offset.y, seed);
    return colour_frame(f, color);
}

// The panned world with a special value in one channel of about 15 % of its pixels: NaN, +Inf, -Inf,
// half's largest finite value and a half denormal, by turns.
Frame panned_specials(const FrameFormat& f, glm::vec2 offset, uint32_t seed) {
    const float specials[5] = {std::numeric_limits<float>::quiet_NaN(),
                               std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity(), 65504.f, 1e-7f};
    std::vector<glm::vec4> color(size_t(f.width) * f.height);
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x) {
            glm::vec4& c = color[size_t(y) * f.width + x];
            c = world(float(x) + offset.x, float(y) + offset.y, seed);
            if (lattice(int32_t(x), int32_t(y), seed + 5) < 0.15f) c[(x + y) % 3] = specials[(x + 2 * y) % 5];
        }
    return colour_frame(f, color);
}

Frame flat(const FrameFormat& f, float v) {
    return colour_frame(f, std::vector<glm::vec4>(size_t(f.width) * f.height, glm::vec4(v, v, v, 1.f)));
}

Frame noise(const FrameFormat& f, uint32_t frame) {
    std::vector<glm::vec4> color(size_t(f.width) * f.height);
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x)
            for (int ch = 0; ch < 3; ++ch)
                color[size_t(y) * f.width + x][ch] =
                    lattice(int32_t(x), int32_t(y), 977u * frame + uint32_t(ch));
    for (glm::vec4& c : color) c.w = 1.f;
    return colour_frame(f, color);
}

FrameFormat colour_format(uint32_t w, uint32_t h) {
    FrameFormat f = format_of(w, h);
    f.has_vectors = false;
    f.has_depth = false;
    return f;
}

const std::vector<float> kInterp = {1e-6f, 0.5f, 1.f - 1e-6f};
const std::vector<float> kExtrap = {1e-6f, 0.5f, 1.f};

// Three frames made by `frame(k)`: every request after the second and the third (SR outputs with
// a scale), then one more interpolation.
Case sequence_case(std::string name, std::string checks, const FrameFormat& f, float scale,
                   std::function<Frame(int)> frame, bool fast_motion = false, bool agree = false) {
    const bool sr = scale > 1.f;
    Case c;
    c.name = sr ? name + "/sr" : std::move(name);
    c.checks = std::move(checks);
    c.format = f;
    c.params = params_of(scale);
    c.params.correct_vectors = f.has_vectors && !agree; // the corrected/* cases below
    c.params.colour_agree = agree;                      // the agreeing/* cases
    c.params.fast_motion = fast_motion;
    c.cpu_reference = false; // the CPU reference has no motion estimation; GPU-CPU tests are the passes'
    c.max_seconds = kMaxSeconds;
    std::vector<StepFn> s;
    for (int k = 0; k < 3; ++k) {
        s.push_back([=] { return submit(frame(k)); });
        if (sr) s.push_back([] { return request(Op::super_resolve, {}); });
        if (k == 0) continue;
        for (Op op : {Op::interpolate, Op::extrapolate})
            s.push_back([op] {
                Step st = request(op, op == Op::interpolate ? kInterp : kExtrap);
                st.cut_allowed = true; // the engine may take this content for a cut and restart
                return st;
            });
    }
    c.step_count = s.size();
    c.step = sequence(std::move(s));
    return c;
}

} // namespace

void add_colour_only_cases(std::vector<Case>& out) {
    for (float scale : {1.f, 2.f}) {
        const FrameFormat small = colour_format(64, 36);
        out.push_back(sequence_case("colour-only/flat", "colour only: flat grey (0.4), no texture to match",
                                    small, scale, [small](int) { return flat(small, 0.4f); }));
        out.push_back(sequence_case("colour-only/flat-changing",
                                    "colour only: flat colour that brightens every frame (0.2, 0.5, 0.8)",
                                    small, scale,
                                    [small](int k) { return flat(small, 0.2f + 0.3f * float(k)); }));
        out.push_back(sequence_case("colour-only/noise", "colour only: independent uniform noise every frame",
                                    small, scale, [small](int k) { return noise(small, uint32_t(k)); }));
    }
    const FrameFormat f = colour_format(480, 270);
    out.push_back(sequence_case("colour-only/pan-216px",
                                "colour only: 480x270, full-frame pan of 216 px per frame", f, 1.f,
                                [f](int k) { return panned(f, glm::vec2(216.f * float(k), 0.f), 7); }));
    out.push_back(
        sequence_case("colour-only/pan-diagonal-quarter",
                      "colour only: 480x270, full-frame pan of (-130, 72) px per frame (over a quarter "
                      "of the frame on both axes)",
                      f, 1.f, [f](int k) { return panned(f, glm::vec2(-130.f, 72.f) * float(k), 11); }));

    // The same content at a size whose level 1 (128x72) the patch inverse search runs on
    // (Params::motion_search, ref::kSearchMinSide): a flat patch has no Gauss-Newton step (a zero
    // matrix), noise a matrix of random gradients and no right vector.
    const FrameFormat searched = colour_format(256, 144);
    out.push_back(sequence_case("colour-only/searched/flat-changing",
                                "colour only, 256x144 (the patch search runs): flat colour that brightens "
                                "every frame",
                                searched, 1.f,
                                [searched](int k) { return flat(searched, 0.2f + 0.3f * float(k)); }));
    out.push_back(sequence_case("colour-only/searched/noise",
                                "colour only, 256x144 (the patch search runs): independent uniform noise "
                                "every frame",
                                searched, 1.f, [searched](int k) { return noise(searched, uint32_t(k)); }));
    out.push_back(sequence_case(
        "colour-only/searched/pan-specials",
        "colour only, 256x144 (the patch search runs): a 3 px a frame pan with NaN, +-Inf, 65504 and "
        "denormal channels in about 15 % of the pixels",
        searched, 1.f,
        [searched](int k) { return panned_specials(searched, glm::vec2(3.f * float(k), 0.f), 13); }));

    // Fast motion estimation on the content with nothing to match.
    const FrameFormat small = colour_format(64, 36);
    out.push_back(sequence_case(
        "colour-only/fast/flat-changing", "colour only, fast motion: flat colour that brightens every frame",
        small, 1.f, [small](int k) { return flat(small, 0.2f + 0.3f * float(k)); }, true));
    out.push_back(sequence_case(
        "colour-only/fast/noise", "colour only, fast motion: independent uniform noise every frame", small,
        1.f, [small](int k) { return noise(small, uint32_t(k)); }, true));

    // The same content with zero vectors and depth given, corrected by colour.
    const FrameFormat z = format_of(64, 36);
    out.push_back(sequence_case("corrected/flat-changing",
                                "corrected vectors: flat colour that brightens every frame (0.2, 0.5, 0.8)", z,
                                1.f, [z](int k) { return flat(z, 0.2f + 0.3f * float(k)); }));
    out.push_back(sequence_case("corrected/noise", "corrected vectors: independent uniform noise every frame", z,
                                1.f, [z](int k) { return noise(z, uint32_t(k)); }));
    const FrameFormat zf = format_of(480, 270);
    out.push_back(sequence_case("corrected/pan-216px",
                                "corrected vectors: 480x270, full-frame pan of 216 px per frame, given zero",
                                zf, 1.f, [zf](int k) { return panned(zf, glm::vec2(216.f * float(k), 0.f), 7); }));

    // The same content with zero vectors and depth given, in sessions that also generate from
    // colour-only motion and take per pixel the field whose warped frames agree.
    out.push_back(sequence_case(
        "agreeing/flat-changing", "colour_agree: flat colour that brightens every frame, zero vectors given",
        z, 1.f, [z](int k) { return flat(z, 0.2f + 0.3f * float(k)); }, false, true));
    out.push_back(sequence_case(
        "agreeing/noise", "colour_agree: independent uniform noise every frame, zero vectors given", z, 1.f,
        [z](int k) { return noise(z, uint32_t(k)); }, false, true));
    out.push_back(sequence_case(
        "agreeing/pan-216px", "colour_agree: 480x270, full-frame pan of 216 px per frame, zero vectors given",
        zf, 1.f, [zf](int k) { return panned(zf, glm::vec2(216.f * float(k), 0.f), 7); }, false, true));
    for (const glm::uvec2 size :
         {glm::uvec2(1, 1), glm::uvec2(7, 1), glm::uvec2(1, 7), glm::uvec2(37, 23), glm::uvec2(33, 65)}) {
        const FrameFormat a = format_of(size.x, size.y);
        const std::string wh = std::to_string(size.x) + "x" + std::to_string(size.y);
        out.push_back(sequence_case(
            "agreeing/noise-" + wh,
            "colour_agree: " + wh + " frames of independent noise, zero vectors given", a, 1.f,
            [a](int k) { return noise(a, uint32_t(k)); }, false, true));
    }
    // With super resolution, extrapolation from both fields (ESR: the box means at the input's
    // size, the mix per output pixel), at scales that are and are not integers.
    out.push_back(sequence_case(
        "agreeing/flat-changing",
        "colour_agree, x2: flat colour that brightens every frame, zero vectors given", z, 2.f,
        [z](int k) { return flat(z, 0.2f + 0.3f * float(k)); }, false, true));
    for (const auto& [size, scale] : {std::pair{glm::uvec2(1, 1), 2.f}, std::pair{glm::uvec2(37, 23), 1.5f},
                                      std::pair{glm::uvec2(7, 1), 3.f}}) {
        const FrameFormat a = format_of(size.x, size.y);
        const std::string wh = std::to_string(size.x) + "x" + std::to_string(size.y);
        out.push_back(sequence_case(
            "agreeing/noise-" + wh,
            "colour_agree, x" + std::to_string(scale).substr(0, 3) + ": " + wh +
                " frames of independent noise, zero vectors given",
            a, scale, [a](int k) { return noise(a, uint32_t(k)); }, false, true));
    }

    // A cut the client does not flag: two frames of one scene (a slow pan), then another scene.
    const FrameFormat g = colour_format(96, 54);
    Case c;
    c.name = "colour-only/scene-cut";
    c.checks = "colour only: an unflagged cut between two scenes; across it the output is one of the two "
               "frames or the request is refused as after a reset; the session works on after it";
    c.format = g;
    c.params = params_of(1.f);
    c.cpu_reference = false;
    c.max_seconds = kMaxSeconds;
    std::vector<StepFn> s = {
        [g] { return submit(panned(g, glm::vec2(0.f), 3)); },
        [g] { return submit(panned(g, glm::vec2(3.f, 1.f), 3)); },
        [] { return request(Op::interpolate, {0.5f}); },
        [g] { return submit(panned(g, glm::vec2(500.f, 300.f), 99)); }, // the other scene
        [] {
            Step st = request(Op::interpolate, {0.5f});
            st.across_cut = true;
            return st;
        },
        [] {
            Step st = request(Op::extrapolate, {0.5f});
            st.across_cut = true;
            return st;
        },
        [g] { return submit(panned(g, glm::vec2(503.f, 301.f), 99)); },
        [] { return request(Op::interpolate, kInterp); },
        [] { return request(Op::extrapolate, kExtrap); },
    };
    c.step_count = s.size();
    c.step = sequence(std::move(s));
    out.push_back(std::move(c));
}

} // namespace fgsr::stress::detail
