// The depth change that a field of motion implies for the surface under a pixel, shared by the
// motion's frame-0 test (motion.h, change 21 of docs/ACCURACY.md), the agree pass's depth tests
// (agree.h, change 37) and blend's (blend.h, change 38). A patch's size on screen goes as 1 / depth, so a
// patch facing the camera whose local map to the earlier frame is J = I + grad(mv) was 1 / sqrt(det J) times
// as far there.
//
// Entry provides:
//   vec2  load_mv1(ivec2 pixel)     frame 1 vectors
//   float load_depth1(ivec2 pixel)

// s for frame-1 pixel p1 of depth d1 (central differences of the frame-1 vectors over p1's edge
// neighbours on its surface, depth within T_D; one-sided at an edge of it; det J clamped to
// [1/4, 4]).
// mc: load_mv1(p1), which the caller has read already.
FGSR_INLINE float frame1_depth_scale(ivec2 p1, float d1, vec2 mc, GenParams g) {
    vec2 grad[2];
    for (int axis = 0; axis < 2; ++axis) {
        ivec2 step = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
        ivec2 lo_q = p1 - step, hi_q = p1 + step;
        bool lo_ok = inside(lo_q, g) && relative_depth_difference(load_depth1(lo_q), d1) <= g.t_depth;
        bool hi_ok = inside(hi_q, g) && relative_depth_difference(load_depth1(hi_q), d1) <= g.t_depth;
        vec2 m_lo = lo_ok ? load_mv1(lo_q) : mc, m_hi = hi_ok ? load_mv1(hi_q) : mc;
        float span = float(int(lo_ok) + int(hi_ok));
        grad[axis] = span > 0.0f ? (m_hi - m_lo) / span : vec2(0.0f);
    }
    return expansion_depth_scale(grad[0], grad[1]);
}

// How far d0 lies outside [d1 lo, d1 hi], relative (0 inside): the edge neighbours' ranking
// (motion.h); the agree pass's depth tests (agree.h).
FGSR_INLINE float surface_distance0(float d0, float d1, vec3 band) {
    return relative_depth_difference(d0, clamp(d0, d1 * band.x, d1 * band.y));
}

// blend.h's depth band [lo, hi] for warped depths d0 and d1, d1 frame 1's at its pixel p1 (the
// sample_pixel of warped frame 1's position), where the plain test fails: frame 0 may show the
// same surface at any depth in [d1 lo, d1 hi]. Its two parts:
//   - the depth change frame 1's vectors imply there (frame1_depth_scale; [1, s] or [s, 1]);
//   - the depth slope of that surface: each warped depth is its nearest pixel's, up to half a
//     pixel from the position sampled in either frame, so the two may differ by a pixel's change
//     along the surface (r, the largest relative difference to p1's edge neighbours within T_D),
//     which widens the band by 1 + r on both sides.
// (1, 1) where the plain test passes (the band then contains d1: the same decision, without the
// reads), where a sample is off screen, and without BLEND_DEPTH_MOTION.
FGSR_INLINE vec2 blend_depth_band(float d0, float d1, ivec2 p1, GenParams g) {
    if ((g.blend_mode & BLEND_DEPTH_MOTION) == 0u || g.frame1_has_mv == 0u || d0 < 0.0f || d1 < 0.0f)
        return vec2(1.0f);
    if (relative_depth_difference(d0, d1) <= g.t_depth) return vec2(1.0f);
    float s = frame1_depth_scale(p1, d1, load_mv1(p1), g);
    float r = 0.0f;
    for (int k = 0; k < 4; ++k) {
        ivec2 q = p1 + edge_neighbour_offset(k);
        if (!inside(q, g)) continue;
        float e = relative_depth_difference(load_depth1(q), d1);
        if (e <= g.t_depth) r = max(r, e);
    }
    return vec2(min(s, 1.0f) / (1.0f + r), max(s, 1.0f) * (1.0f + r));
}
