// CPU reference: the algorithm headers of shaders/ compiled as C++ members of small structs whose
// load_/store_ functions read and write host vectors.
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

// The algorithm headers are included inside structs in dependency order: keep them unsorted.
// clang-format off
namespace fgsr::gpu {

namespace {

uint word_at(const std::byte* base, size_t word) {
    uint v;
    std::memcpy(&v, base + 4 * word, 4);
    return v;
}

struct IngestCpu {
    const std::byte* color;
    const std::byte* depth;
    const std::byte* mv;
    ref::InternalFrame* out;

    uint load_color_word(uint w) const { return word_at(color, w); }
    uvec2 load_color_pair(uint p) const { return uvec2(word_at(color, 2 * p), word_at(color, 2 * p + 1)); }
    uint load_depth_word(uint i) const { return word_at(depth, i); }
    uint load_mv_word(uint w) const { return word_at(mv, w); }
    uvec2 load_mv_pair(uint p) const { return uvec2(word_at(mv, 2 * p), word_at(mv, 2 * p + 1)); }
    void store_frame(uint i, uvec2 c, float d, vec2 m) {
        out->color[i] = unpack_color(c); // exactly the values the GPU passes unpack
        out->depth[i] = d;
        out->mv[i] = m;
    }
#include "ingest.h"
    void note_bright(uvec2, vec4, IngestParams) {} // tile flags: the reference dilates every pixel
};

// Ingest's dilate stage: reads the ingested frame (a copy), writes f.
struct DilateCpu {
    const ref::InternalFrame* src;
    ref::InternalFrame* f;
    const ref::InternalFrame* prev; // the edge rule's previous frame (null: the rule is off)
    vec4 load_frame_color(uint i) const { return src->color[i]; }
    vec4 load_prev_color(uint i) const { return prev->color[i]; }
    float load_source_depth(uint i) const { return src->depth[i]; }
    vec2 load_source_mv(uint i) const { return src->mv[i]; }
    void store_frame_depth_mv(uint i, float d, vec2 m) {
        f->depth[i] = d;
        f->mv[i] = m;
    }
#include "dilate.h"
};

// Ingest's cut stage: the ingested frame against the previous frame's colour.
struct CutCpu {
    const ref::InternalFrame* f;
    const ref::InternalFrame* prev;
    std::vector<ref::CutBlock>* out;
    float load_cut_luma(uint i) const { return motion_luma(f->color[i]); }
    float load_cut_prev_luma(uint i) const { return motion_luma(prev->color[i]); }
    vec2 load_cut_mv(uint i) const { return f->mv[i]; }
    void store_cut_block(uint b, vec4 sad, vec4 level) { (*out)[b] = {sad, level}; }
#include "cut.h"
};

// Loads shared by the generation passes.
struct FramesCpu {
    const ref::InternalFrame* f0;
    const ref::InternalFrame* f1;
    size_t at(ivec2 q) const { return size_t(q.y) * f1->width + size_t(q.x); }
    vec2 load_mv1(ivec2 q) const { return f1->mv[at(q)]; }
    vec2 load_mv0(ivec2 q) const { return f0->mv[at(q)]; }
    float load_depth1(ivec2 q) const { return f1->depth[at(q)]; }
    float load_depth0(ivec2 q) const { return f0->depth[at(q)]; }
    vec4 load_color1(ivec2 q) const { return f1->color[at(q)]; }
    vec4 load_color0(ivec2 q) const { return f0->color[at(q)]; }
};

// One alpha per splat (the GPU's slices of a multi-alpha dispatch are each this splat).
struct SplatCpu : FramesCpu {
    ref::Splat* out;
    float alpha;
    uint splat_count() const { return 1u; }
    float splat_alpha(uint) const { return alpha; }
    void splat_min(uint, uint i, uint64_t key) { out->keys[i] = std::min(out->keys[i], key); }
    void store_source_motion(uint i, vec4 m) { out->motion[i] = m; }
    vec4 load_source_motion(uint i) const { return out->motion[i]; }
#include "field.h"
#include "motion.h"
#include "splat.h"
};

struct KeysCpu : FramesCpu {
    const ref::Splat* splat;
    GenParams gen; // the generated frame's (load_motion)
    uint64_t load_key(ivec2 q) const { return splat->keys[at(q)]; }
    vec4 load_source_motion(uint src) const { return splat->motion[src]; }
#include "field.h"
#include "motion.h"
    vec4 load_motion(uint src) { return source_field_vectors(src, gen); }
#include "refine.h"
#include "disocc.h"
};

struct WarpCpu : FramesCpu {
#include "field.h"
#include "warp.h"
};

struct BlendCpu : FramesCpu {
#include "field.h"
#include "depth_change.h"
#include "blend_depth.h"
#include "blend.h"
};

struct AgreeCpu {
    const ref::Warped* warped_frames[2];
    const std::vector<uint32_t>* field_states[2];
    const std::vector<vec4>* frames[2]; // given, colour
    std::vector<vec2> e_buf, rows_buf;
    size_t n;
    // Extrapolation's stage 4: the inputs (frame 0, frame 1) and each field's frame-1 vectors.
    const ref::InternalFrame* inputs[2] = {};
    const std::vector<vec2>* field_mv[2] = {};
    const std::vector<vec4>* given_field = nullptr; // stage 1: the given field's (v0, v1)
    vec4 load_given_field(uint i) const { return (*given_field)[i]; }
    vec4 load_frame_colour(uint f, uint i) const { return inputs[f]->color[i]; }
    float load_frame_depth(uint f, uint i) const { return inputs[f]->depth[i]; }
    vec2 load_field_mv(uint field, uint i) const { return (*field_mv[field])[i]; }
    uint width = 0; // stage 4's pixel reads by position (depth_change.h)
    vec2 load_mv1(ivec2 q) const { return (*field_mv[0])[size_t(q.y) * width + size_t(q.x)]; }
    float load_depth1(ivec2 q) const { return inputs[1]->depth[size_t(q.y) * width + size_t(q.x)]; }
    vec4 load_warped(uint field, uint f, uint i) const { return warped_frames[field]->color[f * n + i]; }
    float load_warped_depth(uint field, uint f, uint i) const { return warped_frames[field]->depth[f * n + i]; }
    uint load_field_state(uint field, uint i) const { return (*field_states[field])[i]; }
    vec2 load_e(uint i) const { return e_buf[i]; }
    vec2 load_rows(uint i) const { return rows_buf[i]; }
    std::vector<vec4> light_buf, light_rows_buf; // stages 5-7 (AgreeParams::gain)
    vec4 load_light(uint i) const { return light_buf[i]; }
    vec4 load_light_rows(uint i) const { return light_rows_buf[i]; }
    void store_light(uint i, vec4 v) { light_buf[i] = v; }
    void store_light_rows(uint i, vec4 v) { light_rows_buf[i] = v; }
    void store_rows(uint i, vec2 v) { rows_buf[i] = v; }
    std::vector<vec4>* agreed = nullptr; // stage 3's output
    void store_agreed(uint i, vec4 c) { (*agreed)[i] = c; }
    void store_means(uint i, vec2 m) { e_buf[i] = m; } // stage 8
    vec4 load_given(uint i) const { return (*frames[0])[i]; }
    vec4 load_colour(uint i) const { return (*frames[1])[i]; }
#include "field.h"
#include "blend.h"
#include "agree.h"
};

struct GenerateCpu : KeysCpu {
    std::vector<vec4>* out;
    void store_output(uint i, vec4 c) { (*out)[i] = c; }
#include "warp.h"
#include "blend_depth.h"
#include "blend.h"
#include "generate.h"
};

struct ClassifyCpu : FramesCpu {
#include "field.h"
#include "depth_change.h"
#include "blend_depth.h"
#include "blend.h"
#include "classify.h"
};

struct ResampleCpu {
    const std::vector<vec4>* src;
    uint width;
    std::span<const float> lut;
    vec4 load_src(ivec2 q) const { return (*src)[size_t(q.y) * width + size_t(q.x)]; }
    vec4 load_lut4(uint r) const { return vec4(lut[4 * r], lut[4 * r + 1], lut[4 * r + 2], lut[4 * r + 3]); }
#include "resample.h"
};

struct SrCpu {
    const ref::InternalFrame* cur;
    const std::vector<float>* prev_depth;
    const std::vector<vec4>* history;
    std::span<const float> lut;
    uint lr_w, hr_w;
    std::vector<vec2> noise; // sr.h's (r, q) per LR pixel, the stage's output
    vec4 load_lr_color(ivec2 q) const { return cur->color[size_t(q.y) * lr_w + size_t(q.x)]; }
    vec2 load_noise(ivec2 q) const { return noise[size_t(q.y) * lr_w + size_t(q.x)]; }
    float load_lr_depth(ivec2 q) const { return cur->depth[size_t(q.y) * lr_w + size_t(q.x)]; }
    vec2 load_lr_mv(ivec2 q) const { return cur->mv[size_t(q.y) * lr_w + size_t(q.x)]; }
    float load_prev_depth(ivec2 q) const { return (*prev_depth)[size_t(q.y) * lr_w + size_t(q.x)]; }
    vec4 load_src(ivec2 q) const { return (*history)[size_t(q.y) * hr_w + size_t(q.x)]; }
    vec4 load_lut4(uint r) const { return vec4(lut[4 * r], lut[4 * r + 1], lut[4 * r + 2], lut[4 * r + 3]); }
#include "resample.h"
#include "sr.h"
};

struct DenoiseCpu {
    const ref::InternalFrame* in;
    std::vector<vec4>* out;
    std::array<uint, DENOISE_WORDS>* noise;
    vec4 load_color(ivec2 q) const { return in->color[size_t(q.y) * in->width + size_t(q.x)]; }
    void store_color(uint i, vec4 c) { (*out)[i] = unpack_color(pack_color(c)); } // as the GPU stores it
    void add_to_bin(uint b) { ++(*noise)[b]; }
    uint load_bin(uint b) const { return (*noise)[b]; }
    void store_level(float sigma, float range) {
        (*noise)[DENOISE_SIGMA] = floatBitsToUint(sigma);
        (*noise)[DENOISE_RANGE] = floatBitsToUint(range);
    }
    float load_range() const { return uintBitsToFloat((*noise)[DENOISE_RANGE]); }
#include "denoise.h"
};

struct GenerateSrCpu : KeysCpu {
    const std::vector<vec4>* src;
    std::span<const float> lut;
    uint hr_w;
    vec4 load_src(ivec2 q) const { return (*src)[size_t(q.y) * hr_w + size_t(q.x)]; }
    vec4 load_lut4(uint r) const { return vec4(lut[4 * r], lut[4 * r + 1], lut[4 * r + 2], lut[4 * r + 3]); }
#include "warp.h"
#include "blend_depth.h"
#include "blend.h"
#include "resample.h"
#include "generate_sr.h"
};

#include "field.h" // FIELD_* for the static_assert in fgsr::ref

template <class F> void for_each_pixel(uint32_t w, uint32_t h, F&& f) {
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) f(ivec2(int(x), int(y)));
}

} // namespace
} // namespace fgsr::gpu
// clang-format on

