#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { PolishParams p; } pc;
layout(binding = POLISH_CUR) uniform samplerBuffer cur; // texel buffers, as in flow.comp
layout(binding = POLISH_PREV) uniform samplerBuffer prev;
layout(std430, binding = POLISH_MV) writeonly buffer Mv { vec2 mv[]; };
layout(binding = POLISH_MV_TEXELS) uniform samplerBuffer mv_texels; // RG32F view of the same buffer
layout(binding = POLISH_FIELD) uniform samplerBuffer field;         // RGBA32F texels
layout(std430, binding = POLISH_PATCHES) buffer Patches { vec4 patches[]; };

float load_cur(uint i) { return texelFetch(cur, int(pc.p.luma_offset + i)).x; }
float load_prev(uint i) { return texelFetch(prev, int(pc.p.luma_offset + i)).x; }
vec2 load_mv(uint i) { return texelFetch(mv_texels, int(i)).xy; }
vec2 load_field_vector(uint i) { return load_mv(i); }
void store_mv(uint i, vec2 v) { mv[i] = v; }
vec4 load_field(uint i) { return texelFetch(field, int(i)); }
vec4 load_patch(uint i) { return patches[i]; }
void store_patch(uint i, vec4 v) { patches[i] = v; }

#include "polish.h"
#include "search.h"

#if defined(FGSR_POLISH_SEARCH) && FGSR_POLISH_SEARCH == 1
void main() { search_patch(gl_GlobalInvocationID.xy, pc.p); }
#elif defined(FGSR_POLISH_SEARCH)
void main() { search_densify_pixel(gl_GlobalInvocationID.xy, pc.p); }
#elif defined(FGSR_POLISH_SEED)
void main() { polish_seed_pixel(gl_GlobalInvocationID.xy, pc.p); }
#else
void main() { polish_pixel(gl_GlobalInvocationID.xy, pc.p); }
#endif
