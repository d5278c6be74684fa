// Pass `splat` (paper 3.3): every frame-1 pixel writes itself to the nearest pixel of its position
// at the generated time. Conflicts resolve toward the nearest depth with one 64-bit atomicMin on
// (depth bits << 32 | source index): positive float bits order like the floats, and the source
// index breaks ties deterministically. Positions off screen are dropped, never wrapped.
//
// Entry provides (besides motion.h's loads):
//   float load_depth1(ivec2 pixel)
//   void  splat_min(uint target_index, uint64_t key)

FGSR_INLINE void splat_pixel(ivec2 p1, GenParams g) {
    if (!inside(p1, g)) return;
    vec4 m = source_motion(p1, g);
    vec2 pt = vec2(m.x, m.y);
    if (!(abs(pt.x) < 1.0e7f && abs(pt.y) < 1.0e7f)) return;
    ivec2 t = ivec2(floor(pt));
    if (!inside(t, g)) return;
    uint src = uint(p1.y) * g.width + uint(p1.x);
    uint64_t key = (uint64_t(floatBitsToUint(load_depth1(p1))) << 32) | uint64_t(src);
    splat_min(uint(t.y) * g.width + uint(t.x), key);
}
