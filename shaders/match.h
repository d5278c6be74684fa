// Pass `match`: block matching on one pyramid level, one invocation per block of MOTION_BLOCK x
// MOTION_BLOCK pixels of the source frame, searching the destination frame (the host runs it
// coarse to fine, once per level and direction: current -> previous gives the vectors, previous ->
// current the field flow.h checks them against).
//
// The design follows hierarchical block matching as in FidelityFX optical flow (8x8 blocks on a
// luminance pyramid, each level seeded from the coarser one):
//   1. candidates: the zero vector (below the coarsest level at a cost bias, zero_bias);
//      the previous submit's vector of the block (motion is coherent
//      in time); below the coarsest level, twice the vectors of the parent block and of its three
//      neighbours on this block's side (so a block at a motion boundary can take the motion of
//      either side). Each level of the current -> previous field is then matched a second time
//      (propagation; the other direction only checks it, flow.h): the candidates are
//      the first pass's vectors of the block and its four neighbours, so that a good match
//      spreads along structures (poles, floors) that single blocks miss;
//   2. cost of a displacement d: mean absolute luma difference over the block (SAD / 64; or, where
//      lower, with the means removed plus light_cap x the block's mean: a local change of
//      brightness costs at most that) plus lambda x |d - prediction| (the parent's vector), which
//      keeps flat regions, where every displacement costs the same, on the coarse motion;
//   3. a full integer search of +-radius around the best candidate (the coarsest level searches
//      widely, the finer ones +-1);
//   4. sub-pixel refinement by equiangular (V-shaped) line fits through the SAD at the best
//      position and its four neighbours, the fit suited to SAD (a parabola under-shoots it).
// A block is moved inward where it would reach past the level's edge (match_origin); destination
// pixels outside the level are read at the nearest edge pixel. The field stores vec4(v, SAD,
// contrast): v in pixels of this level, from a source pixel to its position in the destination;
// SAD of the match; the block's mean absolute deviation from its mean.
//
// Entry provides:
//   float load_src(uint index)   the source pyramid
//   float load_dst(uint index)   the destination pyramid
//   vec4  load_field(uint index) the block field (coarser level)
//   void  store_field(uint index, vec4 value)

// Which candidates and stores a pass has. The GPU builds of the passes (FGSR_MATCH_KIND: 0 the
// coarsest level's first pass, 1 a first pass below it, 2 a propagation pass; FGSR_MATCH_STORE:
// its MATCH_STORE_* bits; shaders/variants.def) fix them at compile time: CPU devices run both
// sides of a branch with the inactive lanes masked off, so a pass would otherwise pay for the
// candidates and the fits of the others (the propagation's 5 candidates, the parent's 4, the
// sub-pixel fit's 4 costs and the full SAD: 32 to 64 reads each). The host picks the build from
// the parameters (daemon/engine/src/motion.cpp, match_variant); the build without
// FGSR_MATCH_KIND, and the CPU reference, read them from the parameters.
#if defined(FGSR_MATCH_KIND)
#define MATCH_PROPAGATES(p) (FGSR_MATCH_KIND == 2)
#define MATCH_BELOW_COARSEST(p) (FGSR_MATCH_KIND == 1)
#define MATCH_STORES(p, bits) ((FGSR_MATCH_STORE & (bits)) != 0u)
#else
#define MATCH_PROPAGATES(p) ((p).same_offset != MOTION_NONE)
#define MATCH_BELOW_COARSEST(p) ((p).coarse_blocks_x > 0u)
#define MATCH_STORES(p, bits) (((p).store & (bits)) != 0u)
#endif

#define MATCH_GOOD 0.003f // mean absolute luma difference of a match that needs no search
#define MATCH_STILL 1.0e-5f // ... of a block that has not changed at all: zero motion, nothing else tried

// Pixel (x, y) of the source block at origin (match_origin keeps it inside the level; read at the
// nearest edge pixel outside it).
FGSR_INLINE float match_src(ivec2 origin, int x, int y, MatchParams p) {
    ivec2 q = min(origin + ivec2(x, y), ivec2(int(p.width) - 1, int(p.height) - 1));
    return load_src(p.src_offset + uint(q.y) * p.width + uint(q.x));
}

// Pixel k (0..31) of the block's checkerboard half as match_cost holds it (blk): row y = k / 4, its
// pixels x = (y & 1) + 2i at blk[4y + i].
FGSR_INLINE float match_half_src(ivec2 origin, int k, MatchParams p) {
    int y = k >> 2;
    return match_src(origin, (y & 1) + 2 * (k & 3), y, p);
}

