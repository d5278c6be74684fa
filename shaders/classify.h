// Pass `classify`: per-tile classification of the work a frame needs, before the expensive passes.
//
// Tiles are square, `tile` pixels a side (8, 16 or 32; the engine's default was measured, see
// docs/TILES.md), at multiples of `tile` from the top-left corner; border tiles are clipped.
//
// Generate mode (frame generation and ISR / ESR): a frame-1 pixel p is a *static source* when its
// motion to the generated instant is exactly zero under motion.h for every alpha: mv1(p) == 0 and,
// where the frame-0 vector m0 is read (quadratic model with frame-0 vectors), every frame-0 vector
// motion.h may pick is zero (p's own when its depth agrees within 4 T_D, else its 4 edge
// neighbours'); and in interpolation with frame-0 vectors, frame-0 pixel p does not splat itself
// as content leaving the frame (splat.h: m0 is zero or frame 1 shows p's frame-0 surface at p).
// Such a pixel splats onto itself, key (depth1 << 32 | index), field vectors 0. A
// tile whose pixels are all static sources is TILE_STATIC: splat runs only over the other tiles,
// and the passes after it read a static tile's key as the nearer of that own key and what splat
// left there (tiles.h, FGSR_TILED_KEYS), which is exactly the key of a full splat. Splat marks a static tile
// TILE_DIRTY when a moving source lands in it (and appends it to the generate list). Every pixel of a static
// tile that is not dirty has its own key, so refine, disocc and warp reduce to reading both frames at the
// pixel itself: the generated frame there is copy_through() below, which classify writes for every static
// pixel (the passes over the generate list overwrite moving and dirty tiles) (no motion and no depth change
// give the input colour itself; a depth or shading change without motion gives what blend would give). Depth
// changes without motion therefore need no generation either.
//
// SR mode (the `sr` pass of a frame with history): an LR pixel is static when its vector is zero
// (with dilation: every vector of its 3x3 neighbourhood, the frontmost of which sr.h uses) and its
// depth agrees with the previous frame's within T_D (no disocclusion: sr.h would keep the history).
// HR pixels over a static tile then read the history at their own position, which every
// resampling kind returns unchanged at phase 0 (the LUT's phase 0 is forced to the identity), so
// the `sr` pass runs there with zero vectors, no rejection test and a 1-tap history read.
//
// Lists: every tile list is a buffer of uint: [0..2] workgroup counts for vkCmdDispatchIndirect
// (x grows with appends; y = z = 1), [3] number of tiles, [4] tile side, [5] side of the square of
// invocations each listed tile gets (tile for LR passes, more for HR passes), [6..7] 0, then the
// tiles, packed x | y << 16 in tile units. The host writes the header before classify.
//
// Entry provides (generate mode): motion.h's loads, load_color0/1 (warp.h); (sr mode) load_mv1 =
// current vectors, load_depth1 = current depth, load_depth0 = previous depth.

// ClassifyParams, TILE_* and the list layout: common.h.

// static_source split in two for classify's wide form, which loads pixels 4 at a time: the part
// that reads only p's own values (m1 = mv1(p), d0 / d1 = depth0 / depth1 at p, m0 = mv0(p)) gives
// STATIC_NO / STATIC_YES, or STATIC_IF_NEIGHBOURS where the depths at p disagree and p is static
// exactly when static_source_neighbours(p) holds.
#define STATIC_NO 0u
#define STATIC_YES 1u
#define STATIC_IF_NEIGHBOURS 2u
FGSR_INLINE uint static_source_own(vec2 m1, float d0, float d1, vec2 m0, GenParams g) {
    if (m1 != vec2(0.0f)) return STATIC_NO;
    // A frame-0 pixel that may leave the frame splats itself (splat.h, splat_leaving): one that
    // moves where frame 1 shows another surface. (Whether it leaves the frame is not asked here.)
    if (g.extrapolate == 0u && g.frame0_has_mv != 0u && m0 != vec2(0.0f) &&
        relative_depth_difference(d0, d1) > g.t_depth)
        return STATIC_NO;
    if (g.quadratic == 0u || g.frame0_has_mv == 0u) return STATIC_YES;
    if (relative_depth_difference(d0, d1) < 4.0f * g.t_depth) return m0 == vec2(0.0f) ? STATIC_YES : STATIC_NO;
    return STATIC_IF_NEIGHBOURS;
}
FGSR_INLINE bool static_source_neighbours(ivec2 p, GenParams g) {
    for (int k = 0; k < 4; ++k) {
        ivec2 q = p + edge_neighbour_offset(k);
        if (inside(q, g) && load_mv0(q) != vec2(0.0f)) return false;
    }
    return true;
}

FGSR_INLINE bool static_source(ivec2 p, GenParams g) {
    uint own = static_source_own(load_mv1(p), load_depth0(p), load_depth1(p), load_mv0(p), g);
    return own == STATIC_IF_NEIGHBOURS ? static_source_neighbours(p, g) : own == STATIC_YES;
}

FGSR_INLINE bool static_sr_pixel(ivec2 p, ClassifyParams c) {
    if (relative_depth_difference(load_depth1(p), load_depth0(p)) > c.g.t_depth) return false;
    if (c.dilate == 0u) return load_mv1(p) == vec2(0.0f);
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = clamp(p + ivec2(x, y), ivec2(0), ivec2(int(c.g.width) - 1, int(c.g.height) - 1));
            if (load_mv1(q) != vec2(0.0f)) return false;
        }
    return true;
}

FGSR_INLINE bool static_pixel(ivec2 p, ClassifyParams c) {
    return c.mode == CLASSIFY_SR ? static_sr_pixel(p, c) : static_source(p, c.g);
}

// The splat key of a static source (splat.h's key of a pixel that lands on itself).
FGSR_INLINE uint64_t own_key(ivec2 p, GenParams g) {
    return (uint64_t(floatBitsToUint(load_depth1(p))) << 32) | uint64_t(uint(p.y) * g.width + uint(p.x));
}

// The generated frame at a pixel of a static tile that is not dirty: generate.h with the field
// sample (0, 0, 0, 0) splatted, whose warps read both frames exactly at the pixel.
// c0, d0, c1, d1: the frames' values at p.
FGSR_INLINE vec4 copy_through_values(ivec2 p, vec4 c0, float d0, vec4 c1, float d1, GenParams g) {
    if (g.extrapolate != 0u) return c1;
    vec2 d = blend_depths(d0, d1, p, g);
    return select_blend(c0, d.x, c1, d.y, FIELD_SPLATTED, g);
}
FGSR_INLINE vec4 copy_through(ivec2 p, GenParams g) {
    vec4 c1 = load_color1(p);
    if (g.extrapolate != 0u) return c1;
    return copy_through_values(p, load_color0(p), load_depth0(p), c1, load_depth1(p), g);
}

// Whether a whole tile is static (the CPU reference; the GPU entry reduces static_pixel itself).
FGSR_INLINE bool classify_tile(ivec2 tile, ClassifyParams c) {
    ivec2 lo = tile * int(c.tile);
    ivec2 hi = min(lo + ivec2(int(c.tile)), ivec2(int(c.g.width), int(c.g.height)));
    for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x)
            if (!static_pixel(ivec2(x, y), c)) return false;
    return true;
}
