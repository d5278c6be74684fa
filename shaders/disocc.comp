#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { GenParams g; } pc;
layout(std430, binding = DISOCC_MV1) readonly buffer Mv1 { vec2 mv1[]; };
layout(std430, binding = DISOCC_FIELD) buffer Field { vec4 field[]; };
layout(std430, binding = DISOCC_FIELD_DEPTH) buffer FieldDepth { float field_depth[]; };
layout(std430, binding = DISOCC_FIELD_STATE) buffer FieldState { uint field_state[]; };

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.g.width) + q.x]; }
vec4 load_field(ivec2 q) { return field[q.y * int(pc.g.width) + q.x]; }
float load_field_depth(ivec2 q) { return field_depth[q.y * int(pc.g.width) + q.x]; }
uint load_field_state(ivec2 q) { return field_state[q.y * int(pc.g.width) + q.x]; }
void store_field(uint i, vec4 f, float d, uint s) { field[i] = f; field_depth[i] = d; field_state[i] = s; }

#include "field.h"
#include "disocc.h"

void main() { disocc_pixel(ivec2(gl_GlobalInvocationID.xy), pc.g); }
