// Pass `denoise` (super-resolution sessions, Params::denoise): an adaptive pre-filter of the
// rendered low-resolution colour before `sr` accumulates it (docs/SR.md, "Noisy input").
//
// Why: Eq. 2 with the calibrated a (~0.66) keeps most of each frame's samples, so per-pixel noise
// in the input (Monte Carlo shading, sub-pixel texture detail point-sampled at one sample per
// pixel) stays in the output, and a sharp history resampler (the LUT) keeps it in the history.
// On clean rasterised input the estimate falls below the floor and the filter is the identity.
//
// Noise relative to brightness (p.gamma > 0): the noise of rendered content grows with its
// brightness (a texture point-sampled below its detail, shading noise: both multiply the light),
// so one absolute level fits a frame with sunlit and shaded parts badly: the median follows the
// larger, darker part and the bright part keeps its noise. Every magnitude is therefore divided
// by the local brightness scale m^gamma, m = max(mean luminance of the 3x3 neighbourhood,
// DENOISE_LUMA_FLOOR), and the filter's range at a pixel is r times that scale at the pixel:
// gamma 1 measures noise as a fraction of the brightness, 0 in linear units (docs/ACCURACY.md,
// change 17).
//
// Stage DENOISE_HISTOGRAM, one invocation per 2x2 block, at the block's pixel (2i+1, 2j+1) where
// it is interior: the Laplacian L = [1 -2 1; -2 4 -2; 1 -2 1] of the luminance (mean of R, G, B);
// for white noise of standard deviation sigma, L / 6 has standard deviation sigma. |L| / 6 over
// the brightness scale is counted in a histogram of DENOISE_BINS bins: bin 0 below 2^-16, then 8
// bins per octave.
// Stage DENOISE_LEVEL, one invocation: sigma = median of the counted magnitudes / 0.6745 (the
// median absolute deviation of a normal distribution; with gamma > 0 in units of m^gamma); edges
// and texture are a minority of the blocks and move the median little. The noise above the floor,
// sqrt(max(sigma^2 - floor^2, 0)), times the strength is the filter's range r. A median bin stands
// for its geometric centre (bins are 9 % wide). Fewer than 1 interior block (width or height < 3):
// sigma 0.
// Stage DENOISE_FILTER, one invocation per pixel: a 3x3 bilateral filter, weight
// s(dx) s(dy) exp(-d^2 / (2 r'^2)) with s(0) = 1, s(+-1) = 0.6 (a Gaussian of about one pixel),
// d^2 the mean squared RGB difference to the centre pixel (neighbours clamped at the border) and
// r' = r times the pixel's brightness scale.
// Alpha passes through. r = 0 (or no finite positive r) leaves every pixel exactly as it was, and
// the engine then skips stages 2 and 3 (indirect dispatches of 0 workgroups written by stage 1).
// The filter writes a scratch buffer that stage DENOISE_COPY copies back into the frame.
//
// Entry provides:
//   vec4  load_color(ivec2 pixel)          the ingested colour
//   void  store_color(uint pixel, vec4 c)  the filtered colour (stored with pack_color)
//   void  add_to_bin(uint bin)             histogram bin += 1 (atomic on the GPU)
//   uint  load_bin(uint bin)
//   void  store_level(float sigma, float range)   (GPU: also the dispatch of stages 2 and 3)
//   float load_range()

