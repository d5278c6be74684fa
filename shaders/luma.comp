#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { LumaParams p; } pc;
layout(std430, binding = LUMA_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = LUMA_PYRAMID) writeonly buffer Pyramid { float pyramid[]; };
// The finer level as texels: a gather where a storage-buffer load is a loop over the lanes on
// lavapipe (match.comp); the same floats.
layout(binding = LUMA_PYRAMID_TEXELS) uniform samplerBuffer finer;

vec4 load_color(uint i) { return unpack_color(color[i]); }
float load_level(uint i) { return texelFetch(finer, int(i)).x; }
void store_level(uint i, float v) { pyramid[i] = v; }

#include "luma.h"

#if FGSR_LUMA_LEVEL0 == 2
// Level 0, 4 pixels per invocation (frames whose width is a multiple of 4, the level at an offset
// that is one): one 32-byte colour load and one 16-byte store where the per-pixel build makes four
// of each, on CPU devices a loop over the lanes per access. The same luma as luma_pixel.
layout(std430, binding = LUMA_COLOR) readonly buffer ColorQuad { u64vec4 color_quad[]; };
layout(std430, binding = LUMA_PYRAMID) writeonly buffer PyramidQuad { vec4 pyramid_quad[]; };

void main() {
    uvec2 q = gl_GlobalInvocationID.xy; // q.x counts quads
    if (4u * q.x >= pc.p.dst_width || q.y >= pc.p.dst_height) return;
    uint quad = q.y * (pc.p.dst_width >> 2) + q.x;
    u64vec4 c = color_quad[quad];
    vec4 v;
    for (int l = 0; l < 4; ++l) v[l] = motion_luma(unpack_color(unpack32(c[l])));
    pyramid_quad[(pc.p.dst_offset >> 2) + quad] = v;
}
#else
void main() { luma_pixel(gl_GlobalInvocationID.xy, pc.p); }
#endif
