// Pass `luma`: the luma pyramid of a submitted frame, for motion estimation from colour (colour-
// only sessions, FrameFormat::has_vectors false). Level 0 is the display-referred luma of the
// frame (the square root of linear luminance clamped to [0, 1], as blend.h's brightness: about
// perceptually even steps, so that a matching cost means the same in dark and bright regions);
// level k is level k - 1 low-passed and decimated by 2, of size ceil(size / 2). Every level lives in one float
// buffer per frame at offsets the host computes. One invocation per pixel of the level written.
//
// Entry provides:
//   vec4  load_color(uint pixel)              the frame's colour (level 0)
//   float load_level(uint index)              the pyramid (levels > 0 read the finer level)
//   void  store_level(uint index, float value)

// motion_luma (common.h): that luma of one colour.

// Level 0 and the levels above it are separate builds on the GPU (luma_level0 defines
// FGSR_LUMA_LEVEL0): CPU devices run both sides of a branch with the inactive lanes masked off,
// and level 0 then paid the 16 reads of the low-pass as well. The CPU reference reads p.level.
#if defined(FGSR_LUMA_LEVEL0)
#define LUMA_LEVEL0(p) true
#elif defined(__cplusplus)
#define LUMA_LEVEL0(p) ((p).level == 0u)
#else
#define LUMA_LEVEL0(p) false
#endif

FGSR_INLINE void luma_pixel(uvec2 q, LumaParams p) {
    if (q.x >= p.dst_width || q.y >= p.dst_height) return;
    float v;
    if (LUMA_LEVEL0(p)) {
        v = motion_luma(load_color(q.y * p.src_width + q.x));
    } else {
        // Separable [1 3 3 1] / 8 over source pixels 2q - 1 .. 2q + 2 (edges clamped): a low-pass
        // before the decimation, so that fine periodic texture (checkers, bricks) fades on the
        // coarse levels instead of aliasing into false structure that block matching would lock on.
        v = 0.0f;
        for (int j = 0; j < 4; ++j) {
            int y = clamp(2 * int(q.y) - 1 + j, 0, int(p.src_height) - 1);
            float wy = (j == 0 || j == 3) ? 0.125f : 0.375f;
            for (int i = 0; i < 4; ++i) {
                int x = clamp(2 * int(q.x) - 1 + i, 0, int(p.src_width) - 1);
                float wx = (i == 0 || i == 3) ? 0.125f : 0.375f;
                v += wx * wy * load_level(p.src_offset + uint(y) * p.src_width + uint(x));
            }
        }
    }
    store_level(p.dst_offset + q.y * p.dst_width + q.x, v);
}
