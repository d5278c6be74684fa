// Shared test helpers: one engine per test process (lavapipe by default, validation on when
// FGSR_VALIDATION=1, which ctest sets), frame builders and comparisons.
#pragma once

#include <fgsr/engine/engine.hpp>
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

namespace fgsr::test {

inline Engine& engine() {
    static std::unique_ptr<Engine> e = [] {
        auto r = Engine::create();
        if (!r) {
            std::fprintf(stderr, "cannot create the engine: %s\n", r.error().message.c_str());
            std::abort();
        }
        return std::move(*r);
    }();
    return *e;
}

// The default Params without colour_agree (on by default since change 41): the given field's path
// alone, which fgsrd's sessions run unless a client asks for agreement. Tests of a pass of that path
// (tile skipping, the fused passes, the CPU references of one field) use it, so that a session with
// vectors does not also run the colour-only twin and the agree pass over its frames.
inline Params given_field() {
    Params p;
    p.colour_agree = false;
    return p;
}

// Fails the current test when the validation layer reported errors since the last call.
inline void expect_no_validation_errors() {
    static uint64_t seen = 0;
    uint64_t now = engine().validation_errors();
    EXPECT_EQ(now, seen) << "Vulkan validation errors were reported (see stderr)";
    seen = now;
}

template <class T> std::vector<std::byte> bytes_of(const std::vector<T>& v) {
    std::vector<std::byte> b(v.size() * sizeof(T));
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}

// A frame in the internal convention as raw planes: rgba32f colour, linear depth, rg32f vectors.
struct RawFrame {
    std::vector<std::byte> color, depth, mv;
    FrameView view() const { return FrameView{color, depth, mv}; }
};

inline FrameFormat internal_format(uint32_t w, uint32_t h) {
    FrameFormat f;
    f.width = w;
    f.height = h;
    f.color_format = ColorFormat::rgba32f_linear;
    f.mv_format = MvFormat::rg32f;
    return f;
}

inline RawFrame make_raw(const std::vector<glm::vec4>& color, const std::vector<float>& depth,
                         const std::vector<glm::vec2>& mv) {
    return RawFrame{bytes_of(color), bytes_of(depth), mv.empty() ? std::vector<std::byte>{} : bytes_of(mv)};
}

inline ref::InternalFrame to_internal(const Session::InternalFrameData& d, uint32_t w, uint32_t h) {
    ref::InternalFrame f;
    f.width = w;
    f.height = h;
    size_t n = size_t(w) * h;
    f.color.resize(n);
    f.depth = d.depth;
    f.mv.resize(n);
    std::memcpy(f.color.data(), d.color.data(), n * 16);
    std::memcpy(f.mv.data(), d.mv.data(), n * 8);
    f.has_mv = d.has_mv;
    return f;
}

// Random frame: colours in [0,1], depths in [1,100] with flat patches (ties and edges), vectors
// in [-range, range] pixels, constant over small blocks so that splats collide.
// The warped frames of read-back intermediates (separate passes) as ref::blend and ref::agree take
// them: frame 0's, then frame 1's.
inline ref::Warped warped_of(const Session::Intermediates& m) {
    const size_t n = m.warped_depth0.size();
    ref::Warped w;
    w.color.resize(2 * n);
    w.depth.resize(2 * n);
    std::memcpy(w.color.data(), m.warped_color0.data(), n * 16);
    std::memcpy(w.color.data() + n, m.warped_color1.data(), n * 16);
    std::copy(m.warped_depth0.begin(), m.warped_depth0.end(), w.depth.begin());
    std::copy(m.warped_depth1.begin(), m.warped_depth1.end(), w.depth.begin() + long(n));
    return w;
}

inline RawFrame random_frame(uint32_t w, uint32_t h, uint32_t seed, float range, bool with_mv = true) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.f, 1.f), um(-range, range), ud(1.f, 100.f);
    size_t n = size_t(w) * h;
    std::vector<glm::vec4> c(n);
    std::vector<float> d(n);
    std::vector<glm::vec2> m(with_mv ? n : 0);
    const uint32_t block = 4;
    uint32_t bw = (w + block - 1) / block, bh = (h + block - 1) / block;
    std::vector<float> bd(size_t(bw) * bh);
    std::vector<glm::vec2> bm(size_t(bw) * bh);
    for (size_t i = 0; i < bd.size(); ++i) {
        bd[i] = ud(rng);
        bm[i] = glm::vec2(um(rng), um(rng));
    }
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = size_t(y) * w + x, b = size_t(y / block) * bw + x / block;
            c[i] = glm::vec4(u01(rng), u01(rng), u01(rng), 1.f);
            d[i] = bd[b];
            if (with_mv) m[i] = bm[b] + glm::vec2(um(rng), um(rng)) * 0.05f;
        }
    return make_raw(c, d, m);
}

} // namespace fgsr::test
