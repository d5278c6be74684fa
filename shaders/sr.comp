#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { SrParams p; } pc;
layout(std430, binding = SR_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = SR_DEPTH) readonly buffer Depth { float depth[]; };
layout(std430, binding = SR_MV) readonly buffer Mv { vec2 mv[]; };
layout(std430, binding = SR_PREV_DEPTH) readonly buffer PrevDepth { float prev_depth[]; };
layout(std430, binding = SR_HISTORY) readonly buffer History { vec4 history[]; };
layout(std430, binding = SR_LUT) readonly buffer Lut { vec4 lut[]; };
layout(std430, binding = SR_OUTPUT) writeonly buffer Output { vec4 outp[]; };

vec4 load_lr_color(ivec2 q) { return unpack_color(color[q.y * int(pc.p.lr_width) + q.x]); }
float load_lr_depth(ivec2 q) { return depth[q.y * int(pc.p.lr_width) + q.x]; }
#ifdef FGSR_STATIC_TILES
// Static tiles (classify.h, sr mode): zero vectors and depths that agree with the previous frame's,
// so the history is kept and read at the pixel itself (the host sets bilinear, exact at phase 0).
vec2 load_lr_mv(ivec2 q) { return vec2(0.0f); }
float load_prev_depth(ivec2 q) { return load_lr_depth(q); }
#else
vec2 load_lr_mv(ivec2 q) { return mv[q.y * int(pc.p.lr_width) + q.x]; }
float load_prev_depth(ivec2 q) { return prev_depth[q.y * int(pc.p.lr_width) + q.x]; }
#endif
vec4 load_src(ivec2 q) { return history[q.y * int(pc.p.hr_width) + q.x]; }
vec4 load_lut4(uint row) { return lut[row]; }

#include "resample.h"
#include "sr.h"

#ifdef FGSR_TILED
layout(std430, binding = SR_COUNT + TILED_LIST) readonly buffer TileList { uint tile_list[]; };
#include "tiles.h"
#endif

void main() {
#ifdef FGSR_TILED
    ivec2 q;
    if (!listed_output_pixel(pc.p.scale, ivec2(int(pc.p.lr_width), int(pc.p.lr_height)),
                             ivec2(int(pc.p.hr_width), int(pc.p.hr_height)), q))
        return;
#else
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= int(pc.p.hr_width) || q.y >= int(pc.p.hr_height)) return;
#endif
    outp[q.y * int(pc.p.hr_width) + q.x] = super_resolve(q, pc.p);
}
