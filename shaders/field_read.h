// Reading a dense field of vectors (one per pixel of a pyramid level) bilinearly between the pixel
// centres, edges clamped: flow.h reads the coarse-to-fine field's level 1 at each frame pixel, and
// polish.h seeds a coarse level from the one above it. No include guard, as luma_read.h: the CPU
// reference compiles flow.h and polish.h into two structs of one translation unit.
//
// Entry provides:
//   vec2 load_field_vector(uint index)  the buffer holding the field (its first vector at `offset`)

// The field of width x height vectors starting at `offset`, at position b in its pixels (centres at
// integers: b = position in pixels - 0.5).
FGSR_INLINE vec2 field_bilinear(vec2 b, uint offset, uint width, uint height) {
    vec2 fb = floor(b);
    vec2 f = b - fb;
    ivec2 c = ivec2(fb);
    ivec2 hi = ivec2(int(width) - 1, int(height) - 1);
    vec2 corner[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 q = clamp(c + ivec2(k & 1, k >> 1), ivec2(0), hi);
        corner[k] = load_field_vector(offset + uint(q.y) * width + uint(q.x));
    }
    return mix(mix(corner[0], corner[1], f.x), mix(corner[2], corner[3], f.x), f.y);
}
