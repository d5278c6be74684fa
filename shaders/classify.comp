#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Two dispatches, a barrier between them (workgroup barriers and shared-memory reductions were
// measured slower than a whole generate pass on lavapipe):
//   stage 0, per pixel: a pixel that is not static ORs TILE_MOVING into its tile's flag (zeroed by
//            the host); a static one writes its copy-through colour (write_output), which the
//            passes over the generate list overwrite where its tile is moving or gets dirty;
//   stage 1, per tile: sets a static tile's flag to TILE_STATIC and appends every tile to its lists.
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

void main() {
    if (pc.c.stage == 0u) {
        ivec2 p = ivec2(gl_GlobalInvocationID.xy);
        if (!inside(p, pc.c.g)) return;
        uint t = tile_index(p, pc.c.g.width, pc.c.tile);
        if (!static_pixel(p, pc.c)) {
            if ((tile_flags[t] & TILE_MOVING) == 0u) atomicOr(tile_flags[t], TILE_MOVING);
        } else if (pc.c.mode == CLASSIFY_GENERATE && pc.c.write_output != 0u) {
            outp[uint(p.y) * pc.c.g.width + uint(p.x)] = copy_through(p, pc.c.g);
        }
        return;
    }
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
