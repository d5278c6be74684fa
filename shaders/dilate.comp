#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Stage dilate of pass ingest (shaders/dilate.h), after ingest, with its bindings and push
// constants: depths and vectors decoded again from the client's planes (ingest.h, the same values
// ingest stored), the results written over the frame's.
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in; // one invocation per flag tile
layout(push_constant) uniform Push { IngestParams p; } pc;
layout(std430, binding = INGEST_COLOR_RAW) readonly buffer ColorRaw { uint color_raw[]; };
layout(std430, binding = INGEST_DEPTH_RAW) readonly buffer DepthRaw { uint depth_raw[]; };
layout(std430, binding = INGEST_MV_RAW) readonly buffer MvRaw { uint mv_raw[]; };
layout(std430, binding = INGEST_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = INGEST_DEPTH) writeonly buffer Depth { float depth[]; };
layout(std430, binding = INGEST_MV) writeonly buffer Mv { vec2 mv[]; };
layout(std430, binding = INGEST_BRIGHT) buffer Bright { uint bright[]; }; // cleared here for the next frame

uint load_color_word(uint w) { return color_raw[w]; }
uint load_depth_word(uint i) { return depth_raw[i]; }
uint load_mv_word(uint w) { return mv_raw[w]; }
uvec2 load_color_pair(uint p) { return uvec2(color_raw[2u * p], color_raw[2u * p + 1u]); }
uvec2 load_mv_pair(uint p) { return uvec2(mv_raw[2u * p], mv_raw[2u * p + 1u]); }
void store_frame(uint i, uvec2 c, float d, vec2 m) {}
void note_bright(uvec2 pix, vec4 c, IngestParams p) {}
#include "ingest.h"

vec4 load_frame_color(uint i) { return unpack_color(color[i]); }
float load_source_depth(uint i) { return linear_depth(uintBitsToFloat(load_depth_word(i)), pc.p); }
vec2 load_source_mv(uint i) { return decode_mv(i, pc.p); }
void store_frame_depth_mv(uint i, float d, vec2 m) {
    depth[i] = d;
    mv[i] = m;
}

#include "dilate.h"

void main() {
    uvec2 tile = gl_GlobalInvocationID.xy;
    uint side = 1u << FGSR_BRIGHT_TILE_SHIFT;
    if (tile.x * side >= pc.p.width || tile.y * side >= pc.p.height) return;
    uint t = tile.y * pc.p.bright_tiles_x + tile.x;
    if (bright[t] == 0u) return;
    bright[t] = 0u; // the next frame's ingest starts from clear flags, without a fill and a barrier
    for (uint k = 0u; k < side * side; ++k) dilate_pixel(tile * side + uvec2(k % side, k / side), pc.p);
}
