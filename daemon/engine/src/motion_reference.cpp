// CPU reference of motion estimation from colour: shaders/luma.h, match.h and flow.h compiled as
// C++ members of structs whose load_/store_ functions read and write host vectors.
#include <fgsr/engine/reference.hpp>

#include <algorithm>
#include <array>
#include <cstring>

// clang-format off
namespace fgsr::gpu {
namespace {

struct LumaCpu {
    const ref::InternalFrame* f;
    std::vector<float>* pyr;
    const std::vector<float>* prev = nullptr; // the gain: the previous frame's pyramid
    std::array<uint, LUMA_GAIN_BINS> bins{};    // ... and its histogram
    vec4 load_color(uint i) const { return f->color[i]; }
    float load_level(uint i) const { return (*pyr)[i]; }
    void store_level(uint i, float v) { (*pyr)[i] = v; }
    float load_prev_level(uint i) const { return (*prev)[i]; }
    void add_to_bin(uint b) { ++bins[b]; }
    uint load_bin(uint b) const { return bins[b]; }
#include "luma.h"
};

struct MatchCpu {
    const std::vector<float>* src;
    const std::vector<float>* dst;
    std::vector<vec4>* field;
    float load_src(uint i) const { return (*src)[i]; }
    float load_dst(uint i) const { return (*dst)[i]; }
    vec4 load_field(uint i) const { return (*field)[i]; }
    void store_field(uint i, vec4 v) { (*field)[i] = v; }
#include "match.h"
};

// The cut statistics of the finest level's blocks under their matched vectors (match.comp's
// FGSR_MATCH_CUT build).
struct CutMatchCpu {
    const std::vector<float>* src;
    const std::vector<float>* dst;
    std::vector<vec4>* field;
    MatchParams p;
    float load_cut_luma(uint i) const { return (*src)[p.src_offset + i]; }
    float load_cut_prev_luma(uint i) const { return (*dst)[p.dst_offset + i]; }
    vec2 load_cut_mv(uint i) const {
        const uint x = i % p.width, y = i / p.width;
        return vec2((*field)[p.field_offset + (y / MOTION_BLOCK) * p.blocks_x + x / MOTION_BLOCK]);
    }
    void store_cut_block(uint b, vec4 sad, vec4 level) {
        (*field)[p.same_offset + 2u * b] = sad;
        (*field)[p.same_offset + 2u * b + 1u] = level;
    }
#define CUT_SEARCH CUT_MATCH_SEARCH
#include "cut.h"
#undef CUT_SEARCH
};

struct FlowCpu {
    const std::vector<float>* cur_luma;
    const std::vector<float>* prev_luma;
    const std::vector<vec4>* blocks;
    ref::InternalFrame* out;
    const ref::InternalFrame* prev_frame; // read only when correcting
    const std::vector<vec2>* coarse;       // read only where p.coarse_level > 0
    float load_cur(uint i) const { return (*cur_luma)[i]; }
    float load_prev(uint i) const { return (*prev_luma)[i]; }
    vec4 load_field(uint i) const { return (*blocks)[i]; }
    vec2 load_given(uint i) const { return out->mv[i]; }
    float load_depth(uint i) const { return out->depth[i]; }
    float load_prev_depth(uint i) const { return prev_frame->depth[i]; }
    vec2 load_field_vector(uint i) const { return (*coarse)[i]; }
    void store_flow(uint i, vec2 m, float d, bool write_depth) {
        out->mv[i] = m;
        if (write_depth) out->depth[i] = d;
    }
#include "flow.h"
};

struct PolishCpu {
    const std::vector<float>* cur_luma;
    const std::vector<float>* prev_luma;
    std::vector<vec2>* mv;           // the frame's vectors or the coarse fields
    const std::vector<vec4>* blocks; // read by polish_seed_pixel from the blocks only
    std::vector<vec4>* patches = nullptr; // search.h's patch vectors
    uint luma_offset = 0;            // the level's in the pyramids (PolishParams::luma_offset)
    float load_cur(uint i) const { return (*cur_luma)[luma_offset + i]; }
    float load_prev(uint i) const { return (*prev_luma)[luma_offset + i]; }
    vec2 load_mv(uint i) const { return (*mv)[i]; }
    vec2 load_field_vector(uint i) const { return (*mv)[i]; }
    void store_mv(uint i, vec2 v) { (*mv)[i] = v; }
    vec4 load_field(uint i) const { return (*blocks)[i]; }
    vec4 load_patch(uint i) const { return (*patches)[i]; }
    void store_patch(uint i, vec4 v) { (*patches)[i] = v; }
#include "polish.h"
#include "search.h"
};

} // namespace
} // namespace fgsr::gpu
// clang-format on

