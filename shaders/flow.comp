#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { FlowParams p; } pc;
layout(binding = FLOW_CUR) uniform samplerBuffer cur; // texel buffers, as in match.comp
layout(binding = FLOW_PREV) uniform samplerBuffer prev;
layout(binding = FLOW_FIELD) uniform samplerBuffer field; // RGBA32F texels
layout(std430, binding = FLOW_MV) buffer Mv { vec2 mv[]; }; // read: the given vectors (correct)
layout(std430, binding = FLOW_DEPTH) buffer Depth { float depth[]; };
layout(std430, binding = FLOW_PREV_DEPTH) readonly buffer PrevDepth { float prev_depth[]; };
layout(binding = FLOW_COARSE) uniform samplerBuffer coarse; // RG32F texels

float load_cur(uint i) { return texelFetch(cur, int(i)).x; }
float load_prev(uint i) { return texelFetch(prev, int(i)).x; }
vec4 load_field(uint i) { return texelFetch(field, int(i)); }
vec2 load_given(uint i) { return mv[i]; }
float load_depth(uint i) { return depth[i]; }
float load_prev_depth(uint i) { return prev_depth[i]; }
vec2 load_field_vector(uint i) { return texelFetch(coarse, int(i)).xy; }
void store_flow(uint i, vec2 m, float d, bool write_depth) {
    mv[i] = m;
    if (write_depth) depth[i] = d;
}

#include "flow.h"

void main() { flow_pixel(gl_GlobalInvocationID.xy, pc.p); }
