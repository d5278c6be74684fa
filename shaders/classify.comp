#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Two dispatches, a barrier between them (workgroup barriers and shared-memory reductions were
// measured slower than a whole generate pass on lavapipe):
//   stage 0, per row segment of CLASSIFY_SPAN pixels inside one tile: a segment with a pixel that
//            is not static ORs TILE_MOVING into its tile's flag (zeroed by the host); static pixels
//            get their copy-through colour (write_output), which the passes over the generate list
//            overwrite where the tile is moving or gets dirty;
//   stage 1, per tile: sets a static tile's flag to TILE_STATIC and appends every tile to its lists.
// Each stage and mode is its own build of this file (no define: stage 1; FGSR_CLASSIFY_PIXELS = 1:
// stage 0 in generate mode, 2: in sr mode, 3: generate mode 4 pixels per buffer access, for widths
// divisible by 4). CPU devices run every branch of a shader with the inactive lanes masked off
// (lavapipe: both sides of an `if`, only a loop that no lane enters is skipped), so code behind a
// uniform branch costs as if taken; separate builds cost only what their stage runs. On CPU
// devices (FGSR_GROUP 32) a segment is FGSR_CLASSIFY_SPAN_CPU pixels (fixed cost per invocation).
// Keys and field vectors of static tiles are not written: the tiled passes derive them (tiles.h).
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { ClassifyParams c; } pc;
layout(std430, binding = GEN_MV1) readonly buffer Mv1 { vec2 mv1[]; };
layout(std430, binding = GEN_MV0) readonly buffer Mv0 { vec2 mv0[]; };
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = CLASSIFY_COLOR0) readonly buffer Color0 { uvec2 color0[]; }; // pack_color
layout(std430, binding = CLASSIFY_COLOR1) readonly buffer Color1 { uvec2 color1[]; };
layout(std430, binding = CLASSIFY_OUTPUT) writeonly buffer Output { vec4 outp[]; };
layout(std430, binding = CLASSIFY_FLAGS) buffer Flags { uint tile_flags[]; };
// The same buffers 4 pixels per element (the wide form of stage 0; pack_color colours are 64 bits).
layout(std430, binding = GEN_MV1) readonly buffer Mv1Quad { u64vec4 mv1_quad[]; };
layout(std430, binding = GEN_MV0) readonly buffer Mv0Quad { u64vec4 mv0_quad[]; };
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1Quad { vec4 depth1_quad[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0Quad { vec4 depth0_quad[]; };
layout(std430, binding = CLASSIFY_COLOR0) readonly buffer Color0Quad { u64vec4 color0_quad[]; };
layout(std430, binding = CLASSIFY_COLOR1) readonly buffer Color1Quad { u64vec4 color1_quad[]; };
layout(std430, binding = CLASSIFY_OUTPUT) writeonly buffer OutputPair { u64vec4 outp_pair[]; }; // 2 rgba32f
layout(std430, binding = CLASSIFY_LIST_WORK) buffer ListWork { uint list_work[]; };
layout(std430, binding = CLASSIFY_LIST_GENERATE) buffer ListGenerate { uint list_generate[]; };
layout(std430, binding = CLASSIFY_LIST_STATIC) buffer ListStatic { uint list_static[]; };

vec2 load_mv1(ivec2 q) { return mv1[q.y * int(pc.c.g.width) + q.x]; }
vec2 load_mv0(ivec2 q) { return mv0[q.y * int(pc.c.g.width) + q.x]; }
float load_depth1(ivec2 q) { return depth1[q.y * int(pc.c.g.width) + q.x]; }
float load_depth0(ivec2 q) { return depth0[q.y * int(pc.c.g.width) + q.x]; }
vec4 load_color0(ivec2 q) { return unpack_color(color0[q.y * int(pc.c.g.width) + q.x]); }
vec4 load_color1(ivec2 q) { return unpack_color(color1[q.y * int(pc.c.g.width) + q.x]); }

#include "field.h"
#include "depth_change.h"
#include "blend_depth.h"
#include "blend.h"
#include "classify.h"
#include "tiles.h"

#if FGSR_GROUP == 32
#define CLASSIFY_SPAN FGSR_CLASSIFY_SPAN_CPU
#define CLASSIFY_SUB 8u
#else
#define CLASSIFY_SPAN 1u
#define CLASSIFY_SUB 1u
#endif

#if FGSR_CLASSIFY_PIXELS == 3
uint64_t pack_pair(vec2 v) { return pack64(floatBitsToUint(v)); }

// The quad of pixels p .. p + (3, 0) (row-major index 4 * quad on), values read and written 4
// pixels per access: true when one of them is not a static source by its own values
// (static_source_own); sets bit l of `neighbours` where pixel p + (l, 0) is static exactly when
// static_source_neighbours holds. Writes the quad's copy-through colours unless a pixel is not
// static (a pixel that then fails its neighbour test makes its tile moving: it is regenerated).
bool classify_quad(ivec2 p, uint quad, out uint neighbours) {
    u64vec4 m1 = mv1_quad[quad];
    u64vec4 m0 = mv0_quad[quad];
    vec4 d0 = depth0_quad[quad];
    vec4 d1 = depth1_quad[quad];
    u64vec4 c0 = color0_quad[quad];
    u64vec4 c1 = color1_quad[quad];
    bool moving = false;
    neighbours = 0u;
    vec4 c[4];
    for (int l = 0; l < 4; ++l) {
        uint own = static_source_own(uintBitsToFloat(unpack32(m1[l])), d0[l], d1[l], uintBitsToFloat(unpack32(m0[l])),
                                     pc.c.g);
        if (own == STATIC_NO) moving = true;
        if (own == STATIC_IF_NEIGHBOURS) neighbours |= 1u << uint(l);
        c[l] = copy_through_values(p + ivec2(l, 0), unpack_color(unpack32(c0[l])), d0[l],
                                   unpack_color(unpack32(c1[l])), d1[l], pc.c.g);
    }
    if (!moving && pc.c.write_output != 0u) {
        outp_pair[2u * quad] = u64vec4(pack_pair(c[0].xy), pack_pair(c[0].zw), pack_pair(c[1].xy), pack_pair(c[1].zw));
        outp_pair[2u * quad + 1u] =
            u64vec4(pack_pair(c[2].xy), pack_pair(c[2].zw), pack_pair(c[3].xy), pack_pair(c[3].zw));
    }
    return moving;
}
#endif

#ifdef FGSR_CLASSIFY_PIXELS
// Stage 0 over CLASSIFY_SUB pixels from p0 (inside one tile): true when one is not static.
bool classify_pixels(ivec2 p0) {
    bool moving = false;
#if FGSR_CLASSIFY_PIXELS == 3
    uint neighbours = 0u; // bit k: pixel p0 + (k, 0) needs static_source_neighbours
    for (uint k = 0u; k < CLASSIFY_SUB; k += 4u) {
        ivec2 p = p0 + ivec2(int(k), 0);
        uint n = 0u;
        if (p.x < int(pc.c.g.width) && classify_quad(p, (uint(p.y) * pc.c.g.width + uint(p.x)) >> 2u, n))
            moving = true;
        neighbours |= n << k;
    }
    // One loop for the rare pixels whose depths disagree: CPU devices skip a loop no lane enters
    // (an `if` they would run with the lanes masked off).
    for (uint b = moving ? 0u : neighbours; b != 0u; b &= b - 1u)
        if (!static_source_neighbours(p0 + ivec2(findLSB(b), 0), pc.c.g)) moving = true;
#else
    for (uint k = 0u; k < CLASSIFY_SUB; ++k) {
        ivec2 p = p0 + ivec2(int(k), 0);
        if (p.x >= int(pc.c.g.width)) break;
#if FGSR_CLASSIFY_PIXELS == 2
        if (!static_sr_pixel(p, pc.c)) moving = true;
#else
        if (!static_source(p, pc.c.g)) moving = true;
        else if (pc.c.write_output != 0u) outp[uint(p.y) * pc.c.g.width + uint(p.x)] = copy_through(p, pc.c.g);
#endif
    }
#endif
    return moving;
}

void main() {
    ivec2 seg = ivec2(int(gl_GlobalInvocationID.x * CLASSIFY_SPAN), int(gl_GlobalInvocationID.y));
    if (!inside(seg, pc.c.g)) return;
    for (uint s = 0u; s < CLASSIFY_SPAN; s += CLASSIFY_SUB) {
        ivec2 p0 = seg + ivec2(int(s), 0);
        if (p0.x >= int(pc.c.g.width)) break;
        uint t = tile_index(p0, pc.c.g.width, pc.c.tile);
        if (classify_pixels(p0) && (tile_flags[t] & TILE_MOVING) == 0u) atomicOr(tile_flags[t], TILE_MOVING);
    }
}
#else
void main() {
    ivec2 tile = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(tile * int(pc.c.tile), pc.c.g)) return;
    uint t = tile_index(tile * int(pc.c.tile), pc.c.g.width, pc.c.tile);
    uint packed = uint(tile.x) | (uint(tile.y) << 16);
    if ((tile_flags[t] & TILE_MOVING) != 0u) {
        TILE_APPEND(list_work, packed, pc.c.work_invocations);
        if (pc.c.mode == CLASSIFY_GENERATE) TILE_APPEND(list_generate, packed, pc.c.output_invocations);
    } else {
        tile_flags[t] = TILE_STATIC;
        TILE_APPEND(list_static, packed, pc.c.output_invocations);
    }
}
#endif