namespace fgsr::ref {

using gpu::for_each_pixel;

static_assert(kFieldSplatted == FIELD_SPLATTED && kFieldGapFilled == FIELD_GAP_FILLED &&
              kFieldHole == FIELD_HOLE && kFieldHoleFilled == FIELD_HOLE_FILLED);

InternalFrame ingest(const FrameFormat& f, const FrameView& frame, glm::vec2 mv_offset) {
    const size_t n = size_t(f.width) * f.height;
    InternalFrame out;
    out.width = f.width;
    out.height = f.height;
    out.color.resize(n);
    out.depth.resize(n);
    out.mv.resize(n);
    out.has_mv = f.has_vectors && !frame.mv.empty();
    gpu::IngestCpu cpu{frame.color.data(), frame.depth.data(), frame.mv.data(), &out};
    IngestParams p = params::ingest_params(f, out.has_mv);
    p.mv_offset_x = mv_offset.x;
    p.mv_offset_y = mv_offset.y;
    for_each_pixel(f.width, f.height, [&](glm::ivec2 q) { cpu.ingest_pixel(glm::uvec2(q), p); });
    return out;
}

void dilate(InternalFrame& f, const InternalFrame* prev, const IngestParams& p) {
    const bool edges = p.edge_ratio > 0.f && prev != nullptr;
    if (!(p.bright > 0.f) && !edges) return;
    const InternalFrame src = f;
    gpu::DilateCpu cpu{&src, &f, prev};
    // The edge rule first: the over-white rule's writes take precedence (as the GPU dispatches).
    if (edges) for_each_pixel(f.width, f.height, [&](glm::ivec2 q) { cpu.dilate_edge_pixel(glm::uvec2(q), p); });
    if (p.bright > 0.f) for_each_pixel(f.width, f.height, [&](glm::ivec2 q) { cpu.dilate_pixel(glm::uvec2(q), p); });
}

glm::uvec2 cut_grid(uint32_t width, uint32_t height) {
    return {(width + CUT_BLOCK - 1) / CUT_BLOCK, (height + CUT_BLOCK - 1) / CUT_BLOCK};
}

uint32_t cut_blocks(uint32_t width, uint32_t height) {
    const glm::uvec2 g = cut_grid(width, height);
    return g.x * g.y;
}

std::vector<CutBlock> cut_stage(const InternalFrame& f, const InternalFrame& prev) {
    std::vector<CutBlock> out(cut_blocks(f.width, f.height));
    gpu::CutCpu cpu{&f, &prev, &out};
    const glm::uvec2 g = cut_grid(f.width, f.height);
    for_each_pixel(g.x, g.y, [&](glm::ivec2 b) { cpu.cut_block(glm::uvec2(b), f.width, f.height); });
    return out;
}

LightingFit fit_lighting(std::span<const CutBlock> blocks) {
    // Least squares of the block means, in double: a frame has up to ~10^5 blocks.
    double n = 0, sp = 0, sc = 0, spp = 0, spc = 0;
    for (const CutBlock& b : blocks) {
        const double c = b.level.x, p = b.level.y;
        n += 1;
        sp += p;
        sc += c;
        spp += p * p;
        spc += p * c;
    }
    LightingFit fit;
    if (n == 0) return fit;
    const double var = spp - sp * sp / n;
    const double gain = var > 1e-9 * n ? (spc - sp * sc / n) / var : 1.0;
    fit.gain = std::clamp(float(gain), kCutLightGainMin, kCutLightGainMax);
    fit.offset = float((sc - double(fit.gain) * sp) / n);
    return fit;
}

float cut_share(std::span<const CutBlock> blocks) {
    if (blocks.empty()) return 0.f;
    const LightingFit fit = fit_lighting(blocks);
    size_t high = 0;
    for (const CutBlock& b : blocks)
        high += block_unmatched(b.sad.x, b.sad.y) && relit_unmatched(b, fit) ? 1 : 0;
    return float(high) / float(blocks.size());
}

std::vector<glm::vec4> generate_sr(const InternalFrame& f0, const InternalFrame& f1, const Splat& sp,
                                   const std::vector<glm::vec4>& src, const GenParams& g, const SrParams& s,
                                   std::span<const float> lut) {
    std::vector<glm::vec4> out(size_t(s.hr_width) * s.hr_height);
    gpu::GenerateSrCpu cpu{{{&f0, &f1}, &sp, g}, &src, lut, s.hr_width};
    for (uint32_t y = 0; y < s.hr_height; ++y)
        for (uint32_t x = 0; x < s.hr_width; ++x)
            out[size_t(y) * s.hr_width + x] = cpu.generate_sr_pixel(glm::ivec2(int(x), int(y)), g, s);
    return out;
}

std::vector<glm::vec4> super_resolve(const InternalFrame& cur, const std::vector<float>& prev_depth,
                                     const std::vector<glm::vec4>& history, const SrParams& p,
                                     std::span<const float> lut) {
    std::vector<glm::vec4> out(size_t(p.hr_width) * p.hr_height);
    gpu::SrCpu cpu{&cur, &prev_depth, &history, lut, p.lr_width, p.hr_width, {}};
    // The stage before the pass (variant sr_noise), where the host dispatches it.
    cpu.noise.assign(size_t(p.lr_width) * p.lr_height, glm::vec2(-1.f, 0.f));
    if (p.has_history != 0u && (p.flags & (SR_NOISE_KERNEL | SR_NOISE_AVERAGE)) != 0u)
        for (uint32_t y = 0; y < p.lr_height; ++y)
            for (uint32_t x = 0; x < p.lr_width; ++x)
                cpu.noise[size_t(y) * p.lr_width + x] =
                    cpu.noise_stats(glm::ivec2(int(x), int(y)), glm::vec2(p.jitter_x, p.jitter_y), p);
    for (uint32_t y = 0; y < p.hr_height; ++y)
        for (uint32_t x = 0; x < p.hr_width; ++x)
            out[size_t(y) * p.hr_width + x] = cpu.super_resolve(glm::ivec2(int(x), int(y)), p);
    return out;
}

NoiseEstimate noise_level(const InternalFrame& f, const DenoiseParams& p) {
    std::array<uint32_t, DENOISE_WORDS> noise{};
    gpu::DenoiseCpu cpu{&f, nullptr, &noise};
    for (uint32_t j = 0; j < (p.height + 1) / 2; ++j)
        for (uint32_t i = 0; i < (p.width + 1) / 2; ++i) cpu.denoise_histogram(glm::ivec2(int(i), int(j)), p);
    cpu.denoise_level(p);
    return NoiseEstimate{glm::uintBitsToFloat(noise[DENOISE_SIGMA]),
                         glm::uintBitsToFloat(noise[DENOISE_RANGE])};
}

std::vector<glm::vec4> denoise(const InternalFrame& f, const DenoiseParams& p, float range) {
    std::array<uint32_t, DENOISE_WORDS> noise{};
    noise[DENOISE_RANGE] = glm::floatBitsToUint(range);
    std::vector<glm::vec4> out(size_t(p.width) * p.height);
    gpu::DenoiseCpu cpu{&f, &out, &noise};
    for (uint32_t y = 0; y < p.height; ++y)
        for (uint32_t x = 0; x < p.width; ++x)
            cpu.store_color(y * p.width + x, cpu.denoise_pixel(glm::ivec2(int(x), int(y)), p));
    return out;
}

Splat splat(const InternalFrame& f0, const InternalFrame& f1, const GenParams& g) {
    const size_t n = size_t(g.width) * g.height;
    Splat out{std::vector<uint64_t>(n, std::numeric_limits<uint64_t>::max()), std::vector<glm::vec4>(n)};
    gpu::SplatCpu cpu{{&f0, &f1}, &out, g.alpha};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) { cpu.splat_pixel(q, g); });
    return out;
}

