// Pass `disocc` (paper 3.4, supplement 4): gives the holes that refine left a vector.
//
// Extrapolation (disocclusion, the paper's method): a hole at t was covered at time 1 by a surface
// that has since moved on; frame 1's own vector at t points back along that surface's path, where
// frame 1 shows what the surface uncovered, so v1 = alpha * mv1(t).
// Interpolation (occlusion: visible at alpha, covered by time 1, so only frame 0 sees it): the
// surface is the background next to the hole; take the vectors of the farthest known pixel on a
// sparse ring pattern (radii 1..16) around t. Blend then reads frame 0 only.
// Only hole pixels are written and only known pixels are read, so the pass is race-free in place.
//
// Entry provides:
//   vec2  load_mv1(ivec2 pixel)
//   vec4  load_field(ivec2 pixel)
//   float load_field_depth(ivec2 pixel)
//   uint  load_field_state(ivec2 pixel)
//   void  store_field(uint index, vec4 field, float depth, uint state)

FGSR_INLINE void disocc_pixel(ivec2 t, GenParams g) {
    if (!inside(t, g)) return;
    if (load_field_state(t) != FIELD_HOLE) return;
    uint i = uint(t.y) * g.width + uint(t.x);
    if (g.extrapolate != 0u) {
        vec2 v1 = g.alpha * load_mv1(t);
        store_field(i, vec4(v1, v1), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
        return;
    }
    float farthest = -1.0f;
    vec4 best = vec4(0.0f);
    for (int r = 1; r <= 16; r *= 2)
        for (int d = 0; d < 8; ++d) {
            ivec2 dir = ivec2(d < 3 ? -1 : (d == 3 || d == 7 ? 0 : 1), d == 1 || d == 5 ? 0 : (d < 1 || d > 5 ? -1 : 1));
            ivec2 q = t + r * dir;
            if (inside(q, g) && field_known(load_field_state(q))) {
                float dq = load_field_depth(q);
                if (dq > farthest) {
                    farthest = dq;
                    best = load_field(q);
                }
            }
        }
    if (farthest > 0.0f) store_field(i, best, farthest, FIELD_HOLE_FILLED);
    else store_field(i, vec4(0.0f), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
}
