#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { IngestParams p; } pc;
layout(std430, binding = INGEST_COLOR_RAW) readonly buffer ColorRaw { uint color_raw[]; };
layout(std430, binding = INGEST_DEPTH_RAW) readonly buffer DepthRaw { uint depth_raw[]; };
layout(std430, binding = INGEST_MV_RAW) readonly buffer MvRaw { uint mv_raw[]; };
layout(std430, binding = INGEST_COLOR) writeonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = INGEST_DEPTH) writeonly buffer Depth { float depth[]; };
layout(std430, binding = INGEST_MV) writeonly buffer Mv { vec2 mv[]; };

uint load_color_word(uint w) { return color_raw[w]; }
uint load_depth_word(uint i) { return depth_raw[i]; }
uint load_mv_word(uint w) { return mv_raw[w]; }
void store_frame(uint i, uvec2 c, float d, vec2 m) { color[i] = c; depth[i] = d; mv[i] = m; }

#include "ingest.h"

void main() { ingest_pixel(gl_GlobalInvocationID.xy, pc.p); }