// The first pixel of block b. A block of the grid's last column or row that would reach past the
// level's edge is moved inward to end at it (levels above 0 are at least 16 pixels a side; a frame
// smaller than a block keeps it at 0, its pixels past the edge read at the nearest edge pixel), so
// that every pixel its cost compares is the frame's own. Read at the nearest edge pixel instead, the
// rows or columns past the edge would all repeat the last one, and so would the destination's under
// any displacement that points out of the frame there: such displacements matched those rows for
// nothing, and the blocks along the bottom edge of a camera moving forward (whose content comes
// from above) took them (docs/MOTION.md, "Blocks at the frame's edge").
FGSR_INLINE ivec2 match_origin(uvec2 b, MatchParams p) {
    ivec2 last = max(ivec2(int(p.width), int(p.height)) - int(MOTION_BLOCK), ivec2(0));
    return min(ivec2(b) * int(MOTION_BLOCK), last);
}

// Whether block c lies in the level's block grid.
FGSR_INLINE bool match_inside(ivec2 c, MatchParams p) {
    return c.x >= 0 && c.y >= 0 && c.x < int(p.blocks_x) && c.y < int(p.blocks_y);
}

// The block's contrast (mean absolute deviation): what a cut's mismatch is measured against, and
// what tells the fill stage which blocks have texture.
FGSR_INLINE float match_contrast(ivec2 origin, MatchParams p) {
    float mean = 0.0f;
    FGSR_UNROLL for (int k = 0; k < 64; ++k) mean += match_src(origin, k & 7, k >> 3, p);
    mean *= 1.0f / 64.0f;
    float contrast = 0.0f;
    FGSR_UNROLL for (int k = 0; k < 64; ++k) contrast += abs(match_src(origin, k & 7, k >> 3, p) - mean);
    return contrast * (1.0f / 64.0f);
}

FGSR_INLINE float match_dst(ivec2 q, MatchParams p) {
    q = clamp(q, ivec2(0), ivec2(int(p.width) - 1, int(p.height) - 1));
    return load_dst(p.dst_offset + uint(q.y) * p.width + uint(q.x));
}

// The mean of a block's checkerboard half (blk).
FGSR_INLINE float match_half_mean(float blk[32]) {
    float m = 0.0f;
    FGSR_UNROLL for (int k = 0; k < 32; ++k) m += blk[k];
    return m * (1.0f / 32.0f);
}

// The cost of displacement d: the mean absolute difference over the block's checkerboard half (32
// pixels, held in blk: row y's pixels x = (y & 1) + 2i at blk[4y + i]; half the reads, and a
// displacement that fits one half of an 8x8 block fits the other), or, where lower, the same with
// the two halves' means removed plus p.light_cap times the block's mean: a change of the block's
// brightness between the frames (a light or a shadow falling on it, a surface nearing a lamp)
// costs at most that, however large (a negative light_cap: the plain cost only). Without it, on
// dark content of little texture the brightness change outweighs the texture, and the match goes
// wherever the mean brightness fits (docs/MOTION.md, "Local changes of brightness"). Only this
// half is kept in registers: 64 live values made llvmpipe's register allocation take seconds per
// build.
FGSR_INLINE float match_cost(float blk[32], ivec2 origin, ivec2 d, MatchParams p) {
    float ms = match_half_mean(blk);
    float off = 0.0f;
    if (p.light_cap >= 0.0f) { // the candidate's mean: only the capped cost needs it (a uniform branch)
        float mv = 0.0f;
        FGSR_UNROLL for (int y = 0; y < 8; ++y)
            FGSR_UNROLL for (int x = y & 1; x < 8; x += 2) mv += match_dst(origin + ivec2(x, y) + d, p);
        off = ms - mv * (1.0f / 32.0f);
    }
    float s = 0.0f, z = 0.0f;
    FGSR_UNROLL for (int y = 0; y < 8; ++y)
        FGSR_UNROLL for (int x = y & 1; x < 8; x += 2) {
            float v = match_dst(origin + ivec2(x, y) + d, p);
            z += abs(blk[y * 4 + (x >> 1)] - off - v);
            s += abs(blk[y * 4 + (x >> 1)] - v);
        }
    float cost = s * (1.0f / 32.0f);
    return p.light_cap >= 0.0f ? min(cost, z * (1.0f / 32.0f) + p.light_cap * ms) : cost;
}

// Mean absolute difference of the whole block against the destination at origin + d.
FGSR_INLINE float match_sad(ivec2 origin, ivec2 d, MatchParams p) {
    float s = 0.0f;
    FGSR_UNROLL for (int y = 0; y < 8; ++y)
        FGSR_UNROLL for (int x = 0; x < 8; ++x) s += abs(match_src(origin, x, y, p) - match_dst(origin + ivec2(x, y) + d, p));
    return s * (1.0f / 64.0f);
}

