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
//    taken as occluded in the previous frame (background the motion uncovered): it is background
//    for the depth proxy, and it takes, of its candidates, the one nearest the dominant motion,
//    unless its own match explains its colour far better (the candidate costs more than
//    FLOW_OCC_RATIO x its own plus FLOW_OCC_MARGIN). Uncovered background matches nothing well,
//    so there every candidate costs about the same; a pixel whose own match is good failed the
//    test through the coarser, noisier check field (an object's edge, a rotating or bobbing
//    surface) and keeps it (docs/MOTION.md, "Occluded pixels").
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
// 4. Correction (correct, Params::correct_vectors): the frame has the client's vectors and depth;
//    steps 1 and 2 only supply candidates, and a pixel's given vector is replaced where a
//    candidate explains its colour far better on the same surface, away from depth edges, with
//    its neighbours agreeing (the guards and why: docs/ACCURACY.md, change 4). No depth written.
// 5. Coarse to fine (coarse_level > 0, colour-only sessions that refine; applied before step 3):
//    the coarse levels' refined field (polish.h, polish_coarse), upsampled, replaces the choice of
//    steps 1 and 2 where it differs by more than FLOW_AGREE and costs less over the pixel's 3x3
//    neighbourhood (the previous frame read bilinearly for both): it mends regions of wrong block
//    matches that no neighbouring block can (docs/MOTION.md, "Coarse to fine").
//
// Entry provides:
//   float load_cur(uint pixel)   level-0 luma of the current frame
//   float load_prev(uint pixel)  level-0 luma of the previous frame
//   vec4  load_field(uint index) the block field
//   vec2  load_given(uint pixel) the client's vector of the current frame (read with correct only)
//   float load_depth(uint pixel), load_prev_depth(uint pixel)  depths of both frames (correct only)
//   vec2  load_field_vector(uint index) the coarse-to-fine refined field (field_read.h; read
//                                where coarse_level > 0)
//   void  store_flow(uint pixel, vec2 mv, float depth, bool write_depth)

#define FLOW_SMOOTH_BIAS 0.9f // cost factor of the bilinear candidate
#define FLOW_AGREE 0.25f     // pixels: blocks this close to their blend need no per-pixel choice
#define FLOW_PROXY_RANGE 0.04f // depth proxies lie in (1 - range, 1]
// Step 2: an occluded pixel takes the candidate nearest the dominant motion only where that
// candidate's cost is at most FLOW_OCC_RATIO x its own match's plus FLOW_OCC_MARGIN (luma).
#define FLOW_OCC_RATIO 2.0f
#define FLOW_OCC_MARGIN 0.02f
#define FLOW_EDGE_REACH 2      // correction: pixels to the depth samples of the edge test
#define FLOW_EDGE_DEPTH 0.04f  // correction: relative depth step over that reach that is an edge
#define FLOW_AGREE_NEIGHBOURS 3 // correction: of the 4 neighbours at that reach, those that must agree
// Step 5 exists only in the flow_coarse build (FGSR_FLOW_COARSE; the CPU reference reads
// p.coarse_level), for the same reason: compiled into the plain build, whose sessions never run it
// (frames above kPolishMaxPixels), its 3x3 costs made that pass about 1.3x slower at 720p.
#if defined(FGSR_FLOW_COARSE)
#define FLOW_COARSE_STEP(p) true
#elif defined(__cplusplus)
#define FLOW_COARSE_STEP(p) ((p).coarse_level > 0u)
#else
#define FLOW_COARSE_STEP(p) false
#endif
// Step 4 exists only in the flow_correct build (FGSR_FLOW_CORRECT; the CPU reference reads
// p.correct): on CPU devices a branch costs every lane whether taken or not, and compiled into the
// colour-only build it made that pass about 3x slower.
#if defined(FGSR_FLOW_CORRECT)
#define FLOW_CORRECTS(p) true
#elif defined(__cplusplus)
#define FLOW_CORRECTS(p) ((p).correct != 0u)
#else
#define FLOW_CORRECTS(p) false
#endif

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

#include "luma_read.h"

// A pixel position clamped to the frame.
FGSR_INLINE ivec2 flow_clamp(ivec2 q, FlowParams p) {
    return luma_clamp(q, p.width, p.height);
}

FGSR_INLINE float flow_luma(ivec2 q, bool prev, FlowParams p) {
    return luma_at(q, prev, p.width, p.height);
}

// Offset k (0..3: left, right, up, down) at distance r.
FGSR_INLINE ivec2 flow_cross(int k, int r) {
    return k == 0 ? ivec2(-r, 0) : (k == 1 ? ivec2(r, 0) : (k == 2 ? ivec2(0, -r) : ivec2(0, r)));
}

