// Pass `flow`: per-pixel vectors of the current frame from the level-0 block fields, their
// forward-backward consistency, and (sessions without depth) a depth proxy. One invocation per
// pixel; writes the frame's vectors in the internal convention (pixels, y down, current ->
// previous), which the splat / refine / disocc / warp / blend passes and the SR history then use
// exactly as client vectors.
//
// 1. Densification: candidates are the vectors of the four blocks around the pixel and their
//    bilinear blend; each costs the mean absolute luma difference over the pixel's 3x3
//    neighbourhood against the previous frame at the nearest displaced pixel, and the blend wins
//    ties (FLOW_SMOOTH_BIAS): inside a block's motion the field stays smooth, at a motion boundary
//    each pixel takes the side it matches.
// 2. Consistency: the previous -> current field at the pixel's previous position should point
//    back at it. Where |v + forward(p + v)| exceeds fb_tolerance + 10 % of |v|, the pixel is
//    occluded in the previous frame (background the motion uncovered): its own match is
//    unreliable, so it takes, of its candidates, the one nearest the dominant motion.
// 3. Depth proxy (write_depth): the splat orders colliding surfaces by depth, and where there is
//    none the proxy says that what moves unlike the dominant motion (the camera's, for most
//    content) is in front: depth = 1 - FLOW_PROXY_RANGE * m / (m + depth_scale), m = max(|v -
//    global| - 1, 0). Motion within a pixel of the dominant one is background at depth 1, and so
//    are occluded pixels. The range is kept below the relative depth threshold T_D (0.05), so the
//    proxy orders the splat but never claims a depth discontinuity: the unbounded form 1 / (1 +
//    m / s), which does, measured 0.2-0.5 dB below a constant depth on every capture (the
//    disocclusion and warp tests then fire on estimation noise), while this one is level with or
//    above it (docs/MOTION.md). Why motion rather than boundaries: objects that move over a still
//    or panning background are in front of it in the content this serves, and the rule needs no
//    neighbourhood reasoning that fails on thin or textureless objects; it is wrong where the
//    background is what moves behind a still overlay (the overlay then loses collisions).
//
// Entry provides:
//   float load_cur(uint pixel)   level-0 luma of the current frame
//   float load_prev(uint pixel)  level-0 luma of the previous frame
//   vec4  load_field(uint index) the block field
//   void  store_flow(uint pixel, vec2 mv, float depth, bool write_depth)

#define FLOW_SMOOTH_BIAS 0.9f // cost factor of the bilinear candidate
#define FLOW_AGREE 0.25f     // pixels: blocks this close to their blend need no per-pixel choice
#define FLOW_PROXY_RANGE 0.04f // depth proxies lie in (1 - range, 1]

// A block's vector in pixels of the frame (blocks of a coarser level hold vectors of theirs).
FGSR_INLINE vec2 flow_block(ivec2 b, uint offset, FlowParams p) {
    b = clamp(b, ivec2(0), ivec2(int(p.blocks_x) - 1, int(p.blocks_y) - 1));
    vec4 f = load_field(offset + uint(b.y) * p.blocks_x + uint(b.x));
    return vec2(f.x, f.y) * float(1u << p.block_shift);
}

// The field at a position in pixels, bilinear between block centres.
FGSR_INLINE vec2 flow_bilinear(vec2 pos, uint offset, FlowParams p) {
    vec2 b = pos * (1.0f / float(MOTION_BLOCK << p.block_shift)) - 0.5f;
    vec2 i = floor(b);
    vec2 f = b - i;
    ivec2 c = ivec2(i);
    vec2 top = mix(flow_block(c, offset, p), flow_block(c + ivec2(1, 0), offset, p), f.x);
    vec2 bottom = mix(flow_block(c + ivec2(0, 1), offset, p), flow_block(c + ivec2(1, 1), offset, p), f.x);
    return mix(top, bottom, f.y);
}

FGSR_INLINE float flow_luma(ivec2 q, bool prev, FlowParams p) {
    q = clamp(q, ivec2(0), ivec2(int(p.width) - 1, int(p.height) - 1));
    uint i = uint(q.y) * p.width + uint(q.x);
    return prev ? load_prev(i) : load_cur(i);
}

FGSR_INLINE float flow_cost(ivec2 q, vec2 v, FlowParams p) {
    ivec2 d = ivec2(floor(v + 0.5f));
    float s = 0.0f;
    for (int k = 0; k < 5; ++k) {
        ivec2 o = k == 0 ? ivec2(0) : (k == 1 ? ivec2(-1, 0) : (k == 2 ? ivec2(1, 0) : (k == 3 ? ivec2(0, -1) : ivec2(0, 1))));
        s += abs(flow_luma(q + o, false, p) - flow_luma(q + o + d, true, p));
    }
    return s * 0.2f;
}

FGSR_INLINE void flow_pixel(uvec2 u, FlowParams p) {
    if (u.x >= p.width || u.y >= p.height) return;
    ivec2 q = ivec2(u);
    vec2 pos = vec2(q) + 0.5f;
    vec2 g = vec2(p.global_x, p.global_y);
    vec2 b = pos * (1.0f / float(MOTION_BLOCK << p.block_shift)) - 0.5f;
    vec2 fb = floor(b);
    vec2 f = b - fb;
    ivec2 c = ivec2(fb);
    vec2 corner[4];
    for (int k = 0; k < 4; ++k) corner[k] = flow_block(c + ivec2(k & 1, k >> 1), p.back_offset, p);
    vec2 best = mix(mix(corner[0], corner[1], f.x), mix(corner[2], corner[3], f.x), f.y); // flow_bilinear
    float spread = 0.0f;
    for (int k = 0; k < 4; ++k) spread = max(spread, length(corner[k] - best));
    vec2 nearest_g = best;
    // Where the four blocks agree (most of a frame) the blend is the answer: no costs to compare.
    if (spread > FLOW_AGREE) {
        float best_cost = FLOW_SMOOTH_BIAS * flow_cost(q, best, p);
        for (int k = 0; k < 4; ++k) {
            float cost = flow_cost(q, corner[k], p);
            if (cost < best_cost) {
                best_cost = cost;
                best = corner[k];
            }
            if (length(corner[k] - g) < length(nearest_g - g)) nearest_g = corner[k];
        }
    }
    vec2 back = flow_bilinear(pos + best, p.fwd_offset, p);
    bool occluded = length(best + back) > p.fb_tolerance + 0.1f * length(best);
    vec2 v = occluded ? nearest_g : best;
    float m = occluded ? 0.0f : max(length(v - g) - 1.0f, 0.0f);
    store_flow(u.y * p.width + u.x, v, 1.0f - FLOW_PROXY_RANGE * m / (m + p.depth_scale), p.write_depth != 0u);
}
