// Resampling of an image at a continuous position with a 4x4 footprint, shared by the SR history
// warp (sr.h), the joint ISR/ESR warps and the LUT trainer (tools/fgsr lut-train), so that what is
// trained is exactly what the engine runs.
//
// Position `pos` in pixels (centres at +0.5). Base pixel b = floor(pos - 0.5), phase
// f = pos - 0.5 - b in [0,1)^2; taps at b + (i - 1, j - 1), i, j in 0..3, weight index j * 4 + i.
// Kinds (RESAMPLE_*):
//   bilinear    only the inner 2x2 taps, weights (1-f)/f per axis
//   catmull_rom separable Catmull-Rom cubic (bicubic with a = -0.5)
//   lut         learned weights, phase rounded to the nearest multiple of 1/L (L = FGSR_LUT_LEVELS),
//               so that whole-pixel positions (phase 0, static content) are a bin of their own:
//               k = floor((pos - 0.5) * L + 0.5), base = floor(k / L), bin = k - base * L (0..L-1),
//               phase of the bin = bin / L; weights lut[((bin.y * L) + bin.x) * 16 + j * 4 + i]
// Taps outside the image are clamped to the border (never wrapped).
//
// Entry provides:
//   vec4  load_src(ivec2 pixel)      the image being resampled (caller-chosen size, see src_size)
//   vec4  load_lut4(uint row)        the LUT's weights 4 * row .. 4 * row + 3 (only read for
//                                    RESAMPLE_LUT; one access for 4 weights)
#define RESAMPLE_BILINEAR 0u
#define RESAMPLE_CATMULL_ROM 1u
#define RESAMPLE_LUT 2u
#define FGSR_LUT_LEVELS 32
#define FGSR_LUT_SIZE (FGSR_LUT_LEVELS * FGSR_LUT_LEVELS * 16)

// The cubic B-spline's weights of the 4 taps around t in [0, 1): smooth, not interpolating (a
// low-pass the Catmull-Rom weights are not).
FGSR_INLINE vec4 bspline_weights(float t) {
    float t2 = t * t;
    float t3 = t2 * t;
    float u = 1.0f - t;
    return vec4(u * u * u, 3.0f * t3 - 6.0f * t2 + 4.0f, -3.0f * t3 + 3.0f * t2 + 3.0f * t + 1.0f, t3) / 6.0f;
}

// The LUT's base pixel (xy) and phase bin (zw, 0..L-1) of position pos.
FGSR_INLINE ivec4 lut_bin(vec2 pos) {
    ivec2 k = ivec2(floor((pos - vec2(0.5f)) * float(FGSR_LUT_LEVELS) + vec2(0.5f)));
    ivec2 base = ivec2(floor(vec2(k) / float(FGSR_LUT_LEVELS)));
    return ivec4(base, k - base * FGSR_LUT_LEVELS);
}

FGSR_INLINE vec4 resample(vec2 pos, ivec2 src_size, uint kind) {
    vec2 x = pos - vec2(0.5f);
    vec2 b = floor(x);
    vec2 f = x - b;
    ivec2 base = ivec2(b);
    ivec2 hi = src_size - ivec2(1);
    vec4 sum = vec4(0.0f);
    if (kind == RESAMPLE_BILINEAR) {
        ivec2 q0 = clamp(base, ivec2(0), hi), q1 = clamp(base + ivec2(1), ivec2(0), hi);
        vec4 top = mix(load_src(ivec2(q0.x, q0.y)), load_src(ivec2(q1.x, q0.y)), f.x);
        vec4 bottom = mix(load_src(ivec2(q0.x, q1.y)), load_src(ivec2(q1.x, q1.y)), f.x);
        return mix(top, bottom, f.y);
    }
    vec4 wx = catmull_rom_weights(f.x), wy = catmull_rom_weights(f.y);
    uint lut_row = 0u; // the phase's first row of 4 weights
    if (kind == RESAMPLE_LUT) {
        ivec4 lb = lut_bin(pos);
        base = ivec2(lb.x, lb.y);
        lut_row = uint(lb.w * FGSR_LUT_LEVELS + lb.z) * 4u;
    }
    for (int j = 0; j < 4; ++j) {
        vec4 w = kind == RESAMPLE_LUT ? load_lut4(lut_row + uint(j)) : wx * wy[j];
        for (int i = 0; i < 4; ++i) sum += w[i] * load_src(clamp(base + ivec2(i - 1, j - 1), ivec2(0), hi));
    }
    return sum;
}

// The LUT's read with its weights moved towards the cubic B-spline's by k (0..1), on the same 16
// taps: the B-spline taken at the phase of the LUT's bin, at most 1/(2 FGSR_LUT_LEVELS) of a pixel
// from the exact phase (sr.h step 3, SR_NOISE_KERNEL).
FGSR_INLINE vec4 resample_lut_smoothed(vec2 pos, ivec2 src_size, float k) {
    ivec4 lb = lut_bin(pos);
    ivec2 base = ivec2(lb.x, lb.y), hi = src_size - ivec2(1);
    uint lut_row = uint(lb.w * FGSR_LUT_LEVELS + lb.z) * 4u;
    vec4 bx = bspline_weights(float(lb.z) / float(FGSR_LUT_LEVELS)), by = bspline_weights(float(lb.w) / float(FGSR_LUT_LEVELS));
    vec4 sum = vec4(0.0f);
    for (int j = 0; j < 4; ++j) {
        vec4 w = mix(load_lut4(lut_row + uint(j)), bx * by[j], k);
        for (int i = 0; i < 4; ++i) sum += w[i] * load_src(clamp(base + ivec2(i - 1, j - 1), ivec2(0), hi));
    }
    return sum;
}
