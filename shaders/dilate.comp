#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Stage dilate of pass ingest (shaders/dilate.h), after ingest, with its bindings and push
// constants: depths and vectors decoded again from the client's planes (ingest.h, the same values
// ingest stored), the results written over the frame's.
#if defined(FGSR_DILATE_EDGES)
layout(local_size_x = FGSR_DILATE_EDGES_GROUP_X, local_size_y = FGSR_DILATE_EDGES_GROUP_Y) in; // per 16x16 tile
#else
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in; // one invocation per 16x16 tile
#endif
layout(push_constant) uniform Push { IngestParams p; } pc;
layout(std430, binding = INGEST_COLOR_RAW) readonly buffer ColorRaw { uint color_raw[]; };
layout(std430, binding = INGEST_DEPTH_RAW) readonly buffer DepthRaw { uint depth_raw[]; };
layout(std430, binding = INGEST_MV_RAW) readonly buffer MvRaw { uint mv_raw[]; };
layout(std430, binding = INGEST_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = INGEST_DEPTH) writeonly buffer Depth { float depth[]; };
layout(std430, binding = INGEST_MV) writeonly buffer Mv { vec2 mv[]; };
layout(std430, binding = INGEST_BRIGHT) buffer Bright { uint bright[]; }; // cleared here for the next frame
layout(std430, binding = INGEST_PREV_COLOR) readonly buffer PrevColor { uvec2 prev_color[]; }; // pack_color

uint load_color_word(uint w) { return color_raw[w]; }
uint load_depth_word(uint i) { return depth_raw[i]; }
uint load_mv_word(uint w) { return mv_raw[w]; }
uvec2 load_color_pair(uint p) { return uvec2(color_raw[2u * p], color_raw[2u * p + 1u]); }
uvec2 load_mv_pair(uint p) { return uvec2(mv_raw[2u * p], mv_raw[2u * p + 1u]); }
void store_frame(uint i, uvec2 c, float d, vec2 m) {}
void note_bright(uvec2 pix, vec4 c, IngestParams p) {}
#include "ingest.h"

vec4 load_frame_color(uint i) { return unpack_color(color[i]); }
vec4 load_prev_color(uint i) { return unpack_color(prev_color[i]); }
// FGSR_DILATE_LINEAR_DEPTH: the build for linear client depth, whose conversion folds to the
// finiteness test (CPU devices pay for both device-depth formulas otherwise: the edge rule's depth
// test reads 5 depths a pixel; 1-2 ms of the rule's 3.7 on builtin at 480x270 on lavapipe).
float load_source_depth(uint i) {
    IngestParams p = pc.p;
#if defined(FGSR_DILATE_LINEAR_DEPTH)
    p.depth_kind = 0u;
#endif
    return linear_depth(uintBitsToFloat(load_depth_word(i)), p);
}
vec2 load_source_mv(uint i) { return decode_mv(i, pc.p); }
void store_frame_depth_mv(uint i, float d, vec2 m) {
    depth[i] = d;
    mv[i] = m;
}

#include "dilate.h"

#if defined(FGSR_DILATE_EDGES)
// The edge rule over one tile in two steps: the depth test of every pixel, which collects the
// tile's edge pixels, then the colour test of those alone. CPU devices run both sides of a branch
// with the inactive lanes masked off, so the colour test (29 colour reads) behind a branch cost
// every pixel: one invocation per pixel with that branch cost ingest about 7 ms more at 480x270
// on lavapipe (foliage-fg, of 4). A loop over a list runs only as long as the longest list of
// the SIMD group's tiles.
void dilate_edge_tile(uvec2 tile, IngestParams p) {
    uint side = 1u << FGSR_BRIGHT_TILE_SHIFT;
    uint edges[1u << (2u * FGSR_BRIGHT_TILE_SHIFT)];
    uint fronts[1u << (2u * FGSR_BRIGHT_TILE_SHIFT)];
    uint n = 0u;
    for (uint k = 0u; k < side * side; ++k) {
        uvec2 pix = tile * side + uvec2(k % side, k / side);
        if (pix.x >= p.width || pix.y >= p.height) continue;
        uint from = dilate_front(pix, load_source_depth(pix.y * p.width + pix.x), p);
        if (from == DILATE_NO_FRONT) continue;
        edges[n] = k;
        fronts[n] = from;
        ++n;
    }
    for (uint m = 0u; m < n; ++m) {
        uvec2 pix = tile * side + uvec2(edges[m] % side, edges[m] / side);
        uint from = fronts[m];
        if (dilate_takes_front(pix, from, p))
            store_frame_depth_mv(pix.y * p.width + pix.x, load_source_depth(from), load_source_mv(from));
    }
}
#endif

// One invocation per 16x16 tile: the edge rule's build (FGSR_DILATE_EDGES) first runs that rule
// over the tile; then, where ingest flagged the tile, the over-white rule, whose writes win.
void main() {
    uvec2 tile = gl_GlobalInvocationID.xy;
    uint side = 1u << FGSR_BRIGHT_TILE_SHIFT;
    if (tile.x * side >= pc.p.width || tile.y * side >= pc.p.height) return;
#if defined(FGSR_DILATE_EDGES)
    dilate_edge_tile(tile, pc.p);
#endif
    if (!(pc.p.bright > 0.0f)) return; // the flags are not kept without the over-white rule
    uint t = tile.y * pc.p.bright_tiles_x + tile.x;
    if (bright[t] == 0u) return;
    bright[t] = 0u; // the next frame's ingest starts from clear flags, without a fill and a barrier
    for (uint k = 0u; k < side * side; ++k) dilate_pixel(tile * side + uvec2(k % side, k / side), pc.p);
}
