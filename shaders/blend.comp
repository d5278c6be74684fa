#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { GenParams g; } pc;
layout(std430, binding = BLEND_COLOR0) readonly buffer Color0 { vec4 color0[]; };
layout(std430, binding = BLEND_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = BLEND_COLOR1) readonly buffer Color1 { vec4 color1[]; };
layout(std430, binding = BLEND_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = BLEND_FIELD_STATE) readonly buffer FieldState { uint field_state[]; };
layout(std430, binding = BLEND_OUTPUT) writeonly buffer Output { vec4 outp[]; };

vec4 load_warped_color(uint i, uint frame) { return frame == 0u ? color0[i] : color1[i]; }
float load_warped_depth(uint i, uint frame) { return frame == 0u ? depth0[i] : depth1[i]; }
uint load_field_state(ivec2 q) { return field_state[q.y * int(pc.g.width) + q.x]; }
void store_output(uint i, vec4 c) { outp[i] = c; }

#include "field.h"
#include "blend.h"

void main() { blend_pixel(ivec2(gl_GlobalInvocationID.xy), pc.g); }
