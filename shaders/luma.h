// Pass `luma`: the luma pyramid of a submitted frame, for motion estimation from colour (colour-
// only sessions, FrameFormat::has_vectors false). Level 0 is the display-referred luma of the
// frame (the square root of linear luminance clamped to [0, 1], as blend.h's brightness: about
// perceptually even steps, so that a matching cost means the same in dark and bright regions);
// level k is the 2x2 mean of level k - 1, of size ceil(size / 2). Every level lives in one float
// buffer per frame at offsets the host computes. One invocation per pixel of the level written.
//
// Entry provides:
//   vec4  load_color(uint pixel)              the frame's colour (level 0)
//   float load_level(uint index)              the pyramid (levels > 0 read the finer level)
//   void  store_level(uint index, float value)

FGSR_INLINE float motion_luma(vec4 c) {
    return sqrt(clamp(0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z, 0.0f, 1.0f));
}

FGSR_INLINE void luma_pixel(uvec2 q, LumaParams p) {
    if (q.x >= p.dst_width || q.y >= p.dst_height) return;
    float v;
    if (p.level == 0u) {
        v = motion_luma(load_color(q.y * p.src_width + q.x));
    } else {
        uvec2 a = 2u * q;
        uvec2 b = min(a + 1u, uvec2(p.src_width - 1u, p.src_height - 1u));
        v = 0.25f * (load_level(p.src_offset + a.y * p.src_width + a.x) + load_level(p.src_offset + a.y * p.src_width + b.x) +
                     load_level(p.src_offset + b.y * p.src_width + a.x) + load_level(p.src_offset + b.y * p.src_width + b.x));
    }
    store_level(p.dst_offset + q.y * p.dst_width + q.x, v);
}