FGSR_INLINE vec2 match_same(ivec2 c, uint offset, MatchParams p) {
    c = clamp(c, ivec2(0), ivec2(int(p.blocks_x) - 1, int(p.blocks_y) - 1));
    vec4 f = load_field(offset + uint(c.y) * p.blocks_x + uint(c.x));
    return vec2(f.x, f.y);
}

FGSR_INLINE vec2 match_coarse(ivec2 c, MatchParams p) {
    c = clamp(c, ivec2(0), ivec2(int(p.coarse_blocks_x) - 1, int(p.coarse_blocks_y) - 1));
    vec4 f = load_field(p.coarse_offset + uint(c.y) * p.coarse_blocks_x + uint(c.x));
    return 2.0f * vec2(f.x, f.y);
}

// Offset in (-0.5, 0.5) of the minimum of a V through (-1, cm), (0, c0), (1, cp), c0 the smallest.
FGSR_INLINE float match_subpixel(float cm, float c0, float cp) {
    float slope = max(cm, cp) - c0;
    return slope > 1.0e-7f ? clamp(0.5f * (cm - cp) / slope, -0.5f, 0.5f) : 0.0f;
}

#if defined(FGSR_MATCH_RADIUS)
// One candidate's terms of one block row: its four checkerboard pixels b0..b3, less the offset o
// between the two halves' means, against the destination pixels v0..v3 it compares them with,
// added to acc in match_cost's order.
FGSR_INLINE float match_row_terms(float acc, float b0, float b1, float b2, float b3, float o, float v0, float v1,
                                  float v2, float v3) {
    acc += abs(b0 - o - v0);
    acc += abs(b1 - o - v1);
    acc += abs(b2 - o - v2);
    acc += abs(b3 - o - v3);
    return acc;
}
// The same without the offset.
FGSR_INLINE float match_row_plain(float acc, float b0, float b1, float b2, float b3, float v0, float v1, float v2,
                                  float v3) {
    acc += abs(b0 - v0);
    acc += abs(b1 - v1);
    acc += abs(b2 - v2);
    acc += abs(b3 - v3);
    return acc;
}
// The sum of the destination pixels v0..v3 one candidate compares, added to acc in match_cost's order.
FGSR_INLINE float match_row_sum(float acc, float v0, float v1, float v2, float v3) {
    acc += v0;
    acc += v1;
    acc += v2;
    acc += v3;
    return acc;
}
#endif

