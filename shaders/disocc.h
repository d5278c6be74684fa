// Pass `disocc` (paper 3.4, supplement 4): gives the holes that refine left a vector.
//
// Extrapolation (disocclusion, the paper's method): a hole at t was covered at time 1 by a surface
// that has since moved on; frame 1's own vector at t points back along that surface's path, where
// frame 1 shows what the surface uncovered, so v1 = alpha * mv1(t).
// Interpolation (occlusion: visible at alpha, covered by time 1, so only frame 0 sees it): the
// surface is the background next to the hole; take the vectors of the farthest splatted pixel on
// a sparse ring pattern (8 directions, radii 1, 2, 4, 8, 16) around t. Blend then reads frame 0
// only. Only splat keys are read, so the pass needs no other pass's output but splat's.
// Entry provides refine.h's and motion.h's loads.

FGSR_INLINE FieldSample fill_hole(ivec2 t, GenParams g) {
    if (g.extrapolate != 0u) {
        vec2 v1 = g.alpha * load_mv1(t);
        return field_sample(vec4(v1, v1), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
    }
    float farthest = -1.0f;
    uint best = 0u;
    for (int r = 1; r <= 16; r *= 2)
        for (int d = 0; d < 8; ++d) {
            ivec2 dir = ivec2(d < 3 ? -1 : (d == 3 || d == 7 ? 0 : 1), d == 1 || d == 5 ? 0 : (d < 1 || d > 5 ? -1 : 1));
            ivec2 q = t + r * dir;
            if (inside(q, g)) {
                uint64_t k = load_key(q);
                if (!key_empty(k) && key_depth(k) > farthest) {
                    farthest = key_depth(k);
                    best = key_source(k);
                }
            }
        }
    if (farthest > 0.0f) return field_sample(load_motion(best), farthest, FIELD_HOLE_FILLED);
    return field_sample(vec4(0.0f), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
}