FGSR_INLINE float flow_cost(ivec2 q, vec2 v, FlowParams p) {
    ivec2 d = ivec2(floor(v + 0.5f));
    float s = 0.0f;
    for (int k = 0; k < 5; ++k) {
        ivec2 o = k == 0 ? ivec2(0) : flow_cross(k - 1, 1);
        s += abs(flow_luma(q + o, false, p) - flow_luma(q + o + d, true, p));
    }
    return s * 0.2f;
}

// The cost of a sub-pixel vector: as flow_cost, with the previous frame read bilinearly.
FGSR_INLINE float flow_cost_subpixel(ivec2 q, vec2 v, FlowParams p) {
    float s = 0.0f;
    for (int k = 0; k < 5; ++k) {
        ivec2 o = k == 0 ? ivec2(0) : flow_cross(k - 1, 1);
        s += abs(flow_luma(q + o, false, p) - luma_prev_bilinear(vec2(q + o) + v, p.width, p.height));
    }
    return s * 0.2f;
}

#include "field_read.h"

// The coarse field (level coarse_level, at the start of its buffer) at a position in frame pixels.
FGSR_INLINE vec2 flow_coarse(vec2 pos, FlowParams p) {
    float scale = float(1u << p.coarse_level);
    return scale * field_bilinear(pos * (1.0f / scale) - vec2(0.5f), 0u, p.coarse_width, p.coarse_height);
}

// The cost of a sub-pixel vector v over the pixel's 3x3 neighbourhood (cur: the current frame's 9
// pixels, row by row): the 9 bilinear reads of the previous frame at q + o + v, o in [-1, 1]^2,
// share one 4x4 grid of pixels and one set of weights (those of q - (1, 1) + v), so the grid is read
// once: 16 reads instead of 36.
FGSR_INLINE float flow_cost_window(float cur[9], ivec2 q, vec2 v, FlowParams p) {
    vec2 at = vec2(q - ivec2(1)) + v;
    vec2 f0 = floor(at);
    vec2 t = at - f0;
    ivec2 c = ivec2(f0);
    float grid[16];
    for (int k = 0; k < 16; ++k) grid[k] = flow_luma(c + ivec2(k & 3, k >> 2), true, p);
    float s = 0.0f;
    for (int k = 0; k < 9; ++k) {
        int g = (k / 3) * 4 + k % 3; // the grid's top-left tap of sample k
        float top = mix(grid[g], grid[g + 1], t.x);
        float bottom = mix(grid[g + 4], grid[g + 5], t.x);
        s += abs(cur[k] - mix(top, bottom, t.y));
    }
    return s * (1.0f / 9.0f);
}

// The costs of two sub-pixel vectors over the pixel's 3x3 neighbourhood (the current frame read
// once for both).
FGSR_INLINE vec2 flow_cost_window_pair(ivec2 q, vec2 a, vec2 b, FlowParams p) {
    float cur[9];
    for (int k = 0; k < 9; ++k) cur[k] = flow_luma(q + ivec2(k % 3 - 1, k / 3 - 1), false, p);
    return vec2(flow_cost_window(cur, q, a, p), flow_cost_window(cur, q, b, p));
}

// Step 4: the colour cost at pixel q that a candidate must beat, ratio x the given vector's less
// the margin (at most 0: the given vector explains the colour well enough).
FGSR_INLINE float flow_correction_bound(ivec2 q, vec2 given, FlowParams p) {
    return p.correct_ratio * flow_cost_subpixel(q, given, p) - p.correct_margin;
}

// Step 4's tests that need no candidate: the pixel's bound (flow_correction_bound), or 0 where the
// pixel keeps its given vector whatever the candidates: the given vector explains its colour, its
// previous position is not the same surface, or a depth edge is near. Run before steps 1 and 2,
// whose costs most pixels then skip.
FGSR_INLINE float flow_correction_limit(ivec2 q, vec2 pos, vec2 given, uint i, FlowParams p) {
    float limit = flow_correction_bound(q, given, p);
    if (limit <= 0.0f) return 0.0f;
    ivec2 pq = ivec2(floor(pos + given));
    if (any(lessThan(pq, ivec2(0))) || pq.x >= int(p.width) || pq.y >= int(p.height)) return 0.0f;
    float d1 = load_depth(i);
    float d0 = load_prev_depth(uint(pq.y) * p.width + uint(pq.x));
    //    The band is wide (a camera approaching the ground changes its depth by more than 10 %
    //    between frames) but one-sided in front: uncovered background's previous position shows
    //    the occluder, nearer than the pixel, at any depth ratio (a cube on the floor, seen from
    //    afar, is within 30 % of the floor behind it).
    if (!(abs(d0 - d1) <= p.correct_depth * min(d0, d1))) return 0.0f;
    if (!(d0 * (1.0f + p.correct_front) >= d1)) return 0.0f;
    //    Nor next to a depth edge of the current frame, where the colour mismatch is the edge's
    //    (antialiasing, the moving silhouette): shading moves over smooth surfaces.
    for (int k = 0; k < 4; ++k) {
        ivec2 n = flow_clamp(q + flow_cross(k, FLOW_EDGE_REACH), p);
        float dn = load_depth(uint(n.y) * p.width + uint(n.x));
        if (!(abs(dn - d1) <= FLOW_EDGE_DEPTH * min(dn, d1))) return 0.0f;
    }
    return limit;
}