#if defined(FGSR_MATCH_RADIUS) && FGSR_MATCH_RADIUS == 1
// One block row's terms of the costs of the three horizontally adjacent candidates dx = -1, 0, 1
// (acc.x, .y, .z; acc.w and e unused): the row's four checkerboard pixels b0..b3 against the 9
// destination pixels from `at` on (the row's first checkerboard pixel displaced by the centre,
// minus 1), each read once. With `sums`, each candidate's sum of those pixels instead (b0..b3 and
// o unused); else the terms less each candidate's offset o between the means (acc) and, in pl, the
// plain terms (match_cost's two sums).
FGSR_INLINE vec4 match_row(float b0, float b1, float b2, float b3, ivec2 at, vec4 acc, inout float e, vec4 o, float oe,
                           bool sums, inout vec4 pl, inout float ple, MatchParams p) {
    float v0 = match_dst(at, p), v1 = match_dst(at + ivec2(1, 0), p), v2 = match_dst(at + ivec2(2, 0), p);
    float v3 = match_dst(at + ivec2(3, 0), p), v4 = match_dst(at + ivec2(4, 0), p), v5 = match_dst(at + ivec2(5, 0), p);
    float v6 = match_dst(at + ivec2(6, 0), p), v7 = match_dst(at + ivec2(7, 0), p), v8 = match_dst(at + ivec2(8, 0), p);
    if (sums) {
        acc.x = match_row_sum(acc.x, v0, v2, v4, v6);
        acc.y = match_row_sum(acc.y, v1, v3, v5, v7);
        acc.z = match_row_sum(acc.z, v2, v4, v6, v8);
        return acc;
    }
    acc.x = match_row_terms(acc.x, b0, b1, b2, b3, o.x, v0, v2, v4, v6);
    acc.y = match_row_terms(acc.y, b0, b1, b2, b3, o.y, v1, v3, v5, v7);
    acc.z = match_row_terms(acc.z, b0, b1, b2, b3, o.z, v2, v4, v6, v8);
    pl.x = match_row_plain(pl.x, b0, b1, b2, b3, v0, v2, v4, v6);
    pl.y = match_row_plain(pl.y, b0, b1, b2, b3, v1, v3, v5, v7);
    pl.z = match_row_plain(pl.z, b0, b1, b2, b3, v2, v4, v6, v8);
    return acc;
}
#elif defined(FGSR_MATCH_RADIUS) && FGSR_MATCH_RADIUS == 2
// The same for the five candidates dx = -2 .. 2 (acc.x .. acc.w, then e): 11 destination pixels
// from `at` (the row's first checkerboard pixel displaced by the centre, minus 2).
FGSR_INLINE vec4 match_row(float b0, float b1, float b2, float b3, ivec2 at, vec4 acc, inout float e, vec4 o, float oe,
                           bool sums, inout vec4 pl, inout float ple, MatchParams p) {
    float v0 = match_dst(at, p), v1 = match_dst(at + ivec2(1, 0), p), v2 = match_dst(at + ivec2(2, 0), p);
    float v3 = match_dst(at + ivec2(3, 0), p), v4 = match_dst(at + ivec2(4, 0), p), v5 = match_dst(at + ivec2(5, 0), p);
    float v6 = match_dst(at + ivec2(6, 0), p), v7 = match_dst(at + ivec2(7, 0), p), v8 = match_dst(at + ivec2(8, 0), p);
    float v9 = match_dst(at + ivec2(9, 0), p), v10 = match_dst(at + ivec2(10, 0), p);
    if (sums) {
        acc.x = match_row_sum(acc.x, v0, v2, v4, v6);
        acc.y = match_row_sum(acc.y, v1, v3, v5, v7);
        acc.z = match_row_sum(acc.z, v2, v4, v6, v8);
        acc.w = match_row_sum(acc.w, v3, v5, v7, v9);
        e = match_row_sum(e, v4, v6, v8, v10);
        return acc;
    }
    acc.x = match_row_terms(acc.x, b0, b1, b2, b3, o.x, v0, v2, v4, v6);
    acc.y = match_row_terms(acc.y, b0, b1, b2, b3, o.y, v1, v3, v5, v7);
    acc.z = match_row_terms(acc.z, b0, b1, b2, b3, o.z, v2, v4, v6, v8);
    acc.w = match_row_terms(acc.w, b0, b1, b2, b3, o.w, v3, v5, v7, v9);
    e = match_row_terms(e, b0, b1, b2, b3, oe, v4, v6, v8, v10);
    pl.x = match_row_plain(pl.x, b0, b1, b2, b3, v0, v2, v4, v6);
    pl.y = match_row_plain(pl.y, b0, b1, b2, b3, v1, v3, v5, v7);
    pl.z = match_row_plain(pl.z, b0, b1, b2, b3, v2, v4, v6, v8);
    pl.w = match_row_plain(pl.w, b0, b1, b2, b3, v3, v5, v7, v9);
    ple = match_row_plain(ple, b0, b1, b2, b3, v4, v6, v8, v10);
    return acc;
}
#endif

// The best candidate so far.
struct MatchSearch {
    ivec2 best;
    float cost; // match cost plus the regularising term
    float raw;  // match cost
};

// The cost a search compares: the match cost r of displacement d, the regularising term toward
// pred, and below the coarsest level the zero displacement's bias (MatchParams::zero_bias).
FGSR_INLINE float match_total(float r, ivec2 d, vec2 pred, MatchParams p) {
    return r + p.lambda * length(vec2(d) - pred) + (d == ivec2(0) ? p.zero_bias : 0.0f);
}

// Keeps displacement d, of match cost r, when its cost (match cost plus the regularising term toward
// pred) is lower than the best so far's.
FGSR_INLINE MatchSearch match_keep(float r, ivec2 d, vec2 pred, MatchSearch s, MatchParams p) {
    float cost = match_total(r, d, pred, p);
    if (cost < s.cost) {
        s.cost = cost;
        s.raw = r;
        s.best = d;
    }
    return s;
}

// Tries displacement d against the best so far (match_keep); the best itself is not evaluated again.
FGSR_INLINE MatchSearch match_try(float blk[32], ivec2 origin, ivec2 d, vec2 pred, MatchSearch s, MatchParams p) {
    if (d == s.best) return s;
    return match_keep(match_cost(blk, origin, d, p), d, pred, s, p);
}

