#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// One workgroup classifies a block of max(FGSR_GROUP, tile) pixels a side: one tile or, with
// tiles smaller than the workgroup, (block / tile)^2 of them (tile >= 8, so at most 16).
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { ClassifyParams c; } pc;
layout(std430, binding = GEN_MV1) readonly buffer Mv1 { vec2 mv1[]; };
layout(std430, binding = GEN_MV0) readonly buffer Mv0 { vec2 mv0[]; };
layout(std430, binding = GEN_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = GEN_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = GEN_KEYS) writeonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = GEN_MOTION) writeonly buffer Motion { vec4 motion[]; };
layout(std430, binding = CLASSIFY_COLOR0) readonly buffer Color0 { uvec2 color0[]; }; // pack_color
layout(std430, binding = CLASSIFY_COLOR1) readonly buffer Color1 { uvec2 color1[]; };
layout(std430, binding = CLASSIFY_OUTPUT) writeonly buffer Output { vec4 outp[]; };
layout(std430, binding = CLASSIFY_FLAGS) writeonly buffer Flags { uint tile_flags[]; };
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
#include "blend.h"
#include "classify.h"
#include "tiles.h"

shared uint moving_tiles; // bit (ty * tiles_per_block + tx): some pixel of that tile is not static

void main() {
    ClassifyParams c = pc.c;
    int side = int(c.tile);
    int block = max(FGSR_GROUP, side);
    int per = block / FGSR_GROUP; // pixels per invocation along each axis
    int tiles_per_block = block / side;
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * block;
    ivec2 lid = ivec2(gl_LocalInvocationID.xy);
    if (gl_LocalInvocationIndex == 0u) moving_tiles = 0u;
    barrier();
    for (int j = 0; j < per; ++j)
        for (int i = 0; i < per; ++i) {
            ivec2 d = ivec2(i, j) * FGSR_GROUP + lid;
            ivec2 p = origin + d;
            if (inside(p, c.g) && !static_pixel(p, c))
                atomicOr(moving_tiles, 1u << uint((d.y / side) * tiles_per_block + d.x / side));
        }
    barrier();
    uint moving = moving_tiles;
    if (c.mode == CLASSIFY_GENERATE)
        for (int j = 0; j < per; ++j)
            for (int i = 0; i < per; ++i) {
                ivec2 d = ivec2(i, j) * FGSR_GROUP + lid;
                ivec2 p = origin + d;
                if (!inside(p, c.g)) continue;
                uint idx = uint(p.y) * c.g.width + uint(p.x);
                bool is_static = (moving & (1u << uint((d.y / side) * tiles_per_block + d.x / side))) == 0u;
                keys[idx] = is_static ? own_key(p, c.g) : ~uint64_t(0);
                if (!is_static) continue;
                motion[idx] = vec4(0.0f);
                if (c.write_output != 0u) outp[idx] = copy_through(p, c.g);
            }
    int k = int(gl_LocalInvocationIndex);
    if (k >= tiles_per_block * tiles_per_block) return;
    ivec2 tile = ivec2(gl_WorkGroupID.xy) * tiles_per_block + ivec2(k % tiles_per_block, k / tiles_per_block);
    if (!inside(tile * side, c.g)) return;
    bool is_static = (moving & (1u << uint(k))) == 0u;
    tile_flags[tile_index(tile * side, c.g.width, c.tile)] = is_static ? TILE_STATIC : TILE_MOVING;
    uint packed = uint(tile.x) | (uint(tile.y) << 16);
    if (!is_static) {
        TILE_APPEND(list_work, packed, c.work_invocations);
        if (c.mode == CLASSIFY_GENERATE) TILE_APPEND(list_generate, packed, c.output_invocations);
    } else {
        TILE_APPEND(list_static, packed, c.output_invocations);
    }
}
