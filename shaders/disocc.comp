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
layout(std430, binding = GEN_MOTION) readonly buffer Motion { vec4 motion[]; }; // (m1, m0) per source
layout(std430, binding = DISOCC_FIELD) buffer Field { vec4 field[]; };
layout(std430, binding = DISOCC_FIELD_DEPTH) buffer FieldDepth { float field_depth[]; };
layout(std430, binding = DISOCC_FIELD_STATE) buffer FieldState { uint field_state[]; };
layout(std430, binding = DISOCC_COLOR1) readonly buffer Color1 { uvec2 color1[]; }; // pack_color

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.g.width) + q.x]; }
vec2 load_mv0(ivec2 q) { return mv0[q.y * int(pc.g.width) + q.x]; }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
vec4 load_color1(ivec2 q) { return unpack_color(color1[q.y * int(pc.g.width) + q.x]); }
uint64_t load_key(ivec2 q) { return keys[q.y * int(pc.g.width) + q.x]; }
vec4 load_source_motion(uint i) { return motion[i]; }
#include "motion.h"
vec4 load_motion(uint src) { return source_field_vectors(src, pc.g); }
uint load_field_state(ivec2 q) { return field_state[q.y * int(pc.g.width) + q.x]; }
void store_field(uint i, vec4 f, float d, uint s) { field[i] = f; field_depth[i] = d; field_state[i] = s; }

#include "field.h"
#include "refine.h"
#include "disocc.h"

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(t, pc.g) || load_field_state(t) != FIELD_HOLE) return;
    FieldSample f = fill_hole_covered(t, pc.g);
    store_field(uint(t.y) * pc.g.width + uint(t.x), f.v, f.depth, f.state);
}