FGSR_INLINE void flow_pixel(uvec2 u, FlowParams p) {
    if (u.x >= p.width || u.y >= p.height) return;
    ivec2 q = ivec2(u);
    vec2 pos = vec2(q) + 0.5f;
    uint i = u.y * p.width + u.x;
    // 4. Correction of given vectors: a candidate replaces the client's vector only where its
    //    colour match is clearly better (shading that moves on its own), and only where the given
    //    vector's previous position shows the same surface (depths agree): elsewhere a colour
    //    mismatch is a disocclusion, which the given vector describes right.
    vec2 given = vec2(0.0f);
    float limit = 0.0f;
    if (FLOW_CORRECTS(p)) {
        given = load_given(i);
        limit = flow_correction_limit(q, pos, given, i, p);
        if (limit <= 0.0f) return;
    }
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
    // The costs (flow_cost) of the chosen candidate and of the one nearest the dominant motion,
    // for the occlusion rule of step 2 (both 0 where the blocks agree: the two are the same).
    float own_cost = 0.0f, nearest_g_cost = 0.0f;
    // Where the four blocks agree (most of a frame) the blend is the answer: no costs to compare.
    if (spread > FLOW_AGREE) {
        own_cost = flow_cost(q, best, p);
        nearest_g_cost = own_cost;
        float best_cost = FLOW_SMOOTH_BIAS * own_cost;
        for (int k = 0; k < 4; ++k) {
            float cost = flow_cost(q, corner[k], p);
            if (cost < best_cost) {
                best_cost = cost;
                own_cost = cost;
                best = corner[k];
            }
            if (length(corner[k] - g) < length(nearest_g - g)) {
                nearest_g = corner[k];
                nearest_g_cost = cost;
            }
        }
    }
    vec2 back = flow_bilinear(pos + best, p.fwd_offset, p);
    bool occluded = length(best + back) > p.fb_tolerance + 0.1f * length(best);
    if (FLOW_CORRECTS(p)) {
        //    Step 4 goes on (flow_correction_limit passed). Candidates: the estimate where it passed
        //    the forward-backward test, the four block vectors where they pass it too, and without
        //    that test the screen's two rigid motions, none (shading fixed to the camera) and the
        //    dominant one (fixed to the scene).
        vec2 e = best;
        float ce = occluded ? 1e30f : flow_cost_subpixel(q, best, p);
        for (int k = 0; k < 6; ++k) {
            vec2 cand = k < 4 ? corner[k] : (k == 4 ? g : vec2(0.0f));
            float cost = flow_cost_subpixel(q, cand, p);
            if (cost < ce && k < 4) {
                vec2 cb = flow_bilinear(pos + cand, p.fwd_offset, p);
                if (length(cand + cb) > p.fb_tolerance + 0.1f * length(cand)) continue;
            }
            if (cost < ce) {
                ce = cost;
                e = cand;
            }
        }
        if (!(ce < limit)) return;
        //    And only where the neighbours (FLOW_EDGE_REACH away) agree: the estimate explains their
        //    colour better too, by the same test. Moving shading covers regions; a lone pixel whose
        //    colour some candidate happens to match better is noise.
        int agree = 0;
        for (int k = 0; k < 4; ++k) {
            ivec2 n = flow_clamp(q + flow_cross(k, FLOW_EDGE_REACH), p);
            agree += flow_cost_subpixel(n, e, p) < flow_correction_bound(n, given, p) ? 1 : 0;
        }
        if (agree >= FLOW_AGREE_NEIGHBOURS) store_flow(i, e, 0.0f, false);
        return;
    }
    vec2 v = occluded && nearest_g_cost <= FLOW_OCC_RATIO * own_cost + FLOW_OCC_MARGIN ? nearest_g : best;
    // 5. The coarse-to-fine refined field (polish.h, polish_coarse), upsampled: taken where it
    //    differs and explains the pixel's colour better (sub-pixel costs of both).
    if (FLOW_COARSE_STEP(p)) {
        vec2 cv = flow_coarse(pos, p);
        vec2 costs = flow_cost_window_pair(q, cv, v, p);
        if (length(cv - v) > FLOW_AGREE && costs.x < costs.y) v = cv;
    }
    float m = occluded ? 0.0f : max(length(v - g) - 1.0f, 0.0f);
    store_flow(i, v, 1.0f - FLOW_PROXY_RANGE * m / (m + p.depth_scale), p.write_depth != 0u);
}