FGSR_INLINE void match_block(uvec2 b, MatchParams p) {
    if (b.x >= p.blocks_x || b.y >= p.blocks_y) return;
    ivec2 origin = match_origin(b, p);
    float blk[32];
    FGSR_UNROLL for (int k = 0; k < 32; ++k) blk[k] = match_half_src(origin, k, p);
    uint at = p.field_offset + b.y * p.blocks_x + b.x;
    // Each candidate's cost is evaluated once: `raw` keeps the best one's match cost, so that a new
    // prediction only changes the regularising term.
    vec2 pred = vec2(0.0f);
    if (MATCH_PROPAGATES(p)) pred = match_same(ivec2(b), p.same_offset, p);
    MatchSearch s;
    s.best = ivec2(0);
    s.raw = match_cost(blk, origin, s.best, p);
    if (s.raw <= MATCH_STILL) { // an unchanged block (a still part of the scene): zero, nothing tried
        store_field(
            at, vec4(0.0f, 0.0f, s.raw, MATCH_STORES(p, MATCH_STORE_CONTRAST) ? match_contrast(origin, p) : 0.0f));
        return;
    }
    s.cost = match_total(s.raw, s.best, pred, p);
    // The candidates, in this order (one loop, so that the block cost is compiled once, not once
    // per candidate: llvmpipe compiles a pipeline at its first dispatch, and sixteen inlined
    // 32-read costs took it seconds per build):
    //   propagation: this block's own first-pass vector and its four neighbours', so that a good
    //     match spreads along a structure (a pole, a floor) that single blocks miss;
    //   the previous submit's vector of this block (motion is coherent in time);
    //   below the coarsest level, twice the vectors of the parent block and of its three
    //     neighbours on this block's side; from the first of them on, the prediction is the
    //     parent's vector.
    int n_same = MATCH_PROPAGATES(p) ? 5 : 0;
    int n_temporal = p.temporal_offset != MOTION_NONE ? 1 : 0;
    int n_coarse = MATCH_BELOW_COARSEST(p) ? 4 : 0;
    ivec2 parent = ivec2(b) / 2;
    ivec2 side = ivec2((b.x & 1u) != 0u ? 1 : -1, (b.y & 1u) != 0u ? 1 : -1);
    vec2 pred_coarse = n_coarse != 0 ? match_coarse(parent, p) : vec2(0.0f);
    FGSR_DONT_UNROLL for (int k = 0; k < n_same + n_temporal + n_coarse; ++k) {
        ivec2 c = ivec2(b);
        uint offset = p.same_offset;
        uvec2 dims = uvec2(p.blocks_x, p.blocks_y);
        float scale = 1.0f;
        if (k < n_same) {
            c += k == 0 ? ivec2(0) : (k == 1 ? ivec2(-1, 0) : (k == 2 ? ivec2(1, 0) : (k == 3 ? ivec2(0, -1) : ivec2(0, 1))));
        } else if (k < n_same + n_temporal) {
            offset = p.temporal_offset;
        } else {
            int j = k - n_same - n_temporal;
            if (j == 0) {
                pred = pred_coarse;
                s.cost = match_total(s.raw, s.best, pred, p);
            }
            c = parent + ivec2((j & 1) != 0 ? side.x : 0, (j & 2) != 0 ? side.y : 0);
            offset = p.coarse_offset;
            dims = uvec2(p.coarse_blocks_x, p.coarse_blocks_y);
            scale = 2.0f;
        }
        c = clamp(c, ivec2(0), ivec2(dims) - 1);
        vec4 f = load_field(offset + uint(c.y) * dims.x + uint(c.x));
        s = match_try(blk, origin, ivec2(floor(scale * vec2(f.x, f.y) + 0.5f)), pred, s, p);
    }
    // Then, in one more loop: a candidate that already matches to within MATCH_GOOD needs no
    // search around it (most blocks of a smooth motion, after the first levels), else the full
    // integer search of +-radius around it (below the coarsest level a zero best always has its
    // neighbourhood searched: its bias exceeds MATCH_GOOD); then the sub-pixel fit's four costs
    // around the best.
    int w = 2 * p.radius + 1;
    int n_search = s.cost >= MATCH_GOOD ? w * w - 1 : 0;
    int n_fit = MATCH_STORES(p, MATCH_STORE_SUBPIXEL) ? 4 : 0;
    ivec2 centre = s.best;
    // Builds whose radius is fixed (FGSR_MATCH_RADIUS; the host picks them only for passes of that
    // radius) search a row of candidates at a time: the 2R + 1 candidates of a row compare each
    // block row with the same 8 + 2R destination pixels, which match_row reads once
    // for all of them (9 reads instead of 12 at R = 1, 11 instead of 20 at R = 2). Each cost adds the
    // same terms in the same order as match_cost, and the candidates are tried in the loop's order
    // below (row-major, the centre skipped: it is the best so far), so the choice is the loop's, bit
    // for bit (Motion.GpuPassesMatchTheCpuReferenceAboveTheHalfResolutionThreshold). The generic
    // build and the CPU reference run the loop.
#if defined(FGSR_MATCH_RADIUS)
    if (n_search > 0) {
        float ms = match_half_mean(blk);
        FGSR_UNROLL for (int dy = -FGSR_MATCH_RADIUS; dy <= FGSR_MATCH_RADIUS; ++dy) {
            // The candidates' means first (the same reads; only for the capped cost), then both
            // sums of each.
            vec4 o = vec4(0.0f), z = vec4(0.0f), pl = vec4(0.0f);
            float oe = 0.0f, ze = 0.0f, ple = 0.0f;
            if (p.light_cap >= 0.0f) {
                FGSR_UNROLL for (int y = 0; y < 8; ++y)
                    o = match_row(0.0f, 0.0f, 0.0f, 0.0f,
                                  origin + centre + ivec2((y & 1) - FGSR_MATCH_RADIUS, y + dy), o, oe, vec4(0.0f),
                                  0.0f, true, pl, ple, p);
                o = vec4(ms) - o * (1.0f / 32.0f);
                oe = ms - oe * (1.0f / 32.0f);
            }
            FGSR_UNROLL for (int y = 0; y < 8; ++y)
                z = match_row(blk[y * 4], blk[y * 4 + 1], blk[y * 4 + 2], blk[y * 4 + 3],
                              origin + centre + ivec2((y & 1) - FGSR_MATCH_RADIUS, y + dy), z, ze, o, oe, false,
                              pl, ple, p);
            FGSR_UNROLL for (int c = 0; c < 2 * FGSR_MATCH_RADIUS + 1; ++c) {
                ivec2 d = centre + ivec2(c - FGSR_MATCH_RADIUS, dy);
                float r = c == 0 ? pl.x : (c == 1 ? pl.y : (c == 2 ? pl.z : (c == 3 ? pl.w : ple)));
                float rz = c == 0 ? z.x : (c == 1 ? z.y : (c == 2 ? z.z : (c == 3 ? z.w : ze)));
                r *= 1.0f / 32.0f;
                if (p.light_cap >= 0.0f) r = min(r, rz * (1.0f / 32.0f) + p.light_cap * ms);
                if (d != centre) s = match_keep(r, d, pred, s, p);
            }
        }
    }
    n_search = 0;
#endif
    vec4 fit = vec4(0.0f); // costs at best - (1, 0), + (1, 0), - (0, 1), + (0, 1)
    FGSR_DONT_UNROLL for (int k = 0; k < n_search + n_fit; ++k) {
        if (k < n_search) {
            int i = k < (w * w - 1) / 2 ? k : k + 1; // row-major over the square, its centre skipped
            s = match_try(blk, origin, centre + ivec2(i % w - p.radius, i / w - p.radius), pred, s, p);
        } else {
            int j = k - n_search;
            ivec2 d = s.best + (j == 0 ? ivec2(-1, 0) : (j == 1 ? ivec2(1, 0) : (j == 2 ? ivec2(0, -1) : ivec2(0, 1))));
            float r = match_cost(blk, origin, d, p);
            if (j == 0) fit.x = r;
            else if (j == 1) fit.y = r;
            else if (j == 2) fit.z = r;
            else fit.w = r;
        }
    }
    float contrast = MATCH_STORES(p, MATCH_STORE_CONTRAST) ? match_contrast(origin, p) : 0.0f;
    float z = MATCH_STORES(p, MATCH_STORE_SAD) ? match_sad(origin, s.best, p) : s.raw;
    if (!MATCH_STORES(p, MATCH_STORE_SUBPIXEL)) {
        store_field(at, vec4(vec2(s.best), z, contrast));
        return;
    }
    float sx = match_subpixel(fit.x, s.raw, fit.y);
    float sy = match_subpixel(fit.z, s.raw, fit.w);
    vec2 v = vec2(s.best) + vec2(sx, sy);
    store_field(at, vec4(v, z, contrast));
}