glm::vec4 source_field_vectors(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat,
                               uint32_t source, const GenParams& g) {
    gpu::KeysCpu cpu{{&f0, &f1}, &splat, g};
    return cpu.load_motion(source);
}

Field refine(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat, const GenParams& g) {
    const size_t n = size_t(g.width) * g.height;
    Field field{std::vector<glm::vec4>(n), std::vector<float>(n), std::vector<uint32_t>(n)};
    gpu::KeysCpu cpu{{&f0, &f1}, &splat, g};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) {
        auto f = cpu.refine_field(q, g);
        const size_t i = cpu.at(q);
        field.v[i] = f.v;
        field.depth[i] = f.depth;
        field.state[i] = f.state;
    });
    return field;
}

void disocc(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat, Field& field,
            const GenParams& g) {
    gpu::KeysCpu cpu{{&f0, &f1}, &splat, g};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) {
        const size_t i = cpu.at(q);
        if (field.state[i] != kFieldHole) return;
        auto f = cpu.fill_hole_covered(q, g);
        field.v[i] = f.v;
        field.depth[i] = f.depth;
        field.state[i] = f.state;
    });
}

Warped warp(const InternalFrame& f0, const InternalFrame& f1, const Field& field, const GenParams& g) {
    const size_t n = size_t(g.width) * g.height;
    Warped out{std::vector<glm::vec4>(2 * n), std::vector<float>(2 * n, -1.f)};
    gpu::WarpCpu cpu{{&f0, &f1}};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) {
        const size_t i = cpu.at(q);
        const glm::vec4 v = field.v[i];
        const glm::vec2 centre = glm::vec2(q) + 0.5f;
        auto w1 = cpu.warp_sample(1u, centre, glm::vec2(v.z, v.w), g);
        out.color[n + i] =
            g.extrapolate != 0u ? cpu.extrapolated_color(w1, v, field.state[i], centre, g) : w1.color;
        out.depth[n + i] = w1.depth;
        if (g.extrapolate == 0u) {
            auto w0 = cpu.warp_sample(0u, centre, glm::vec2(v.x, v.y), g);
            out.color[i] = w0.color;
            out.depth[i] = w0.depth;
        }
    });
    return out;
}

