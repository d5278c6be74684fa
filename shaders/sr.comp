#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { SrParams p; } pc;
// Colours, vectors, the history, the LUT and the output as 64-bit words (shaders/load64.h): half
// the accesses on CPU devices, the same bits.
layout(std430, binding = SR_COLOR) readonly buffer Color { uint64_t color[]; }; // pack_color (uvec2)
layout(std430, binding = SR_DEPTH) readonly buffer Depth { float depth[]; };
layout(std430, binding = SR_MV) readonly buffer Mv { uint64_t mv[]; }; // vec2
layout(std430, binding = SR_PREV_DEPTH) readonly buffer PrevDepth { float prev_depth[]; };
layout(std430, binding = SR_HISTORY) readonly buffer History { u64vec2 history[]; }; // vec4
layout(std430, binding = SR_LUT) readonly buffer Lut { u64vec2 lut[]; };             // vec4
layout(std430, binding = SR_OUTPUT) writeonly buffer Output { u64vec2 outp[]; };     // vec4
layout(std430, binding = SR_NOISE) buffer Noise { vec2 noise[]; };
#include "load64.h"

vec4 load_lr_color(ivec2 q) { return unpack_color(as_uvec2(color[q.y * int(pc.p.lr_width) + q.x])); }
float load_lr_depth(ivec2 q) { return depth[q.y * int(pc.p.lr_width) + q.x]; }
#ifdef FGSR_STATIC_TILES
// Static tiles (classify.h, sr mode): zero vectors and depths that agree with the previous frame's,
// so the history is kept and read at the pixel itself (the host sets bilinear, exact at phase 0).
vec2 load_lr_mv(ivec2 q) { return vec2(0.0f); }
float load_prev_depth(ivec2 q) { return load_lr_depth(q); }
#else
vec2 load_lr_mv(ivec2 q) { return as_vec2(mv[q.y * int(pc.p.lr_width) + q.x]); }
float load_prev_depth(ivec2 q) { return prev_depth[q.y * int(pc.p.lr_width) + q.x]; }
#endif
vec4 load_src(ivec2 q) { return as_vec4(history[q.y * int(pc.p.hr_width) + q.x]); }
vec4 load_lut4(uint row) { return as_vec4(lut[row]); }
vec2 load_noise(ivec2 q) { return noise[q.y * int(pc.p.lr_width) + q.x]; }

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
#ifdef FGSR_SR_NOISE_STAGE
    // The stage before the pass (variant sr_noise): one invocation per LR pixel.
    if (q.x < int(pc.p.lr_width) && q.y < int(pc.p.lr_height))
        noise[q.y * int(pc.p.lr_width) + q.x] = noise_stats(q, vec2(pc.p.jitter_x, pc.p.jitter_y), pc.p);
    return;
#endif
    if (q.x >= int(pc.p.hr_width) || q.y >= int(pc.p.hr_height)) return;
#endif
    outp[q.y * int(pc.p.hr_width) + q.x] = as_u64vec2(super_resolve(q, pc.p));
}