// Stage fill (the match_fill build, after the finest matched level): blocks without texture
// (contrast below MOTION_FILL_CONTRAST: flat walls, sky, the inside of checker squares) match
// every displacement about equally, so their vectors are noise. They take the mean of the vectors
// of the textured blocks within MOTION_FILL_RADIUS blocks, weighted by (contrast -
// MOTION_FILL_CONTRAST)^2; with none, they keep their own. Textured blocks take the component-wise
// median of their 3x3 neighbourhood: it drops isolated wrong matches and keeps motion boundaries
// (a 5x5 median lowered the EPE further but lost 0.7 dB on toss-fg: it eats small movers' edges).
// Reads the level's final blocks (same_offset), writes field_offset.
#define MOTION_FILL_CONTRAST 0.01f
#define MOTION_FILL_RADIUS 3

FGSR_INLINE void fill_block(uvec2 b, MatchParams p) {
    if (b.x >= p.blocks_x || b.y >= p.blocks_y) return;
    vec4 own = load_field(p.same_offset + b.y * p.blocks_x + b.x);
    vec4 result = own;
    if (own.w < MOTION_FILL_CONTRAST) {
        vec2 sum = vec2(0.0f);
        float weight = 0.0f;
        for (int y = -MOTION_FILL_RADIUS; y <= MOTION_FILL_RADIUS; ++y)
            for (int x = -MOTION_FILL_RADIUS; x <= MOTION_FILL_RADIUS; ++x) {
                ivec2 c = ivec2(b) + ivec2(x, y);
                if (!match_inside(c, p)) continue;
                vec4 f = load_field(p.same_offset + uint(c.y) * p.blocks_x + uint(c.x));
                float t = max(f.w - MOTION_FILL_CONTRAST, 0.0f);
                sum += t * t * vec2(f.x, f.y);
                weight += t * t;
            }
        if (weight > 1.0e-8f) result = vec4(sum / weight, own.z, own.w);
    } else { // textured: the component-wise median of the 3x3 blocks (isolated wrong matches)
        float xs[9];
        float ys[9];
        bool all[9];
        for (int k = 0; k < 9; ++k) {
            ivec2 c = clamp(ivec2(b) + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0),
                            ivec2(int(p.blocks_x) - 1, int(p.blocks_y) - 1));
            vec4 f = load_field(p.same_offset + uint(c.y) * p.blocks_x + uint(c.x));
            xs[k] = f.x;
            ys[k] = f.y;
            all[k] = true;
        }
        result = vec4(median9(xs, all, 9), median9(ys, all, 9), own.z, own.w);
    }
    store_field(p.field_offset + b.y * p.blocks_x + b.x, result);
}

