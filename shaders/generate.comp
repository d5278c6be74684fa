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
layout(std430, binding = GEN_KEYS) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = GEN_MOTION) readonly buffer Motion { u64vec2 motion[]; }; // (m1, m0) per source (vec4)
layout(std430, binding = GENERATE_COLOR0) readonly buffer Color0 { uint64_t color0[]; }; // pack_color (uvec2, load64.h)
layout(std430, binding = GENERATE_COLOR1) readonly buffer Color1 { uint64_t color1[]; }; // pack_color (uvec2)
layout(std430, binding = GENERATE_OUTPUT) writeonly buffer Output { u64vec2 outp[]; }; // vec4
#include "load64.h"

// The CPU builds for extrapolation fix the mode (common.h, fixed_mode): an extrapolated frame
// no longer pays for interpolation's frame-0 warp and blend (docs/PERFORMANCE.md, "builds per mode").
GenParams gen_params() { return fixed_mode(pc.g); }

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.g.width) + q.x]; }
vec2 load_mv0(ivec2 q) { return mv0[q.y * int(pc.g.width) + q.x]; }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
vec4 load_source_motion(uint i) { return as_vec4(motion[i]); }
#include "motion.h"
#ifdef FGSR_TILED
// Over the tiles classify and splat listed (moving or dirty); classify wrote the others.
layout(std430, binding = GENERATE_COUNT + TILED_LIST) readonly buffer TileList { uint tile_list[]; };
layout(std430, binding = GENERATE_COUNT + TILED_FLAGS) readonly buffer Flags { uint tile_flags[]; };
#define FGSR_TILED_KEYS
#include "tiles.h"
#else
uint64_t load_key(ivec2 q) { return keys[q.y * int(pc.g.width) + q.x]; }
vec4 load_motion(uint src) { return source_field_vectors(src, gen_params()); }
#endif
vec4 load_color0(ivec2 q) { return unpack_color(as_uvec2(color0[q.y * int(pc.g.width) + q.x])); }
vec4 load_color1(ivec2 q) { return unpack_color(as_uvec2(color1[q.y * int(pc.g.width) + q.x])); }
void store_output(uint i, vec4 c) { outp[i] = as_u64vec2(c); }

#include "field.h"
#include "refine.h"
#include "disocc.h"
#include "warp.h"
#include "blend_depth.h"
#include "blend.h"
#include "generate.h"

#if defined(FGSR_GENERATE_SPLIT)
// The split form (generate.h, generate_splatted) for CPU devices: stage 1 finishes the splatted
// pixels and appends the empty ones (x | y << 16) to a pixel list at GENERATE_COUNT + TILED_APPEND
// (a tile list's header, tiles.h: one invocation per entry); stage 2 runs over that list, bound
// at GENERATE_COUNT + TILED_LIST (an indirect dispatch), with generate_pixel. Plain: stage 1 runs
// over every pixel. Tiled (FGSR_TILED): stage 1 runs over the listed tiles (the tile list at
// TILED_LIST); in stage 2 the pixel list takes TILED_LIST's place, its header's [4] holding the
// tile side that the tiled key reads (tiles.h) take from it.
#if FGSR_GENERATE_SPLIT == 1
layout(std430, binding = GENERATE_COUNT + TILED_APPEND) buffer PixelList { uint pixel_list[]; };
#elif !defined(FGSR_TILED)
layout(std430, binding = GENERATE_COUNT + TILED_LIST) readonly buffer PixelList { uint tile_list[]; };
#endif
#ifndef FGSR_TILED
#include "tiles.h"
#endif
void main() {
#if FGSR_GENERATE_SPLIT == 1
#ifdef FGSR_TILED
    ivec2 t;
    if (!listed_pixel(t)) return;
#else
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
#endif
    if (!generate_splatted(t, gen_params())) TILE_APPEND(pixel_list, uint(t.x) | (uint(t.y) << 16), 1u);
#else
    uint slot = gl_WorkGroupID.x * uint(FGSR_GROUP * FGSR_GROUP) + gl_LocalInvocationIndex;
    if (slot >= tile_list[3]) return;
    uint packed = tile_list[TILE_LIST_HEADER + slot];
    generate_pixel(ivec2(int(packed & 0xffffu), int(packed >> 16)), gen_params());
#endif
}
#elif defined(FGSR_TILED)
void main() {
    ivec2 p;
    if (listed_pixel(p)) generate_pixel(p, gen_params());
}
#else
void main() { generate_pixel(ivec2(gl_GlobalInvocationID.xy), gen_params()); }
#endif
