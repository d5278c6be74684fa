#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push {
    GenParams g;
    uint count;
    uint stride;
    float alpha0;
    float alpha1;
    float alpha2;
    float alpha3;
} pc; // SplatParams
// Vectors and the motion field as 64-bit words (shaders/load64.h): one access per vec2 and two
// per vec4 instead of two and four on CPU devices; the same bits.
layout(std430, binding = GEN_MV1) readonly buffer Mv1 { uint64_t mv1[]; };                 // vec2
layout(std430, binding = GEN_MV0) readonly buffer Mv0 { uint64_t mv0[]; };                 // vec2
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = GEN_KEYS) buffer Keys { uint64_t keys[]; };
layout(std430, binding = GEN_MOTION) buffer Motion { u64vec2 motion[]; }; // (m1, m0) per source (vec4)
#include "load64.h"

vec2 load_mv1(ivec2 q) { return as_vec2(mv1[q.y * int(pc.g.width) + q.x]); }
vec2 load_mv0(ivec2 q) { return as_vec2(mv0[q.y * int(pc.g.width) + q.x]); }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
vec4 load_source_motion(uint i) { return as_vec4(motion[i]); } // motion.h's source_field_vectors (not called here)
#ifdef FGSR_TILED
// Splat over the moving tiles only (classify.h); marks the static tiles it lands in dirty.
layout(std430, binding = SPLAT_COUNT + TILED_LIST) readonly buffer TileList { uint tile_list[]; };
layout(std430, binding = SPLAT_COUNT + TILED_FLAGS) buffer Flags { uint tile_flags[]; };
layout(std430, binding = SPLAT_COUNT + TILED_APPEND) buffer ListGenerate { uint list_generate[]; };
#include "tiles.h"

void mark_dirty(uint i) {
    uint side = tile_list[4];
    uint y = udiv(i, pc.g.width);
    uint t = tile_index(ivec2(int(i - y * pc.g.width), int(y)), pc.g.width, side);
    if (tile_flags[t] != TILE_STATIC ||
        atomicCompSwap(tile_flags[t], TILE_STATIC, TILE_STATIC | TILE_DIRTY) != TILE_STATIC)
        return;
    uint tiles_x = (pc.g.width + side - 1u) >> tile_shift(side);
    uint ty = udiv(t, tiles_x);
    uint span = list_generate[5];
    TILE_APPEND(list_generate, (t - ty * tiles_x) | (ty << 16), span * span);
}
#endif

// FGSR_SPLAT_COUNT: the count as a literal (one build per count; a loop bounded by the push
// constant cost the single-alpha splat ~25 % on lavapipe).
#ifdef FGSR_SPLAT_COUNT
uint splat_count() { return FGSR_SPLAT_COUNT; }
#else
uint splat_count() { return pc.count; }
#endif
float splat_alpha(uint k) { return k == 0u ? pc.alpha0 : k == 1u ? pc.alpha1 : k == 2u ? pc.alpha2 : pc.alpha3; }
void splat_min(uint slice, uint i, uint64_t key) {
    atomicMin(keys[slice * pc.stride + i], key);
#ifdef FGSR_TILED
    mark_dirty(i); // tiled splats are single-alpha (slice 0)
#endif
}
void store_source_motion(uint i, vec4 m) { motion[i] = as_u64vec2(m); }

#include "field.h"
#include "motion.h"
#include "splat.h"

#ifdef FGSR_TILED
void main() {
    ivec2 p;
    if (listed_pixel(p)) splat_pixel(p, pc.g);
}
#else
void main() { splat_pixel(ivec2(gl_GlobalInvocationID.xy), pc.g); }
#endif