// Stages ambiguity and consensus (the match_ambiguity and match_consensus builds; once after the
// propagation pass of every level but the finest; Params::motion_consensus): a periodic
// texture (a checker, stripes, tiles) matches one period off about as well as at its motion, and
// on the integer grid of a coarse level the wrong period can even match better; the temporal
// candidate then carries such a lock from frame to frame and the finer levels keep it
// (docs/MOTION.md, "The consensus of unambiguous blocks"). Costs are match_cost's, over the
// block's checkerboard half (a quarter of a full-block SAD's reads; the train captures scored the
// same). Each block is one of three kinds:
//   - unreliable: its own match is poor against its texture (cost above MATCH_CONSENSUS_RELIABLE x
//     the half's contrast: shading that moves on its own, blades thinner than a block, an
//     occlusion): it keeps its vector and does not vote (without this, a moving shadow's blocks
//     took the still ground's motion: sundial and rotor of the train set lost 0.15-0.56 dB);
//   - ambiguous: a vector of a block within MATCH_CONSENSUS_RADIUS that lies more than
//     MATCH_CONSENSUS_NEAR texels from its own matches it about as well (cost within
//     MATCH_CONSENSUS_RATIO x its own + MATCH_CONSENSUS_SLACK);
//   - unambiguous: the others; they vote.
// An ambiguous block takes, among its own vector and the vectors of the blocks within the radius
// that match it about as well, the one that the most unambiguous blocks within the radius agree with
// (within MATCH_CONSENSUS_NEAR), keeping its sub-texel fraction; the first such in scan order, its
// own on a tie. Vectors are compared rounded to the integer grid, as the next level's candidates
// read them.
// ambiguity: the level's final blocks at field_offset in, their copy at same_offset (the level's
// first-pass region, which the propagation has finished with) out: z the alternatives' bound, w 0
// unambiguous, 1 ambiguous, 2 unreliable. consensus: the copy in, the level's final blocks out (w
// 0: no level but the finest stores a contrast).
#define MATCH_CONSENSUS_RADIUS 2
#define MATCH_CONSENSUS_RATIO 1.25f
#define MATCH_CONSENSUS_SLACK 0.005f
#define MATCH_CONSENSUS_NEAR 1.5f
#define MATCH_CONSENSUS_RELIABLE 0.5f

FGSR_INLINE ivec2 match_rounded(vec4 f) {
    return ivec2(floor(vec2(f.x, f.y) + 0.5f));
}

// Neighbour k (0 .. (2R + 1)^2 - 1, row-major, b itself in the middle) of block b within
// MATCH_CONSENSUS_RADIUS R; match_inside says whether it is in the grid.
FGSR_INLINE ivec2 consensus_neighbour(ivec2 b, int k) {
    int w = 2 * MATCH_CONSENSUS_RADIUS + 1;
    return b + ivec2(k % w, k / w) - MATCH_CONSENSUS_RADIUS;
}
#define MATCH_CONSENSUS_NEIGHBOURS ((2 * MATCH_CONSENSUS_RADIUS + 1) * (2 * MATCH_CONSENSUS_RADIUS + 1))