std::vector<glm::vec4> blend(const InternalFrame& f0, const InternalFrame& f1, const Warped& warped,
                             const Field& field, const GenParams& g) {
    const size_t n = size_t(g.width) * g.height;
    std::vector<glm::vec4> out(n);
    gpu::BlendCpu cpu{{&f0, &f1}};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) {
        const size_t i = cpu.at(q);
        const float d0 = warped.depth[i], d1 = warped.depth[n + i];
        const glm::vec2 v1(field.v[i].z, field.v[i].w);
        const glm::vec2 d = cpu.blend_depths(d0, d1, gpu::sample_pixel(glm::vec2(q) + 0.5f + v1, g), g);
        out[i] = cpu.select_blend(warped.color[i], d.x, warped.color[n + i], d.y, field.state[i], g);
    });
    return out;
}

// The agree pass's stages over every pixel: with AgreeParams::gain in interpolation, the brightness
// box sums (stages 5-7); the first (`first`: stage 1 or 4, e per pixel), the box's rows, then its
// columns and the mix (stages 2 and 3 per segment, as the GPU runs them); with
// AgreeParams::out_width set, the columns' means (stage 8), then the mix per output pixel (stage 9).
namespace {
template <class First>
std::vector<glm::vec4> agree_stages(gpu::AgreeCpu& cpu, const AgreeParams& p, First first) {
    const size_t n = size_t(p.g.width) * p.g.height;
    cpu.e_buf.resize(n);
    cpu.rows_buf.resize(n);
    auto each = [&](auto f) {
        for (uint32_t y = 0; y < p.g.height; ++y)
            for (uint32_t x = 0; x < p.g.width; ++x) f(glm::ivec2(int(x), int(y)), size_t(y) * p.g.width + x);
    };
    const uint32_t segments_x = (p.g.width + AGREE_SEGMENT - 1) / AGREE_SEGMENT;
    const uint32_t segments_y = (p.g.height + AGREE_SEGMENT - 1) / AGREE_SEGMENT;
    if (p.gain > 1.f && p.g.extrapolate == 0u) {
        cpu.light_buf.resize(n);
        cpu.light_rows_buf.resize(n);
        each([&](glm::ivec2 t, size_t i) { cpu.light_buf[i] = cpu.agree_light(t, p); });
        for (uint32_t y = 0; y < p.g.height; ++y)
            for (uint32_t sx = 0; sx < segments_x; ++sx) cpu.agree_light_segment(glm::uvec2(sx, y), false, p);
        for (uint32_t sy = 0; sy < segments_y; ++sy)
            for (uint32_t x = 0; x < p.g.width; ++x) cpu.agree_light_segment(glm::uvec2(x, sy), true, p);
    }
    each([&](glm::ivec2 t, size_t i) { cpu.e_buf[i] = first(t); });
    for (uint32_t y = 0; y < p.g.height; ++y)
        for (uint32_t sx = 0; sx < segments_x; ++sx) cpu.agree_rows_segment(glm::uvec2(sx, y), p);
    const bool upscaled = p.out_width != 0u;
    std::vector<glm::vec4> out(upscaled ? size_t(p.out_width) * p.out_height : n);
    cpu.agreed = &out;
    for (uint32_t sy = 0; sy < segments_y; ++sy)
        for (uint32_t x = 0; x < p.g.width; ++x) cpu.agree_column_segment(glm::uvec2(x, sy), upscaled, p);
    if (upscaled)
        for (uint32_t y = 0; y < p.out_height; ++y)
            for (uint32_t x = 0; x < p.out_width; ++x) cpu.agree_mix_upscaled(glm::ivec2(int(x), int(y)), p);
    return out;
}
} // namespace

