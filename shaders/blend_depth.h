// Interpolation's blend with BLEND_DEPTH_MOTION (blend.h; docs/ACCURACY.md, change 38): the depths
// its test compares. Included after depth_change.h by the entries that blend (blend.comp, generate,
// generate_sr, classify).
//
// Entry provides:
//   vec2  load_mv1(ivec2 pixel)     frame 1 vectors
//   float load_depth1(ivec2 pixel)

// The depths frame 1's warped sample may show: those of its pixel p1 and p1's edge neighbours. A
// warped depth is its nearest pixel's, up to half a pixel from the position sampled, so the surface
// there may be any of them: a step along a depth slope, or the other side of an edge.
FGSR_INLINE vec2 sample_depth_range(ivec2 p1, float d1, GenParams g) {
    vec2 range = vec2(d1);
    for (int k = 0; k < 4; ++k) {
        ivec2 q = p1 + edge_neighbour_offset(k);
        if (!inside(q, g)) continue;
        float d = load_depth1(q);
        range = vec2(min(range.x, d), max(range.y, d));
    }
    return range;
}

// The depths blend.h's test compares for warped depths d0 and d1, d1 read at frame-1 pixel p1 (the
// sample_pixel of warped frame 1's position): where the plain test fails, d0 and the depth nearest
// it that frame 0 may show of what frame 1 shows there: sample_depth_range extended by the depth
// change frame 1's vectors imply (frame1_depth_scale, s: a surface at d1 may be anywhere from d1
// to d1 s in frame 0). (d0, d1) where the plain test passes (the range contains d1: the same
// decision, without the reads), where a sample is off screen, and without BLEND_DEPTH_MOTION.
FGSR_INLINE vec2 blend_depths(float d0, float d1, ivec2 p1, GenParams g) {
    if ((g.blend_mode & BLEND_DEPTH_MOTION) == 0u || d0 < 0.0f || d1 < 0.0f) return vec2(d0, d1);
    if (relative_depth_difference(d0, d1) <= g.t_depth) return vec2(d0, d1);
    float s = g.frame1_has_mv != 0u ? frame1_depth_scale(p1, d1, load_mv1(p1), g) : 1.0f;
    vec2 range = sample_depth_range(p1, d1, g) * vec2(min(s, 1.0f), max(s, 1.0f));
    return vec2(d0, clamp(d0, range.x, range.y));
}
