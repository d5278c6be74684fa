// Pass `splat` (paper 3.3): every frame-1 pixel writes itself to the nearest pixel of its position
// at the generated time. Conflicts resolve toward the nearest depth with one 64-bit atomicMin on
// (depth bits << 32 | source index): positive float bits order like the floats, and the source
// index breaks ties deterministically. Positions off screen are dropped, never wrapped. Every
// source also stores its motion (m1, m0) as motion.h chose it (m0: the vector under its frame-0
// position, or m1 where the model falls back to uniform velocity), from which the later passes
// recompute a splatted pixel's field vectors (motion.h, source_field_vectors) without the
// frame-0 search.
//
// One dispatch splats up to FGSR_SPLAT_ALPHAS generated frames of the same pair (the alphas of one
// call): the alpha-independent part (the source's vectors, motion.h's frame-0 search, its depth,
// its motion) is read, computed and stored once per source pixel, then each alpha gets its own key
// (slice k of the keys).
//
// Entry provides (besides motion.h's loads):
//   uint  splat_count()        alphas of this dispatch
//   float splat_alpha(uint k)  alpha k (the generated time as GenParams::alpha means it)
//   void  splat_min(uint slice, uint target_index, uint64_t key)
//   void  store_source_motion(uint source_index, vec4 motion)  (m1, m0)

// Interpolation: frame-0 content that leaves the frame before frame 1 has no frame-1 pixel to
// splat it, so its frame-0 pixel p0 splats itself, keyed as source frame_pixels(g) + p0 and moved
// as motion.h's leaving_field_vectors says (docs/ACCURACY.md, changes 29 and 30). Its depth in
// the key is raised by T_D, so that frame 1's own splat of the same surface wins over the copy.
// Two kinds, by what frame 1 shows at p0:
// - Another surface (depths differ by more than T_D): the content has moved on, at its frame-0
//   velocity (uniform: its frame-1 velocity is unknown). Splatted only where it lies in front of
//   what frame 1 shows at the landing pixel: a near post crossing the edge covers the background
//   until it has gone. (Frame-0 vectors that are a cut's reprojection leave frame 1 showing the
//   same surfaces at p0, so they move nothing out this way.)
// - The same surface, with frame 1's velocity at p0: the background leaving the frame's edge,
//   which no frame-1 pixel shows at alpha (the edge's holes). Only where the motion is nearly
//   uniform, in time (u1 against u0) and along the way (frame 1's vector where it lands against
//   u1), within 0.5 px + a tenth of |u1|: an accelerating, expanding field (a camera approaching
//   a wall) is left to the hole fill (disocc.h), whose neighbour's motion follows it better.
FGSR_INLINE bool leaving_uniform(vec2 a, vec2 b) {
    return length(a - b) <= 0.5f + 0.1f * length(b);
}
// d1 and m1: frame 1's depth and forward motion (-mv1) at the same pixel, which splat_pixel has read.
FGSR_INLINE void splat_leaving(ivec2 p0, float d1, vec2 m1, GenParams g) {
    vec2 u0 = -load_mv0(p0);
    float d = load_depth0(p0);
    bool same = leaving_same_surface(d, d1, g);
    vec2 u1 = same ? m1 : u0;
    if (same && !leaving_uniform(u0, u1)) return;
    vec2 c0 = vec2(p0) + vec2(0.5f);
    if (on_screen(c0 + u1, g)) return;
    uint src = frame_pixels(g) + uint(p0.y) * g.width + uint(p0.x);
    float d0 = d * (1.0f + g.t_depth);
    uint64_t key = (uint64_t(floatBitsToUint(d0)) << 32) | uint64_t(src);
    for (uint k = 0u; k < splat_count(); ++k) {
        vec2 pt = c0 + leaving_displacement(u0, u1, splat_alpha(k));
        if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) continue; // as splat_pixel: finite, far off
        ivec2 t = ivec2(floor(pt));
        if (!inside(t, g)) continue;
        if (same ? !leaving_uniform(-load_mv1(t), u1) : !(d0 < load_depth1(t))) continue;
        splat_min(k, uint(t.y) * g.width + uint(t.x), key);
    }
}

FGSR_INLINE void splat_pixel(ivec2 p1, GenParams g) {
    if (!inside(p1, g)) return;
    float d1 = load_depth1(p1);
    vec4 m = source_velocities_at_depth(p1, d1, g);
    vec2 c1 = vec2(p1) + vec2(0.5f);
    uint src = uint(p1.y) * g.width + uint(p1.x);
    uint64_t key = (uint64_t(floatBitsToUint(d1)) << 32) | uint64_t(src);
    store_source_motion(src, m);
    if (g.extrapolate == 0u && g.frame0_has_mv != 0u) splat_leaving(p1, d1, vec2(m.x, m.y), g);
    for (uint k = 0u; k < splat_count(); ++k) {
        vec4 pos = motion_at(c1, m, splat_alpha(k), g);
        vec2 pt = vec2(pos.x, pos.y);
        if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) continue;
        ivec2 t = ivec2(floor(pt));
        if (!inside(t, g)) continue;
        splat_min(k, uint(t.y) * g.width + uint(t.x), key);
    }
}
