// Engine::warm_up (engine.hpp): the usual sessions' passes run once on small synthetic frames.
#include <fgsr/engine/engine.hpp>

#include "context.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
#include <thread>

namespace fgsr {
namespace {

constexpr uint32_t kWidth = 128, kHeight = 96; // two levels of the motion pyramid, several tiles
constexpr uint32_t kSide = 32;                 // the mover's side, pixels
constexpr float kStep = 3.0f;                  // its motion, pixels a frame (to the right)
constexpr float kNear = 4.0f, kFar = 10.0f;    // linear depths of the mover and the background

// A value in [0.1, 0.9] per texel: texture the matching can lock on to.
float texel(uint32_t x, uint32_t y, uint32_t seed) {
    uint32_t v = x * 73856093u ^ y * 19349663u ^ seed * 83492791u;
    v ^= v >> 13;
    v *= 0x5bd1e995u;
    v ^= v >> 15;
    return 0.1f + 0.8f * float(v & 1023u) / 1023.0f;
}

struct Frame {
    std::vector<std::byte> color, depth, mv;
    FrameView view(float jitter_x = 0.f, float jitter_y = 0.f) const {
        return FrameView{color, depth, mv, jitter_x, jitter_y};
    }
};

// Frame k: the mover (its own texture, travelling with it) at x = 16 + k * kStep over the
// background, still or panning by one pixel a frame (then no tile is still); vectors to the
// previous frame and linear depth when the format has them.
Frame render(const FrameFormat& f, uint32_t k, bool pan) {
    const size_t n = size_t(f.width) * f.height;
    std::vector<glm::vec4> rgba(n);
    std::vector<float> depth(n);
    std::vector<glm::vec2> mv(n);
    const float left = 16.0f + float(k) * kStep, top = 24.0f;
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x) {
            const size_t i = size_t(y) * f.width + x;
            const float lx = float(x) - left, ly = float(y) - top;
            const bool mover = lx >= 0 && ly >= 0 && lx < float(kSide) && ly < float(kSide);
            const uint32_t bx = x + (pan ? 64u - k : 0u);
            const float v = mover ? texel(uint32_t(lx), uint32_t(ly), 7) : texel(bx, y, 3);
            rgba[i] = glm::vec4(v, 0.5f * v + 0.2f, 1.0f - v, 1.0f);
            depth[i] = mover ? kNear : kFar;
            mv[i] = mover ? glm::vec2(-kStep, 0.0f) : glm::vec2(pan ? -1.0f : 0.0f, 0.0f);
        }
    Frame out;
    const size_t bpp = bytes_per_pixel(f.color_format);
    out.color.resize(n * bpp);
    for (size_t i = 0; i < n; ++i) {
        std::byte* px = out.color.data() + i * bpp;
        if (f.color_format == ColorFormat::rgba8_srgb) {
            for (int c = 0; c < 4; ++c) { // the texture's values as sRGB-encoded bytes
                const uint8_t b = uint8_t(glm::clamp(rgba[i][c], 0.0f, 1.0f) * 255.0f + 0.5f);
                px[c] = std::byte(b);
            }
        } else if (f.color_format == ColorFormat::rgba16f_linear) {
            for (int c = 0; c < 4; ++c) {
                const uint16_t h = glm::packHalf1x16(rgba[i][c]);
                std::memcpy(px + 2 * c, &h, 2);
            }
        } else {
            std::memcpy(px, &rgba[i], 16);
        }
    }
    if (f.has_depth) {
        out.depth.resize(n * 4);
        std::memcpy(out.depth.data(), depth.data(), out.depth.size());
    }
    if (f.has_vectors) {
        out.mv.resize(n * bytes_per_pixel(f.mv_format));
        if (f.mv_format == MvFormat::rg32f) {
            std::memcpy(out.mv.data(), mv.data(), out.mv.size());
        } else {
            for (size_t i = 0; i < n; ++i) {
                const uint32_t h = glm::packHalf2x16(mv[i]);
                std::memcpy(out.mv.data() + 4 * i, &h, 4);
            }
        }
    }
    return out;
}

} // namespace

