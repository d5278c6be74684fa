#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push {
    GenParams g;
    SrParams s;
} pc;
// Vectors, colours, the motion field, the history, the LUT and the output as 64-bit words
// (shaders/load64.h): half the accesses on CPU devices, the same bits.
layout(std430, binding = GEN_MV1) readonly buffer Mv1 { uint64_t mv1[]; }; // vec2
layout(std430, binding = GEN_MV0) readonly buffer Mv0 { uint64_t mv0[]; }; // vec2
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = GEN_KEYS) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = GEN_MOTION) readonly buffer Motion { u64vec2 motion[]; }; // (m1, m0) per source (vec4)
layout(std430, binding = GENSR_COLOR0) readonly buffer Color0 { uint64_t color0[]; }; // pack_color (uvec2)
layout(std430, binding = GENSR_COLOR1) readonly buffer Color1 { uint64_t color1[]; };
layout(std430, binding = GENSR_SRC) readonly buffer Src { u64vec2 src[]; };              // vec4
layout(std430, binding = GENSR_LUT) readonly buffer Lut { u64vec2 lut[]; };              // vec4
layout(std430, binding = GENSR_OUTPUT) writeonly buffer Output { u64vec2 outp[]; };      // vec4
#include "load64.h"

// The CPU builds of the field form (FGSR_SR_FIELD) fix the mode (common.h, fixed_mode): ISR no
// longer runs ESR's history resampling and clip, nor ESR ISR's.
GenParams gen_params() { return fixed_mode(pc.g); }

vec2 load_mv1(ivec2 q) { return as_vec2(mv1[q.y * int(pc.g.width) + q.x]); }
vec2 load_mv0(ivec2 q) { return as_vec2(mv0[q.y * int(pc.g.width) + q.x]); }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
vec4 load_source_motion(uint i) { return as_vec4(motion[i]); }
#include "motion.h"
#ifdef FGSR_TILED
layout(std430, binding = GENSR_COUNT + TILED_LIST) readonly buffer TileList { uint tile_list[]; };
layout(std430, binding = GENSR_COUNT + TILED_FLAGS) readonly buffer Flags { uint tile_flags[]; };
#ifndef FGSR_STATIC_TILES
#define FGSR_TILED_KEYS
#endif
#include "tiles.h"
#endif

#ifdef FGSR_SR_FIELD
// The CPU form (FGSR_SR_FIELD, TILED layout): the field of every input pixel, written by the
// separate refine and disocc passes at input resolution, at GENSR_COUNT + TILED_LIST (vectors,
// vec4) and TILED_FLAGS (state; TILED_APPEND unused), in place of refine_field and fill_hole per output
// pixel (CPU devices run their neighbourhood reads for every pixel, and each input pixel is read
// by scale^2 output pixels).
layout(std430, binding = GENSR_COUNT + TILED_LIST) readonly buffer Field { u64vec2 field[]; }; // vec4
layout(std430, binding = GENSR_COUNT + TILED_FLAGS) readonly buffer FieldState { uint field_state[]; };
#endif

#ifdef FGSR_STATIC_TILES
// Static tiles that splat left alone (classify.h): every pixel holds its own key and zero vectors;
// the host sets bilinear resampling, exact at phase 0.
uint64_t load_key(ivec2 q) {
    return (uint64_t(floatBitsToUint(load_depth1(q))) << 32) | uint64_t(uint(q.y) * pc.g.width + uint(q.x));
}
vec4 load_motion(uint i) { return vec4(0.0f); }
#elif !defined(FGSR_TILED)
uint64_t load_key(ivec2 q) { return keys[q.y * int(pc.g.width) + q.x]; }
vec4 load_motion(uint i) { return source_field_vectors(i, pc.g); }
#endif
vec4 load_color0(ivec2 q) { return unpack_color(as_uvec2(color0[q.y * int(pc.g.width) + q.x])); }
vec4 load_color1(ivec2 q) { return unpack_color(as_uvec2(color1[q.y * int(pc.g.width) + q.x])); }
vec4 load_src(ivec2 q) { return as_vec4(src[q.y * int(pc.s.hr_width) + q.x]); }
vec4 load_lut4(uint row) { return as_vec4(lut[row]); }

#include "field.h"
#include "refine.h"
#include "disocc.h"
#include "warp.h"
#include "blend_depth.h"
#include "blend.h"
#include "resample.h"
#include "generate_sr.h"

void main() {
#ifdef FGSR_TILED
    ivec2 q;
    if (!listed_output_pixel(pc.s.scale, ivec2(int(pc.g.width), int(pc.g.height)),
                             ivec2(int(pc.s.hr_width), int(pc.s.hr_height)), q))
        return;
#ifdef FGSR_STATIC_TILES
    ivec2 t = clamp(ivec2(floor((vec2(q) + vec2(0.5f)) / pc.s.scale)), ivec2(0),
                    ivec2(int(pc.g.width) - 1, int(pc.g.height) - 1));
    if ((tile_flags[tile_index(t, pc.g.width, tile_list[4])] & TILE_DIRTY) != 0u) return; // generate list
#endif
#else
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= int(pc.s.hr_width) || q.y >= int(pc.s.hr_height)) return;
#endif
#ifdef FGSR_SR_FIELD
    ivec2 t = generate_sr_field_pixel(q, pc.g, pc.s);
    uint i = uint(t.y) * pc.g.width + uint(t.x);
    outp[q.y * int(pc.s.hr_width) + q.x] =
        as_u64vec2(generate_sr_finish(q, as_vec4(field[i]), field_state[i], gen_params(), pc.s));
#else
    outp[q.y * int(pc.s.hr_width) + q.x] = as_u64vec2(generate_sr_pixel(q, pc.g, pc.s));
#endif
}
