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

// Interpolation: frame-0 content that leaves the frame before frame 1 (its own velocity -mv0,
// taken as uniform, takes it off screen by then) has no frame-1 pixel to splat it, so its frame-0
// pixel splats itself at c0 - alpha mv0, keyed as source frame_pixels(g) + p0 (motion.h,
// leaving_field_vectors): a near post crossing the edge then covers the background there until
// it has gone. Only where frame 1 no longer shows its surface at p0 (depths differ by more than
// T_D; frame-0 vectors that are a cut's reprojection would otherwise move still content out), and
// only in front of what frame 1 shows where it lands, with its depth raised by T_D in the key:
// frame 1's own splat of the same surface (an accelerating wall, whose frame-0 velocity is too
// slow) wins over this copy. (docs/ACCURACY.md, change 29.)
FGSR_INLINE void splat_leaving(ivec2 p0, GenParams g) {
    vec2 m = load_mv0(p0);
    vec2 c0 = vec2(p0) + vec2(0.5f);
    vec2 end = c0 - m;
    if (end.x >= 0.0f && end.y >= 0.0f && end.x <= float(g.width) && end.y <= float(g.height)) return;
    float d = load_depth0(p0);
    if (relative_depth_difference(d, load_depth1(p0)) <= g.t_depth) return;
    uint src = frame_pixels(g) + uint(p0.y) * g.width + uint(p0.x);
    float d0 = d * (1.0f + g.t_depth);
    uint64_t key = (uint64_t(floatBitsToUint(d0)) << 32) | uint64_t(src);
    for (uint k = 0u; k < splat_count(); ++k) {
        vec2 pt = c0 - splat_alpha(k) * m;
        if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) continue; // as splat_pixel: finite, far off
        ivec2 t = ivec2(floor(pt));
        if (inside(t, g) && d0 < load_depth1(t)) splat_min(k, uint(t.y) * g.width + uint(t.x), key);
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
    if (g.extrapolate == 0u && g.frame0_has_mv != 0u) splat_leaving(p1, g);
    for (uint k = 0u; k < splat_count(); ++k) {
        vec4 pos = motion_at(c1, m, splat_alpha(k), g);
        vec2 pt = vec2(pos.x, pos.y);
        if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) continue;
        ivec2 t = ivec2(floor(pt));
        if (!inside(t, g)) continue;
        splat_min(k, uint(t.y) * g.width + uint(t.x), key);
    }
}
