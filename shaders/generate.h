// Pass `generate`: refine, disocc, warp and blend fused per pixel, with no intermediate buffers.
// The same functions as the separate passes (refine.h, disocc.h, warp.h, blend.h) in the same
// order, so the result equals the chain of separate passes; on CPU devices, whose cost per
// invocation dominates, it saves three dispatches and every intermediate write.
//
// Entry provides the loads of motion.h, refine.h and warp.h, and
//   void store_output(uint index, vec4 color)

FGSR_INLINE void generate_pixel(ivec2 t, GenParams g) {
    if (!inside(t, g)) return;
    uint i = uint(t.y) * g.width + uint(t.x);
    FieldSample f = refine_field(t, g);
    if (f.state == FIELD_HOLE && g.fill_holes != 0u) f = fill_hole(t, g);
    vec2 centre = vec2(t) + vec2(0.5f);
    WarpSample w1 = warp_sample(1u, centre, vec2(f.v.z, f.v.w), g);
    if (g.extrapolate != 0u) {
        store_output(i, w1.color);
        return;
    }
    WarpSample w0 = warp_sample(0u, centre, vec2(f.v.x, f.v.y), g);
    store_output(i, select_blend(w0.color, w0.depth, w1.color, w1.depth, f.state, g));
}
