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
layout(std430, binding = BLEND_FIELD) readonly buffer Field { vec4 field[]; };
layout(std430, binding = BLEND_MV1) readonly buffer Mv1 { vec2 mv1[]; };
layout(std430, binding = BLEND_FRAME_DEPTH1) readonly buffer FrameDepth1 { float frame_depth1[]; };

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.g.width) + q.x]; }
float load_depth1(ivec2 q) { return frame_depth1[q.y * int(pc.g.width) + q.x]; }

#include "field.h"
#include "depth_change.h"
#include "blend_depth.h"
#include "blend.h"

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(t, pc.g)) return;
    uint i = uint(t.y) * pc.g.width + uint(t.x);
    vec2 d = blend_depths(depth0[i], depth1[i], sample_pixel(vec2(t) + vec2(0.5f) + field[i].zw, pc.g), pc.g);
    outp[i] = select_blend(color0[i], d.x, color1[i], d.y, field_state[i], pc.g);
}
