// Pass `generate`: refine, disocc, warp and blend fused per pixel, with no intermediate buffers.
// The same functions as the separate passes (refine.h, disocc.h, warp.h, blend.h) in the same
// order, so the result equals the chain of separate passes; on CPU devices, whose cost per
// invocation dominates, it saves three dispatches and every intermediate write.
//
// Entry provides the loads of motion.h, refine.h and warp.h, and
//   void store_output(uint index, vec4 color)

// Warp and blend of one pixel with its field (the part of generate_pixel after refine / disocc).
FGSR_INLINE void generate_finish(ivec2 t, FieldSample f, GenParams g) {
    uint i = uint(t.y) * g.width + uint(t.x);
    vec2 centre = vec2(t) + vec2(0.5f);
    WarpSample w1 = warp_sample(1u, centre, vec2(f.v.z, f.v.w), g);
    if (g.extrapolate != 0u) {
        store_output(i, extrapolated_color(w1, f.v, f.state, centre, g));
        return;
    }
    WarpSample w0 = warp_sample(0u, centre, vec2(f.v.x, f.v.y), g);
    vec2 d = blend_depths(w0.depth, w1.depth, w1.pixel, g);
    store_output(i, select_blend(w0.color, d.x, w1.color, d.y, f.state, g));
}

FGSR_INLINE void generate_pixel(ivec2 t, GenParams g) {
    if (!inside(t, g)) return;
    FieldSample f = refine_field(t, g);
    if (f.state == FIELD_HOLE && g.fill_holes != 0u) f = fill_hole_covered(t, g);
    generate_finish(t, f, g);
}

// Split form for CPU devices (generate.comp, FGSR_GENERATE_SPLIT), which run every branch of a
// shader with the inactive lanes masked off, so that the neighbourhood reads of refine_field and
// fill_hole, needed only where nobody splatted, cost every pixel: a first pass finishes the
// splatted pixels (refine_field's first line, then the same warp and blend) and returns false for
// the empty ones, which a second pass over their list finishes with generate_pixel. Together they
// write what generate_pixel writes for every pixel.
FGSR_INLINE bool generate_splatted(ivec2 t, GenParams g) {
    if (!inside(t, g)) return true;
    uint64_t k = load_key(t);
    if (key_empty(k)) return false;
    generate_finish(t, field_sample(load_motion(key_source(k)), key_depth(k), FIELD_SPLATTED), g);
    return true;
}
