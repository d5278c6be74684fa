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
void splat_min(uint i, uint64_t key) { atomicMin(keys[i], key); }
void store_motion(uint i, vec4 m) { motion[i] = m; }

#include "field.h"
#include "motion.h"
#include "splat.h"

void main() { splat_pixel(ivec2(gl_GlobalInvocationID.xy), pc.g); }
