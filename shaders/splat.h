// Pass `splat` (paper 3.3): every frame-1 pixel writes itself to the nearest pixel of its position
// at the generated time. Conflicts resolve toward the nearest depth with one 64-bit atomicMin on
// (depth bits << 32 | source index): positive float bits order like the floats, and the source
// index breaks ties deterministically. Positions off screen are dropped, never wrapped. Every
// source also stores its field vectors (v0, v1): the displacement from its position at the
// generated time to its position in frame 0 and in frame 1, so that later passes read one vec4 per
// splatted pixel instead of recomputing the motion.
//
// Entry provides (besides motion.h's loads):
//   void splat_min(uint target_index, uint64_t key)
//   void store_motion(uint source_index, vec4 field_vectors)

FGSR_INLINE void splat_pixel(ivec2 p1, GenParams g) {
    if (!inside(p1, g)) return;
    vec4 m = source_motion(p1, g);
    uint src = uint(p1.y) * g.width + uint(p1.x);
    vec2 pt = vec2(m.x, m.y);
    store_motion(src, vec4(vec2(m.z, m.w) - pt, vec2(p1) + vec2(0.5f) - pt));
    if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) return;
    ivec2 t = ivec2(floor(pt));
    if (!inside(t, g)) return;
    uint64_t key = (uint64_t(floatBitsToUint(load_depth1(p1))) << 32) | uint64_t(src);
    splat_min(uint(t.y) * g.width + uint(t.x), key);
}
