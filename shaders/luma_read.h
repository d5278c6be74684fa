// Reading a frame's level-0 luma, for flow.h and polish.h: pixel positions clamped to the frame,
// and the previous frame read bilinearly. No include guard: the CPU reference compiles flow.h and
// polish.h into two structs of one translation unit, and each struct needs its own copy.
//
// Entry provides:
//   float load_cur(uint pixel)   level-0 luma of the current frame
//   float load_prev(uint pixel)  level-0 luma of the previous frame

// A pixel position clamped to a frame of width x height.
FGSR_INLINE ivec2 luma_clamp(ivec2 q, uint width, uint height) {
    return clamp(q, ivec2(0), ivec2(int(width) - 1, int(height) - 1));
}

// The luma of the previous (prev) or the current frame at a pixel, edges clamped.
FGSR_INLINE float luma_at(ivec2 q, bool prev, uint width, uint height) {
    q = luma_clamp(q, width, height);
    uint i = uint(q.y) * width + uint(q.x);
    return prev ? load_prev(i) : load_cur(i);
}

// The previous frame's luma at a position in pixels (bilinear, edges clamped).
FGSR_INLINE float luma_prev_bilinear(vec2 at, uint width, uint height) {
    vec2 f0 = floor(at);
    vec2 t = at - f0;
    ivec2 c = ivec2(f0);
    float top = mix(luma_at(c, true, width, height), luma_at(c + ivec2(1, 0), true, width, height), t.x);
    float bottom = mix(luma_at(c + ivec2(0, 1), true, width, height),
                       luma_at(c + ivec2(1, 1), true, width, height), t.x);
    return mix(top, bottom, t.y);
}
