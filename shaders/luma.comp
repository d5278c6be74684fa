#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { LumaParams p; } pc;
#if defined(FGSR_LUMA_GAIN)
// The lighting gain (luma.h): 1 counts the coarsest levels' ratios in a histogram and stores the
// gain, and the indirect dispatch of 2: no workgroups where the gain is 1 (most frames), else one
// invocation per float of the previous frame's pyramid (rows of LUMA_GAIN_ROW), which 2 scales.
// p.src_offset, p.src_width: the coarsest level's offset and texels; p.dst_width: the pyramid's
// floats.
layout(std430, binding = LUMA_COLOR) buffer Gain {
    float gain;
    uint pad[3];
    uint dispatch[3]; // LUMA_GAIN_DISPATCH: vkCmdDispatchIndirect's groups
};
layout(std430, binding = LUMA_PYRAMID) buffer Prev { float prev_pyramid[]; };
layout(binding = LUMA_PYRAMID_TEXELS) uniform samplerBuffer cur; // the current frame's pyramid

vec4 load_color(uint i) { return vec4(0.0); }
float load_level(uint i) { return texelFetch(cur, int(i)).x; }
void store_level(uint i, float v) {}
float load_prev_level(uint i) { return prev_pyramid[i]; }
shared uint bins[LUMA_GAIN_BINS];
void add_to_bin(uint b) { atomicAdd(bins[b], 1u); }
uint load_bin(uint b) { return bins[b]; }
#else
layout(std430, binding = LUMA_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = LUMA_PYRAMID) writeonly buffer Pyramid { float pyramid[]; };
// The finer level as texels: a gather where a storage-buffer load is a loop over the lanes on
// lavapipe (match.comp); the same floats.
layout(binding = LUMA_PYRAMID_TEXELS) uniform samplerBuffer finer;

vec4 load_color(uint i) { return unpack_color(color[i]); }
float load_level(uint i) { return texelFetch(finer, int(i)).x; }
void store_level(uint i, float v) { pyramid[i] = v; }
float load_prev_level(uint i) { return 0.0; }
void add_to_bin(uint b) {}
uint load_bin(uint b) { return 0u; }
#endif

#include "luma.h"

#if FGSR_LUMA_GAIN == 1
void main() {
    uint lane = gl_LocalInvocationIndex;
    for (uint b = lane; b < LUMA_GAIN_BINS && lane < LUMA_GAIN_LANES; b += LUMA_GAIN_LANES) bins[b] = 0u;
    barrier();
    if (lane < LUMA_GAIN_LANES) luma_gain_lane(lane, pc.p);
    barrier();
    if (lane == 0u) {
        float k = luma_gain(pc.p.src_width);
        uint rows = (pc.p.dst_width + LUMA_GAIN_ROW - 1u) / LUMA_GAIN_ROW;
        gain = k;
        dispatch[0] = k != 1.0 ? LUMA_GAIN_ROW / FGSR_GROUP : 0u;
        dispatch[1] = (rows + FGSR_GROUP - 1u) / FGSR_GROUP;
        dispatch[2] = 1u;
    }
}
#elif FGSR_LUMA_GAIN == 2
void main() {
    uint i = gl_GlobalInvocationID.y * LUMA_GAIN_ROW + gl_GlobalInvocationID.x;
    if (i < pc.p.dst_width) prev_pyramid[i] *= gain;
}
#elif FGSR_LUMA_LEVEL0 == 2
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
