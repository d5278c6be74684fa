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

void main() { luma_pixel(gl_GlobalInvocationID.xy, pc.p); }