std::vector<glm::vec4> agree(const Warped& given_warped, const Field& given_field,
                             const std::vector<glm::vec4>& given, const Warped& colour_warped,
                             const std::vector<uint32_t>& colour_state, const std::vector<glm::vec4>& colour,
                             const AgreeParams& p) {
    const size_t n = size_t(p.g.width) * p.g.height;
    gpu::AgreeCpu cpu{
        {&given_warped, &colour_warped}, {&given_field.state, &colour_state}, {&given, &colour}, {}, {}, n};
    cpu.given_field = &given_field.v;
    return agree_stages(cpu, p, [&](glm::ivec2 t) { return cpu.agree_error(t, p); });
}

std::vector<glm::vec4> agree_extrapolated(const InternalFrame& f0, const InternalFrame& f1,
                                          const std::vector<glm::vec2>& colour_mv,
                                          const std::vector<glm::vec4>& given,
                                          const std::vector<glm::vec4>& colour, const AgreeParams& p) {
    const size_t n = size_t(p.g.width) * p.g.height;
    gpu::AgreeCpu cpu{{nullptr, nullptr}, {nullptr, nullptr}, {&given, &colour}, {}, {}, n};
    cpu.inputs[0] = &f0;
    cpu.inputs[1] = &f1;
    cpu.field_mv[0] = &f1.mv;
    cpu.field_mv[1] = &colour_mv;
    cpu.width = p.g.width;
    return agree_stages(cpu, p, [&](glm::ivec2 t) { return cpu.agree_residual(t, p); });
}

