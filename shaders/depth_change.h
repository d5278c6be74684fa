// The depth change that a field of motion implies for the surface under a pixel, shared by the
// motion's frame-0 test (motion.h, change 21 of docs/ACCURACY.md), the agree pass's depth tests
// (agree.h, change 37) and blend's (blend_depth.h, change 38). A patch's size on screen goes as
// 1 / depth, so a patch facing the camera whose local map to the earlier frame is J = I + grad(mv)
// was 1 / sqrt(det J) times as far there.
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