FGSR_INLINE float denoise_luma(vec4 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

// The brightness below which noise is measured as at this brightness (linear units): dark pixels
// would otherwise count their tiny absolute noise as large relative noise.
#define DENOISE_LUMA_FLOOR 0.02f

// The brightness scale of a neighbourhood of mean luminance m: m^gamma, 1 for gamma 0.
FGSR_INLINE float denoise_scale(float m, DenoiseParams p) {
    return p.gamma > 0.0f ? pow(max(m, DENOISE_LUMA_FLOOR), p.gamma) : 1.0f;
}

FGSR_INLINE ivec2 denoise_clamp(ivec2 q, DenoiseParams p) {
    return clamp(q, ivec2(0), ivec2(int(p.width) - 1, int(p.height) - 1));
}

// The histogram bin of a noise magnitude (|L| / 6, linear colour units).
FGSR_INLINE uint denoise_bin(float v) {
    if (!(v >= 1.52587890625e-05f)) return 0u; // 2^-16
    float b = floor((log2(v) + 16.0f) * 8.0f);
    return b >= float(DENOISE_BINS - 2u) ? DENOISE_BINS - 1u : 1u + uint(b);
}

// The magnitude a bin stands for: its geometric centre (bin 0: 0).
FGSR_INLINE float denoise_bin_value(uint bin) {
    return bin == 0u ? 0.0f : exp2((float(bin) - 0.5f) * 0.125f - 16.0f);
}

// Stage DENOISE_HISTOGRAM: block (i, j) = invocation id.
FGSR_INLINE void denoise_histogram(ivec2 block, DenoiseParams p) {
    ivec2 c = block * 2 + ivec2(1);
    if (c.x + 1 >= int(p.width) || c.y + 1 >= int(p.height)) return;
    float centre = denoise_luma(load_color(c));
    float edges = denoise_luma(load_color(c + ivec2(-1, 0))) + denoise_luma(load_color(c + ivec2(1, 0))) +
                  denoise_luma(load_color(c + ivec2(0, -1))) + denoise_luma(load_color(c + ivec2(0, 1)));
    float corners = denoise_luma(load_color(c + ivec2(-1, -1))) + denoise_luma(load_color(c + ivec2(1, -1))) +
                    denoise_luma(load_color(c + ivec2(-1, 1))) + denoise_luma(load_color(c + ivec2(1, 1)));
    float l = 4.0f * centre - 2.0f * edges + corners;
    float scale = denoise_scale((centre + edges + corners) * (1.0f / 9.0f), p);
    add_to_bin(denoise_bin(abs(l) * (1.0f / 6.0f) / scale));
}

// Stage DENOISE_LEVEL.
FGSR_INLINE void denoise_level(DenoiseParams p) {
    uint total = 0u;
    for (uint b = 0u; b < DENOISE_BINS; ++b) total += load_bin(b);
    float sigma = 0.0f;
    if (total > 0u) {
        uint half_count = (total + 1u) / 2u, seen = 0u, b = 0u;
        for (; b < DENOISE_BINS - 1u; ++b) {
            seen += load_bin(b);
            if (seen >= half_count) break;
        }
        sigma = denoise_bin_value(b) / 0.6745f;
    }
    float above = sqrt(max(sigma * sigma - p.noise_floor * p.noise_floor, 0.0f));
    store_level(sigma, p.strength * above);
}

// Whether a range filters at all.
FGSR_INLINE bool denoise_filters(float r) { return r > 0.0f && !isinf(r); }

// Stage DENOISE_FILTER.
FGSR_INLINE vec4 denoise_pixel(ivec2 q, DenoiseParams p) {
    vec4 c0 = load_color(q);
    float r = load_range();
    if (!denoise_filters(r)) return c0;
    vec3 n[9];
    float m = 0.0f;
    for (int i = 0; i < 9; ++i) {
        n[i] = vec3(load_color(denoise_clamp(q + ivec2(i % 3 - 1, i / 3 - 1), p)));
        m += denoise_luma(vec4(n[i], 0.0f));
    }
    float rs = r * denoise_scale(m * (1.0f / 9.0f), p);
    float k = 1.0f / (2.0f * rs * rs);
    vec3 sum = vec3(0.0f);
    float wsum = 0.0f;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            vec3 c = n[(y + 1) * 3 + x + 1];
            vec3 d = c - vec3(c0);
            float w = (x == 0 ? 1.0f : 0.6f) * (y == 0 ? 1.0f : 0.6f) * exp(-dot(d, d) * (1.0f / 3.0f) * k);
            sum += w * c;
            wsum += w;
        }
    return vec4(sum / wsum, c0.w); // wsum >= 1: the centre's own weight
}
