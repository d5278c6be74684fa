#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { GenParams g; } pc;
layout(std430, binding = WARP_FIELD) readonly buffer Field { vec4 field[]; };
layout(std430, binding = WARP_COLOR0) readonly buffer Color0 { uvec2 color0[]; }; // pack_color
layout(std430, binding = WARP_COLOR1) readonly buffer Color1 { uvec2 color1[]; }; // pack_color
layout(std430, binding = WARP_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = WARP_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = WARP_OUT_COLOR0) writeonly buffer OutColor0 { vec4 out_color0[]; };
layout(std430, binding = WARP_OUT_DEPTH0) writeonly buffer OutDepth0 { float out_depth0[]; };
layout(std430, binding = WARP_OUT_COLOR1) writeonly buffer OutColor1 { vec4 out_color1[]; };
layout(std430, binding = WARP_OUT_DEPTH1) writeonly buffer OutDepth1 { float out_depth1[]; };
layout(std430, binding = WARP_FIELD_STATE) readonly buffer FieldState { uint field_state[]; }; // extrapolation

vec4 load_color0(ivec2 q) { return unpack_color(color0[q.y * int(pc.g.width) + q.x]); }
vec4 load_color1(ivec2 q) { return unpack_color(color1[q.y * int(pc.g.width) + q.x]); }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.g.width) + q.x]; }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.g.width) + q.x]; }

#include "field.h"
#include "warp.h"

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(t, pc.g)) return;
    uint i = uint(t.y) * pc.g.width + uint(t.x);
    vec4 f = field[i];
    vec2 centre = vec2(t) + vec2(0.5f);
    WarpSample w1 = warp_sample(1u, centre, vec2(f.z, f.w), pc.g);
    out_color1[i] = pc.g.extrapolate != 0u ? extrapolated_color(w1, f, field_state[i], centre, pc.g) : w1.color;
    out_depth1[i] = w1.depth;
    if (pc.g.extrapolate == 0u) {
        WarpSample w0 = warp_sample(0u, centre, vec2(f.x, f.y), pc.g);
        out_color0[i] = w0.color;
        out_depth0[i] = w0.depth;
    }
}
