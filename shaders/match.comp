#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { MatchParams p; } pc;
// The pyramids as uniform texel buffers: a texel fetch is a vector gather on llvmpipe, a storage
// buffer load at a per-invocation index a loop over the lanes (bindings.h, MATCH_TEXELS).
layout(binding = MATCH_SRC) uniform samplerBuffer src;
layout(binding = MATCH_DST) uniform samplerBuffer dst;
layout(std430, binding = MATCH_FIELD) buffer Field { vec4 field[]; };

float load_src(uint i) { return texelFetch(src, int(i)).x; }
float load_dst(uint i) { return texelFetch(dst, int(i)).x; }
vec4 load_field(uint i) { return field[i]; }
void store_field(uint i, vec4 v) { field[i] = v; }

#ifdef FGSR_MATCH_CUT
// The cut statistics of the finest level's blocks (shaders/cut.h), each under its matched vector:
// p is ref::cut_match_params (field_offset: the level's current -> previous blocks; same_offset:
// where the CutBlocks go, two vec4 each).
float load_cut_luma(uint i) { return load_src(pc.p.src_offset + i); }
float load_cut_prev_luma(uint i) { return load_dst(pc.p.dst_offset + i); }
vec2 load_cut_mv(uint i) {
    uint x = i % pc.p.width, y = i / pc.p.width;
    return field[pc.p.field_offset + (y / MOTION_BLOCK) * pc.p.blocks_x + x / MOTION_BLOCK].xy;
}
void store_cut_block(uint b, vec4 sad, vec4 level) {
    field[pc.p.same_offset + 2u * b] = sad;
    field[pc.p.same_offset + 2u * b + 1u] = level;
}
#define CUT_SEARCH CUT_MATCH_SEARCH
#include "cut.h"
void main() { cut_block(gl_GlobalInvocationID.xy, pc.p.width, pc.p.height); }
#else
#include "match.h"

#if defined(FGSR_MATCH_FILL)
void main() { fill_block(gl_GlobalInvocationID.xy, pc.p); }
#elif defined(FGSR_MATCH_CONSENSUS) && FGSR_MATCH_CONSENSUS == 1
void main() { ambiguity_block(gl_GlobalInvocationID.xy, pc.p); }
#elif defined(FGSR_MATCH_CONSENSUS)
void main() { consensus_block(gl_GlobalInvocationID.xy, pc.p); }
#else
void main() { match_block(gl_GlobalInvocationID.xy, pc.p); }
#endif
#endif
