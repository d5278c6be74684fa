#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { IngestParams p; } pc;
layout(std430, binding = INGEST_COLOR_RAW) readonly buffer ColorRaw { uint color_raw[]; };
layout(std430, binding = INGEST_DEPTH_RAW) readonly buffer DepthRaw { uint depth_raw[]; };
layout(std430, binding = INGEST_MV_RAW) readonly buffer MvRaw { uint mv_raw[]; };
// The internal planes as 64-bit words (shaders/load64.h): one store per packed colour and per
// vector instead of two on CPU devices; the same bits.
layout(std430, binding = INGEST_COLOR) writeonly buffer Color { uint64_t color[]; }; // pack_color (uvec2)
layout(std430, binding = INGEST_DEPTH) writeonly buffer Depth { float depth[]; };
layout(std430, binding = INGEST_MV) writeonly buffer Mv { uint64_t mv[]; }; // vec2
layout(std430, binding = INGEST_BRIGHT) buffer Bright { uint bright[]; };
#include "load64.h"

uint load_color_word(uint w) { return color_raw[w]; }
uint load_depth_word(uint i) { return depth_raw[i]; }
uint load_mv_word(uint w) { return mv_raw[w]; }
#if defined(FGSR_INGEST_COLOR) && FGSR_GROUP == 32
// Fixed-format CPU builds read word pairs of the raw planes as one 64-bit access (aliases of the
// same bindings). Only there: the bindings' offsets are multiples of minStorageBufferOffsetAlignment
// (16 on lavapipe), which need not be 8 on every GPU.
layout(std430, binding = INGEST_COLOR_RAW) readonly buffer ColorRaw64 { uint64_t color_raw64[]; };
layout(std430, binding = INGEST_MV_RAW) readonly buffer MvRaw64 { uint64_t mv_raw64[]; };
uvec2 load_color_pair(uint p) { return as_uvec2(color_raw64[p]); }
uvec2 load_mv_pair(uint p) { return as_uvec2(mv_raw64[p]); }
#else
uvec2 load_color_pair(uint p) { return uvec2(color_raw[2u * p], color_raw[2u * p + 1u]); }
uvec2 load_mv_pair(uint p) { return uvec2(mv_raw[2u * p], mv_raw[2u * p + 1u]); }
#endif
void store_frame(uint i, uvec2 c, float d, vec2 m) {
    color[i] = as_u64(c);
#ifndef FGSR_INGEST_COLOUR_ONLY
    depth[i] = d;
    mv[i] = as_u64(floatBitsToUint(m));
#endif
}

// The dilate stage's tile flags (shaders/dilate.h): note_bright remembers whether a pixel of the
// invocation's row segment is over-white, flag_bright then flags the 16x16 tiles of the segment's
// 3x3 neighbourhood, once per invocation (a conditional store per pixel cost lavapipe about 0.5 ms
// of 3 at 480x270 with no pixel over white; docs/ACCURACY.md, change 11). All stores write 1. sRGB colour is never over
// white: the fixed sRGB builds fold the test away; the colour-only builds have no dilate stage.
bool any_bright = false;
void note_bright(uvec2 pix, vec4 c, IngestParams p) {
#ifndef FGSR_INGEST_COLOUR_ONLY
    any_bright = any_bright || (p.color_format != 0u && p.bright > 0.0f && linear_luminance(c) > p.bright);
#endif
}
void flag_bright(uvec2 first, uint count, IngestParams p) {
#ifndef FGSR_INGEST_COLOUR_ONLY
    if (!any_bright) return;
    uvec2 lo = (max(first, uvec2(1u)) - 1u) >> FGSR_BRIGHT_TILE_SHIFT;
    uvec2 hi = min(first + uvec2(count, 1u), uvec2(p.width, p.height) - 1u) >> FGSR_BRIGHT_TILE_SHIFT;
    for (uint ty = lo.y; ty <= hi.y; ++ty)
        for (uint tx = lo.x; tx <= hi.x; ++tx) bright[ty * p.bright_tiles_x + tx] = 1u;
#endif
}

#include "ingest.h"

// Builds with FGSR_INGEST_COLOR and FGSR_INGEST_MV (fgsr::ColorFormat / MvFormat values) fix the
// plane formats, so that the other formats' decoders are compiled out: CPU devices run both sides
// of every branch with the inactive lanes masked off (classify.comp), so every format's loads and
// conversions would be paid for by every session. The build without them serves any format, one
// pixel per invocation; the fixed-format CPU builds (FGSR_GROUP 32) take a row segment of
// FGSR_INGEST_SPAN_CPU pixels per invocation (a fixed cost per invocation, docs/TILES.md).
// The colour-only builds (FGSR_INGEST_COLOUR_ONLY: sessions without vectors and depth) store the
// colour alone: the flow pass writes every pixel's vector and depth proxy after it, and where it does
// not run (a session's first frame, a reset, a cut) the engine fills the two planes with the values
// ingest would have stored (zero vectors, depth 1; session.cpp). That leaves one store per pixel
// of three, on CPU devices each a loop over the SIMD lanes (docs/PERFORMANCE.md, "colour-only
// ingest").
IngestParams fixed_formats(IngestParams p) {
#ifdef FGSR_INGEST_COLOR
    p.color_format = FGSR_INGEST_COLOR;
    p.mv_format = FGSR_INGEST_MV;
#endif
#ifdef FGSR_INGEST_COLOUR_ONLY
    p.has_mv = 0u;
    p.has_depth = 0u;
#endif
    return p;
}

#if defined(FGSR_INGEST_COLOR) && FGSR_GROUP == 32
void main() {
    for (uint k = 0u; k < FGSR_INGEST_SPAN_CPU; ++k)
        ingest_pixel(uvec2(gl_GlobalInvocationID.x * FGSR_INGEST_SPAN_CPU + k, gl_GlobalInvocationID.y),
                     fixed_formats(pc.p));
    flag_bright(uvec2(gl_GlobalInvocationID.x * FGSR_INGEST_SPAN_CPU, gl_GlobalInvocationID.y), FGSR_INGEST_SPAN_CPU,
                fixed_formats(pc.p));
}
#else
void main() {
    ingest_pixel(gl_GlobalInvocationID.xy, fixed_formats(pc.p));
    flag_bright(gl_GlobalInvocationID.xy, 1u, fixed_formats(pc.p));
}
#endif