// The mean absolute deviation of a block's checkerboard half (match_cost's blk) from its mean.
FGSR_INLINE float match_half_contrast(float blk[32]) {
    float mean = 0.0f;
    FGSR_UNROLL for (int k = 0; k < 32; ++k) mean += blk[k];
    mean *= 1.0f / 32.0f;
    float contrast = 0.0f;
    FGSR_UNROLL for (int k = 0; k < 32; ++k) contrast += abs(blk[k] - mean);
    return contrast * (1.0f / 32.0f);
}

FGSR_INLINE void ambiguity_block(uvec2 b, MatchParams p) {
    if (b.x >= p.blocks_x || b.y >= p.blocks_y) return;
    vec4 own = load_field(p.field_offset + b.y * p.blocks_x + b.x);
    ivec2 v = match_rounded(own);
    ivec2 origin = match_origin(b, p);
    float blk[32];
    FGSR_UNROLL for (int k = 0; k < 32; ++k) blk[k] = match_half_src(origin, k, p);
    float contrast = match_half_contrast(blk);
    float cost = match_cost(blk, origin, v, p);
    // The copy's z: the alternatives' bound.
    float limit = MATCH_CONSENSUS_RATIO * cost + MATCH_CONSENSUS_SLACK;
    float kind = 0.0f;
    if (cost > MATCH_CONSENSUS_RELIABLE * contrast) kind = 2.0f; // unreliable
    FGSR_DONT_UNROLL for (int k = 0; k < MATCH_CONSENSUS_NEIGHBOURS && kind == 0.0f; ++k) {
        ivec2 c = consensus_neighbour(ivec2(b), k);
        if (!match_inside(c, p)) continue;
        ivec2 u = match_rounded(load_field(p.field_offset + uint(c.y) * p.blocks_x + uint(c.x)));
        // Only a far alternative makes a block ambiguous (the block itself is never one).
        if (length(vec2(u - v)) <= MATCH_CONSENSUS_NEAR) continue;
        if (match_cost(blk, origin, u, p) <= limit) kind = 1.0f;
    }
    store_field(p.same_offset + b.y * p.blocks_x + b.x, vec4(own.x, own.y, limit, kind));
}

// How many unambiguous blocks within the radius of block b have a vector within
// MATCH_CONSENSUS_NEAR of u (the copy at same_offset).
FGSR_INLINE int consensus_support(ivec2 b, ivec2 u, MatchParams p) {
    int support = 0;
    FGSR_DONT_UNROLL for (int k = 0; k < MATCH_CONSENSUS_NEIGHBOURS; ++k) {
        ivec2 c = consensus_neighbour(b, k);
        if (!match_inside(c, p)) continue;
        vec4 f = load_field(p.same_offset + uint(c.y) * p.blocks_x + uint(c.x));
        if (f.w == 0.0f && length(vec2(f.x, f.y) - vec2(u)) <= MATCH_CONSENSUS_NEAR) ++support;
    }
    return support;
}

FGSR_INLINE void consensus_block(uvec2 b, MatchParams p) {
    if (b.x >= p.blocks_x || b.y >= p.blocks_y) return;
    uint at = b.y * p.blocks_x + b.x;
    vec4 copy = load_field(p.same_offset + at);
    vec4 own = load_field(p.field_offset + at); // this invocation's own block: no other reads it
    vec4 result = vec4(own.x, own.y, own.z, 0.0f);
    if (copy.w == 1.0f) {
        ivec2 v = match_rounded(copy);
        ivec2 origin = match_origin(b, p);
        ivec2 best = v;
        int best_support = consensus_support(ivec2(b), v, p);
        float blk[32];
        bool read = false; // blk, read at the first candidate that needs its cost
        // The alternatives in scan order; the cost only for a vector with more support than the
        // best so far (it alone could replace it).
        FGSR_DONT_UNROLL for (int k = 0; k < MATCH_CONSENSUS_NEIGHBOURS; ++k) {
            ivec2 c = consensus_neighbour(ivec2(b), k);
            if (!match_inside(c, p)) continue;
            ivec2 u = match_rounded(load_field(p.same_offset + uint(c.y) * p.blocks_x + uint(c.x)));
            int support = consensus_support(ivec2(b), u, p);
            if (support <= best_support) continue;
            if (!read) {
                FGSR_UNROLL for (int j = 0; j < 32; ++j) blk[j] = match_half_src(origin, j, p);
                read = true;
            }
            if (match_cost(blk, origin, u, p) <= copy.z) {
                best = u;
                best_support = support;
            }
        }
        if (best != v) result = vec4(vec2(best) + (vec2(own.x, own.y) - vec2(v)), own.z, 0.0f);
    }
    store_field(p.field_offset + at, result);
}
