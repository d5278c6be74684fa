#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { GenParams g; } pc;
layout(std430, binding = GEN_MV1) readonly buffer Mv1 { vec2 mv1[]; };
layout(std430, binding = GEN_MV0) readonly buffer Mv0 { vec2 mv0[]; };
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = GEN_KEYS) buffer Keys { uint64_t keys[]; };
layout(std430, binding = GEN_MOTION) writeonly buffer Motion { vec4 motion[]; };

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.g.width) + q.x]; }
vec2 load_mv0(ivec2 q) { return mv0[q.y * int(pc.g.width) + q.x]; }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
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

void splat_min(uint i, uint64_t key) {
    atomicMin(keys[i], key);
#ifdef FGSR_TILED
    mark_dirty(i);
#endif
}
void store_motion(uint i, vec4 m) { motion[i] = m; }

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