std::vector<glm::vec4> generate_fused(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat,
                                      const GenParams& g) {
    std::vector<glm::vec4> out(size_t(g.width) * g.height);
    gpu::GenerateCpu cpu{{{&f0, &f1}, &splat, g}, &out};
    for_each_pixel(g.width, g.height, [&](glm::ivec2 q) { cpu.generate_pixel(q, g); });
    return out;
}

std::vector<glm::vec4> generate(const InternalFrame& f0, const InternalFrame& f1, const GenParams& g) {
    const Splat sp = splat(f0, f1, g);
    Field field = refine(f0, f1, sp, g);
    if (g.fill_holes != 0u) disocc(f0, f1, sp, field, g);
    Warped warped = warp(f0, f1, field, g);
    if (g.extrapolate != 0u) {
        const size_t n = size_t(g.width) * g.height;
        return std::vector<glm::vec4>(warped.color.begin() + long(n), warped.color.end());
    }
    return blend(f0, f1, warped, field, g);
}

std::vector<uint32_t> classify(const InternalFrame& f0, const InternalFrame& f1, const ClassifyParams& c) {
    const uint32_t tx = (c.g.width + c.tile - 1) / c.tile, ty = (c.g.height + c.tile - 1) / c.tile;
    std::vector<uint32_t> flags(size_t(tx) * ty);
    gpu::ClassifyCpu cpu{{&f0, &f1}};
    for (uint32_t y = 0; y < ty; ++y)
        for (uint32_t x = 0; x < tx; ++x)
            flags[size_t(y) * tx + x] =
                cpu.classify_tile(glm::ivec2(int(x), int(y)), c) ? TILE_STATIC : TILE_MOVING;
    return flags;
}