Result<uint32_t> Engine::warm_up() {
    // Every pipeline first, on every core (sessions create theirs at first use, one at a time).
    FGSR_TRY(impl_->pipelines.create_all(std::max(1u, std::thread::hardware_concurrency())));
    struct Kind {
        ColorFormat color;
        bool vectors; // and depth
        bool passes;  // every pass (else only the first pair, for the ingest build of the format)
    };
    // The layer's sessions (colour only; 8-bit and HDR swapchains), then the client library's.
    // Builds differ by format only in ingest. Every count at every pair: 2 backgrounds x 3 pairs
    // x (1 + 2 + 3) x 2 directions = 72 frames a full kind, 2 for the other.
    constexpr std::array<Kind, 3> kinds{{{ColorFormat::rgba8_srgb, false, true},
                                         {ColorFormat::rgba16f_linear, false, false},
                                         {ColorFormat::rgba16f_linear, true, true}}};
    constexpr std::array<float, 3> alphas{0.25f, 0.5f, 0.75f};
    const std::array<std::span<const float>, 3> per_pair{
        std::span<const float>(alphas.data() + 1, 1), // 1 frame a pair: 1/2
        std::span<const float>(alphas.data(), 2),     // 2 (any two alphas take the same builds)
        std::span<const float>(alphas.data(), 3)};    // 3
    uint32_t generated = 0;
    // Super resolution x2 (half float with vectors and depth, the client library's): the
    // super-resolved frame of every submit, one frame interpolated and extrapolated (ISR, ESR) at
    // every pair, over the still and the panning background: 2 x (4 + 3 x 2) = 20 frames.
    for (const bool pan : {false, true}) {
        FrameFormat f;
        f.width = kWidth / 2;
        f.height = kHeight / 2;
        f.color_format = ColorFormat::rgba16f_linear;
        f.mv_format = MvFormat::rg16f;
        Params params;
        params.scale = 2.0f;
        auto session = create_session(f, params);
        if (!session) return session.error();
        for (uint32_t k = 0; k < 4; ++k) {
            const Frame frame = render(f, k, pan);
            const FrameView view = frame.view(k % 2 == 0 ? -0.25f : 0.25f, k / 2 == 0 ? -0.25f : 0.25f);
            if (auto r = (*session)->submit(view); !r) return r.error();
            auto sr = (*session)->super_resolved();
            if (!sr) return sr.error();
            ++generated;
            if (k == 0) continue;
            auto in = (*session)->interpolate(per_pair[0]);
            if (!in) return in.error();
            auto ex = (*session)->extrapolate(per_pair[0]);
            if (!ex) return ex.error();
            generated += uint32_t(in->size() + ex->size());
        }
    }
    for (const Kind& kind : kinds) {
        FrameFormat f;
        f.width = kWidth;
        f.height = kHeight;
        f.color_format = kind.color;
        f.mv_format = MvFormat::rg16f;
        f.has_vectors = kind.vectors;
        f.has_depth = kind.vectors;
        // Still background (tiles skipped: the tiled builds), then panning (the untiled ones).
        for (const bool pan : {false, true}) {
            if (pan && !kind.passes) break;
            auto session = create_session(f);
            if (!session) return session.error();
            const uint32_t frames = kind.passes ? 4 : 2;
            for (uint32_t k = 0; k < frames; ++k) {
                const Frame frame = render(f, k, pan);
                if (auto r = (*session)->submit(frame.view()); !r) return r.error();
                if (k == 0) continue;
                // Every count at every pair: the builds differ with the count and with the frames
                // behind (the first pair has no frame before it).
                for (const std::span<const float> a : per_pair) {
                    auto in = (*session)->interpolate(a);
                    if (!in) return in.error();
                    auto ex = (*session)->extrapolate(a);
                    if (!ex) return ex.error();
                    generated += uint32_t(in->size() + ex->size());
                    if (!kind.passes) break;
                }
            }
        }
    }
    return generated;
}

} // namespace fgsr
