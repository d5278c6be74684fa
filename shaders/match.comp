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

#include "match.h"

#ifdef FGSR_MATCH_FILL
void main() { fill_block(gl_GlobalInvocationID.xy, pc.p); }
#else
void main() { match_block(gl_GlobalInvocationID.xy, pc.p); }
#endif