glm::vec4 copy_through(const InternalFrame& f0, const InternalFrame& f1, glm::ivec2 p, const GenParams& g) {
    gpu::ClassifyCpu cpu{{&f0, &f1}};
    return cpu.copy_through(p, g);
}

std::vector<glm::vec4> resample_image(const std::vector<glm::vec4>& src, uint32_t w, uint32_t h,
                                      glm::vec2 shift, Resample kind, std::span<const float> lut) {
    std::vector<glm::vec4> out(size_t(w) * h);
    if (kind == Resample::lut && lut.size() < kLutSize) return out;
    gpu::ResampleCpu cpu{&src, w, lut};
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            out[size_t(y) * w + x] = cpu.resample(glm::vec2(float(x) + 0.5f, float(y) + 0.5f) + shift,
                                                  glm::ivec2(int(w), int(h)), uint32_t(kind));
    return out;
}

glm::vec4 resample_at(const std::vector<glm::vec4>& src, uint32_t w, uint32_t h, glm::vec2 pos, Resample kind,
                      std::span<const float> lut) {
    if (kind == Resample::lut && lut.size() < kLutSize) return glm::vec4(0.f);
    gpu::ResampleCpu cpu{&src, w, lut};
    return cpu.resample(pos, glm::ivec2(int(w), int(h)), uint32_t(kind));
}

} // namespace fgsr::ref