namespace fgsr::ref {

std::vector<float> luma_pyramid(const InternalFrame& f, const std::vector<MotionLevel>& levels) {
    const MotionLevel& last = levels.back();
    std::vector<float> pyr(size_t(last.offset) + size_t(last.width) * last.height);
    gpu::LumaCpu cpu{&f, &pyr};
    for (size_t k = 0; k < levels.size(); ++k) {
        const MotionLevel& l = levels[k];
        const MotionLevel& src = levels[k == 0 ? 0 : k - 1];
        const LumaParams p{src.width, src.height, l.width, l.height, src.offset, l.offset, uint32_t(k), 0u};
        for (uint32_t y = 0; y < l.height; ++y)
            for (uint32_t x = 0; x < l.width; ++x) cpu.luma_pixel(glm::uvec2(x, y), p);
    }
    return pyr;
}

float luma_gain_of(const std::vector<float>& cur, const std::vector<float>& prev,
                   const std::vector<MotionLevel>& levels) {
    const MotionLevel& top = levels.back();
    const LumaParams p{top.width * top.height, 0u, 0u, 0u, top.offset, 0u, 0u, 0u};
    gpu::LumaCpu cpu{nullptr, const_cast<std::vector<float>*>(&cur), &prev};
    for (uint32_t l = 0; l < LUMA_GAIN_LANES; ++l) cpu.luma_gain_lane(l, p);
    return cpu.luma_gain(p.src_width);
}

void match_level(const std::vector<float>& src, const std::vector<float>& dst, std::vector<glm::vec4>& field,
                 const MatchParams& p) {
    gpu::MatchCpu cpu{&src, &dst, &field};
    for (uint32_t y = 0; y < p.blocks_y; ++y)
        for (uint32_t x = 0; x < p.blocks_x; ++x) cpu.match_block(glm::uvec2(x, y), p);
}

void consensus_level(const std::vector<float>& src, const std::vector<float>& dst,
                     std::vector<glm::vec4>& field, const MatchParams& p) {
    gpu::MatchCpu cpu{&src, &dst, &field};
    for (uint32_t y = 0; y < p.blocks_y; ++y)
        for (uint32_t x = 0; x < p.blocks_x; ++x) cpu.ambiguity_block(glm::uvec2(x, y), p);
    for (uint32_t y = 0; y < p.blocks_y; ++y)
        for (uint32_t x = 0; x < p.blocks_x; ++x) cpu.consensus_block(glm::uvec2(x, y), p);
}

void fill_level(std::vector<glm::vec4>& field, const MatchParams& p) {
    gpu::MatchCpu cpu{nullptr, nullptr, &field};
    for (uint32_t y = 0; y < p.blocks_y; ++y)
        for (uint32_t x = 0; x < p.blocks_x; ++x) cpu.fill_block(glm::uvec2(x, y), p);
}

void flow(const std::vector<float>& cur, const std::vector<float>& prev, const std::vector<glm::vec4>& field,
          const FlowParams& p, InternalFrame& f, const InternalFrame* prev_frame,
          const std::vector<glm::vec2>* coarse) {
    gpu::FlowCpu cpu{&cur, &prev, &field, &f, prev_frame, coarse};
    for (uint32_t y = 0; y < p.height; ++y)
        for (uint32_t x = 0; x < p.width; ++x) cpu.flow_pixel(glm::uvec2(x, y), p);
}

namespace {
void polish_sweeps(gpu::PolishCpu& cpu, PolishParams p, uint32_t iterations) {
    cpu.luma_offset = p.luma_offset;
    for (uint32_t k = 0; k < 2 * iterations; ++k) {
        p.parity = k & 1u;
        for (uint32_t y = 0; y < p.height; ++y)
            for (uint32_t x = 0; x < (p.width + 1) / 2; ++x) cpu.polish_pixel(glm::uvec2(x, y), p);
    }
}
} // namespace

void polish(const std::vector<float>& cur, const std::vector<float>& prev, InternalFrame& f) {
    gpu::PolishCpu cpu{&cur, &prev, &f.mv, nullptr};
    polish_sweeps(cpu, polish_params(f.width, f.height, 0), kPolishIterations);
}

std::vector<glm::vec2> polish_coarse(const std::vector<float>& cur, const std::vector<float>& prev,
                                     const std::vector<glm::vec4>& field,
                                     const std::vector<MotionLevel>& levels, bool search, bool sweep) {
    std::vector<glm::vec2> coarse(polish_coarse_vectors(levels));
    std::vector<glm::vec4> patches(search ? search_patch_capacity(levels) : 0);
    gpu::PolishCpu cpu{&cur, &prev, &coarse, &field, &patches};
    for (uint32_t level = polish_coarse_top(levels); level >= 1; --level) {
        const PolishParams seed = polish_coarse_params(levels, level, 0, true);
        for (uint32_t y = 0; y < seed.height; ++y)
            for (uint32_t x = 0; x < seed.width; ++x) cpu.polish_seed_pixel(glm::uvec2(x, y), seed);
        if (search && searches_level(levels, level)) {
            for (uint32_t r = 0; r <= kSearchRounds; ++r) {
                const PolishParams sp = search_params(levels, level, r);
                cpu.luma_offset = sp.luma_offset;
                for (uint32_t y = 0; y < sp.patches_y; ++y)
                    for (uint32_t x = 0; x < sp.patches_x; ++x) cpu.search_patch(glm::uvec2(x, y), sp);
            }
            const PolishParams dp = search_params(levels, level, kSearchRounds);
            for (uint32_t y = 0; y < dp.height; ++y)
                for (uint32_t x = 0; x < dp.width; ++x) cpu.search_densify_pixel(glm::uvec2(x, y), dp);
        }
        if (sweep) polish_sweeps(cpu, polish_coarse_params(levels, level, 0, false), kPolishCoarseIterations);
    }
    return coarse;
}

void match_pyramids(const std::vector<float>& cur, const std::vector<float>& prev,
                    const std::vector<MotionLevel>& levels, std::vector<glm::vec4>& field, bool consensus,
                    bool light) {
    const size_t half = motion_field_blocks(levels);
    const bool temporal = field.size() == half * kFieldRegions;
    field.resize(half * kFieldRegions);
    if (temporal)
        std::copy(field.begin(), field.begin() + std::ptrdiff_t(half),
                  field.begin() + std::ptrdiff_t(4 * half));
    const size_t finest = motion_first_level(levels);
    for (size_t k = levels.size(); k-- > finest;) {
        match_level(cur, prev, field, match_params(levels, k, false, false, temporal, light));
        match_level(prev, cur, field, match_params(levels, k, true, false, temporal, light));
        const MatchParams propagation = match_params(levels, k, false, true, temporal, light);
        match_level(cur, prev, field, propagation);
        if (consensus && k != finest) consensus_level(cur, prev, field, propagation);
    }
}

MotionSummary estimate_motion(const InternalFrame& f0, InternalFrame& f1, bool write_depth,
                              std::vector<glm::vec4>& field, VectorCorrection correct, bool fast,
                              float typical_share, bool consensus, bool light, bool search) {
    const std::vector<MotionLevel> levels = motion_levels(f1.width, f1.height);
    const std::vector<float> p1 = luma_pyramid(f1, levels);
    std::vector<float> p0 = luma_pyramid(f0, levels);
    const float gain = luma_gain_of(p1, p0, levels);
    if (gain != 1.f)
        for (float& v : p0) v *= gain;
    match_pyramids(p1, p0, levels, field, consensus && !correct.on, light);
    MotionSummary s = summarise_motion(levels, field.data(), typical_share);
    if (s.cut) { // a cut as matched: relit, as the engine does (ref::summarise_motion)
        gpu::CutMatchCpu cut{&p1, &p0, &field, cut_match_params(levels)};
        for (uint32_t y = 0; y < cut.p.blocks_y; ++y)
            for (uint32_t x = 0; x < cut.p.blocks_x; ++x)
                cut.cut_block(glm::uvec2(x, y), cut.p.width, cut.p.height);
        s = summarise_motion(levels, field.data(), typical_share, true);
    }
    if (s.cut) {
        field.clear();
        return s;
    }
    fill_level(field, fill_params(levels, false));
    fill_level(field, fill_params(levels, true));
    const bool polishing = !correct.on && !fast && polishes(f1.width, f1.height);
    const bool refines_coarse = polishing || (!correct.on && !fast && search);
    const std::vector<glm::vec2> coarse =
        refines_coarse ? polish_coarse(p1, p0, field, levels, search, polishing) : std::vector<glm::vec2>();
    flow(p1, p0, field, flow_params(levels, s.global, write_depth, correct, refines_coarse), f1, &f0,
         &coarse);
    if (polishing) polish(p1, p0, f1);
    f1.has_mv = true;
    return s;
}

} // namespace fgsr::ref
