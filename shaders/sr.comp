#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { SrParams p; } pc;
layout(std430, binding = SR_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = SR_DEPTH) readonly buffer Depth { float depth[]; };
layout(std430, binding = SR_MV) readonly buffer Mv { vec2 mv[]; };
layout(std430, binding = SR_PREV_DEPTH) readonly buffer PrevDepth { float prev_depth[]; };
layout(std430, binding = SR_HISTORY) readonly buffer History { vec4 history[]; };
layout(std430, binding = SR_LUT) readonly buffer Lut { float lut[]; };
layout(std430, binding = SR_OUTPUT) writeonly buffer Output { vec4 outp[]; };

vec4 load_lr_color(ivec2 q) { return unpack_color(color[q.y * int(pc.p.lr_width) + q.x]); }
float load_lr_depth(ivec2 q) { return depth[q.y * int(pc.p.lr_width) + q.x]; }
vec2 load_lr_mv(ivec2 q) { return mv[q.y * int(pc.p.lr_width) + q.x]; }
float load_prev_depth(ivec2 q) { return prev_depth[q.y * int(pc.p.lr_width) + q.x]; }
vec4 load_src(ivec2 q) { return history[q.y * int(pc.p.hr_width) + q.x]; }
float load_lut(uint i) { return lut[i]; }

#include "resample.h"
#include "sr.h"

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= int(pc.p.hr_width) || q.y >= int(pc.p.hr_height)) return;
    outp[q.y * int(pc.p.hr_width) + q.x] = super_resolve(q, pc.p);
}
