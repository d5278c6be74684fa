#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Four dispatches with a barrier between each (denoise.h): the histogram over 2x2 blocks, the
// level (one invocation), then, indirect and empty when the level says r = 0, the filter per pixel
// into the scratch and its copy back.
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { DenoiseParams p; } pc;
layout(std430, binding = DENOISE_COLOR_IN) readonly buffer ColorIn { uvec2 color_in[]; }; // pack_color
layout(std430, binding = DENOISE_COLOR) writeonly buffer Color { uvec2 color[]; };
layout(std430, binding = DENOISE_NOISE) buffer Noise { uint noise[]; };

vec4 load_color(ivec2 q) { return unpack_color(color_in[q.y * int(pc.p.width) + q.x]); }
void store_color(uint i, vec4 c) { color[i] = pack_color(c); }
void add_to_bin(uint b) { atomicAdd(noise[b], 1u); }
uint load_bin(uint b) { return noise[b]; }
void store_level(float sigma, float range) {
    noise[DENOISE_SIGMA] = floatBitsToUint(sigma);
    noise[DENOISE_RANGE] = floatBitsToUint(range);
    uint groups = (pc.p.width + uint(FGSR_GROUP) - 1u) / uint(FGSR_GROUP);
    noise[DENOISE_DISPATCH] = (range > 0.0 && !isinf(range)) ? groups : 0u; // denoise_filters()
    noise[DENOISE_DISPATCH + 1u] = (pc.p.height + uint(FGSR_GROUP) - 1u) / uint(FGSR_GROUP);
    noise[DENOISE_DISPATCH + 2u] = 1u;
}
float load_range() { return uintBitsToFloat(noise[DENOISE_RANGE]); }

#include "denoise.h"

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (pc.p.stage == DENOISE_HISTOGRAM) {
        denoise_histogram(q, pc.p);
    } else if (pc.p.stage == DENOISE_LEVEL) {
        if (q == ivec2(0)) denoise_level(pc.p);
    } else if (q.x < int(pc.p.width) && q.y < int(pc.p.height)) {
        uint i = uint(q.y) * pc.p.width + uint(q.x);
        if (pc.p.stage == DENOISE_FILTER)
            store_color(i, denoise_pixel(q, pc.p));
        else
            color[i] = color_in[i]; // DENOISE_COPY
    }
}
