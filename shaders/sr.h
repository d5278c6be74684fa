// Pass `sr` (paper 3.5, Eq. 2): temporal super resolution of one rendered low-resolution frame.
// One invocation per output (HR) pixel q, centre qc; p = qc / scale is its position in LR pixels.
//   1. Motion: the LR vector at p's pixel t (or, with dilation, of the frontmost pixel of t's 3x3
//      neighbourhood, QRISP 4.1), scaled to HR: the history position is h = qc + mv * scale.
//   2. Rejection: no history (first frame, reset), h off screen, or a disocclusion: the previous
//      frame's depth at p + mv differs from the current depth at t by more than T_D (relative).
//      With SR_DEPTH_MOTION the test first expects the depth change the motion implies: a surface
//      the camera approaches was farther in the previous frame, by the factor s = 1 / sqrt(det J)
//      for a patch facing the camera, J = I + grad(mv) the local map from current to previous
//      positions (central differences of t's vectors over the neighbours on t's surface, depth
//      within T_D; s clamped to [1/2, 2]). A patch seen at a slant changes its depth by less (a
//      ground plane by about s^(2/3)), so the previous depth is accepted anywhere between
//      d_now and d_now * s, widened by T_D either way; with s = 1 this is the plain test. A
//      disocclusion still fails: the occluder in front was nearer than d_now / (1 + T_D) while
//      the background's own vectors expand or shrink nothing. Evaluated only where the plain test
//      rejects (docs/ACCURACY.md, change 15).
//   3. History: resampled at h (bilinear, Catmull-Rom or the learned LUT, resample.h), then
//      clamped to the colour box (min/max) of the current 3x3 LR neighbourhood (shading changes).
//      With SR_NOISE_KERNEL (opt-in; the host sets it for the LUT where the input measures
//      aliased) the LUT's weights move towards the cubic B-spline's, on the same taps, by
//      k = clamp((r - SR_KERNEL_R0) x SR_KERNEL_GAIN, 0, 1) x clamp((SR_KERNEL_Q1 - q) /
//      SR_KERNEL_Q_SPAN, 0, 1): where the samples scatter about the history like noise (r, step 7)
//      and the history read at their positions varies less than they do (q: its luma variance over
//      theirs). That is detail finer than an output pixel, which the truth averages out and the
//      LUT would keep as the samples aliased it; it costs on detail near the output's resolution,
//      which looks the same to the 3x3 (docs/ACCURACY.md, change 20).
//   4. Current samples: LR pixel (i, j) sampled the scene at (i + 0.5 + jitter) LR pixels; the
//      samples within one LR pixel of p get weight w = 1 - b * d (d: distance in LR pixels). With
//      SR_SHARP_CURRENT (the host sets it where the input measures antialiased) their term in Eq. 2
//      is the spatial upsample (Catmull-Rom at p - jitter) with the same total weight: such input
//      is low-passed already, and the tent would blur it again every frame (docs/ACCURACY.md,
//      change 46).
//   5. Eq. 2 with its weights normalised: q = (a * sum(w s) / n + (1 - a) * history) /
//      (a * sum(w) / n + (1 - a)), n the number of samples in reach; read literally (dividing by
//      n only) the equation would darken the image by a * mean(w) + (1 - a) every frame.
//      Rejected pixels (and pixels no sample reaches, and a = 1 with every weight 0) take the
//      spatial upsample: Catmull-Rom of the LR frame at p - jitter, or with SR_SMOOTH_SPATIAL (the
//      host sets it where the input measures aliased, Session::input_aliasing, jittered or not)
//      the cubic B-spline, which does not interpolate the point samples' aliasing but low-passes
//      it (docs/ACCURACY.md, change 16).
//   6. Disagreement (p.disagree > 0; the host sets it only for sessions whose input carries no
//      jitter and measures antialiased, Session::input_aliasing): the history's weight (1 - a) is
//      multiplied by max(0, 1 - disagree * e), e = |clamped history - the tent-weighted mean of the
//      new samples| / |colour box| (RGB lengths). On such input a history that disagrees with the
//      new samples comes from vectors that do not follow the colour (temporally antialiased
//      colour trailing its geometry), not from aliasing; on aliased input it is the detail the
//      samples alias, and the rule would cost (docs/ACCURACY.md, change 9).
//   7. Noise (SR_NOISE_AVERAGE; the host sets it where the input measures aliased): the weight a
//      of the new samples falls to (1 - SR_NOISE_CUT) a where they scatter about the history like
//      noise. Detail finer than an output pixel (the renders' procedural textures point-sampled)
//      gives every jittered sample a new value about the same mean, which the truth is; with a
//      high a the output follows each sample's scatter. The measure r: over t's 3x3 samples on
//      t's surface (depth within T_D), the mean squared luma difference between each sample and
//      the history read bilinearly at that sample's own previous position, less the square of
//      their mean difference (a shift of the history against the samples, from vectors that do
//      not follow the colour, is bias, not noise: there more history would lag), relative to the
//      samples' own luma variance. Detail the history resolves predicts its samples (r small);
//      unresolved detail does not (r about 1 or more). a is lowered by SR_NOISE_CUT x
//      clamp((r - SR_NOISE_R0) x SR_NOISE_GAIN, 0, 1), where at least 4 samples take part. Chosen on
//      the train captures (docs/ACCURACY.md, change 19).
// r and q depend on the LR pixel t alone: a stage before the pass (noise_stats, variant sr_noise)
// measures them once per LR pixel, where step 3's or step 7's flag is set and there is a history.
//
// Entry provides:
//   vec4  load_lr_color(ivec2 lr_pixel), float load_lr_depth(ivec2), vec2 load_lr_mv(ivec2)
//   float load_prev_depth(ivec2 lr_pixel)     previous frame's LR depth
//   vec4  load_src(ivec2 hr_pixel)            the previous HR output (history), for resample.h
//   vec4  load_lut4(uint row)
//   vec2  load_noise(ivec2 lr_pixel)          (r, q) of the stage (steps 3 and 7 only)

FGSR_INLINE ivec2 clamp_lr(ivec2 q, SrParams p) { return clamp(q, ivec2(0), ivec2(int(p.lr_width) - 1, int(p.lr_height) - 1)); }

// The spatial upsample: Catmull-Rom of the LR frame at an LR position, clamped per channel to the
// range of its inner 2x2 taps (as warp.h's cubic: beside a highlight far over white the negative
// lobes would pull the pixels around it to black, a dark ring; docs/ACCURACY.md change 49), or with
// SR_SMOOTH_SPATIAL the cubic B-spline (step 5; its weights are positive).
FGSR_INLINE vec4 lr_upsample(vec2 pos, SrParams p) {
    vec2 x = pos - vec2(0.5f);
    vec2 b = floor(x);
    vec2 f = x - b;
    ivec2 base = ivec2(b);
    bool low_pass = (p.flags & SR_SMOOTH_SPATIAL) != 0u;
    vec4 wx = low_pass ? bspline_weights(f.x) : catmull_rom_weights(f.x);
    vec4 wy = low_pass ? bspline_weights(f.y) : catmull_rom_weights(f.y);
    vec4 sum = vec4(0.0f);
    vec4 lo = vec4(3.0e38f), hi = vec4(-3.0e38f);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            vec4 c = load_lr_color(clamp_lr(base + ivec2(i - 1, j - 1), p));
            sum += wx[i] * wy[j] * c;
            if (!low_pass && i >= 1 && i <= 2 && j >= 1 && j <= 2) {
                lo = min(lo, c);
                hi = max(hi, c);
            }
        }
    if (!low_pass) sum = clamp(sum, lo, hi);
    return max(sum, vec4(0.0f));
}

// s of step 2: the factor by which the depth of t's surface patch was larger in the previous frame,
// if it faces the camera, from the area ratio of the local map from current to previous positions.
FGSR_INLINE float motion_depth_scale(ivec2 t, float d_now, SrParams p) {
    vec2 m0 = load_lr_mv(t);
    vec2 g[2];
    for (int axis = 0; axis < 2; ++axis) {
        ivec2 step = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
        int lim = axis == 0 ? int(p.lr_width) - 1 : int(p.lr_height) - 1;
        int c = axis == 0 ? t.x : t.y;
        ivec2 lo_q = t - step, hi_q = t + step;
        bool lo_ok = c > 0 && relative_depth_difference(load_lr_depth(lo_q), d_now) <= p.t_depth;
        bool hi_ok = c < lim && relative_depth_difference(load_lr_depth(hi_q), d_now) <= p.t_depth;
        vec2 m_lo = lo_ok ? load_lr_mv(lo_q) : m0, m_hi = hi_ok ? load_lr_mv(hi_q) : m0;
        float span = float(int(lo_ok) + int(hi_ok));
        g[axis] = span > 0.0f ? (m_hi - m_lo) / span : vec2(0.0f);
    }
    return expansion_depth_scale(g[0], g[1]);
}

#define SR_NOISE_R0 0.35f
#define SR_NOISE_GAIN 4.0f
#define SR_NOISE_CUT 0.4f
#define SR_KERNEL_R0 0.6f
#define SR_KERNEL_GAIN 4.0f
#define SR_KERNEL_Q1 0.9f
#define SR_KERNEL_Q_SPAN 0.4f

// The stage before the pass (variant sr_noise), one invocation per LR pixel t: (r, q) of steps 3
// and 7 over t's 3x3 samples on t's surface; r < 0 where fewer than 4 take part.
FGSR_INLINE vec2 noise_stats(ivec2 t, vec2 jitter, SrParams p) {
    ivec2 size = ivec2(int(p.hr_width), int(p.hr_height));
    float d_now = load_lr_depth(t);
    float sum = 0.0f, sum2 = 0.0f, diff = 0.0f, diff2 = 0.0f, hsum = 0.0f, hsum2 = 0.0f, count = 0.0f;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 s = clamp_lr(t + ivec2(x, y), p);
            if (!(relative_depth_difference(load_lr_depth(s), d_now) <= p.t_depth)) continue;
            float l = linear_luminance(load_lr_color(s));
            vec2 prev = (vec2(s) + vec2(0.5f) + jitter + load_lr_mv(s)) * p.scale;
            float hl = linear_luminance(resample(prev, size, RESAMPLE_BILINEAR));
            float e = l - hl;
            sum += l;
            sum2 += l * l;
            hsum += hl;
            hsum2 += hl * hl;
            diff += e;
            diff2 += e * e;
            count += 1.0f;
        }
    if (count < 4.0f) return vec2(-1.0f, 0.0f);
    float mean = sum / count, bias = diff / count, hmean = hsum / count;
    float variance = max(sum2 / count - mean * mean, 1.0e-6f);
    return vec2((diff2 / count - bias * bias) / variance, max(hsum2 / count - hmean * hmean, 0.0f) / variance);
}

// Step 7: the factor (1 - SR_NOISE_CUT) .. 1 of the new samples' weight, from r.
FGSR_INLINE float noise_weight(float r) {
    if (r < 0.0f) return 1.0f;
    return 1.0f - SR_NOISE_CUT * clamp((r - SR_NOISE_R0) * SR_NOISE_GAIN, 0.0f, 1.0f);
}

// Step 3: how far (0..1) the LUT's weights move towards the cubic B-spline's, from (r, q).
FGSR_INLINE float kernel_smoothing(vec2 rq) {
    if (rq.x < 0.0f) return 0.0f;
    return clamp((rq.x - SR_KERNEL_R0) * SR_KERNEL_GAIN, 0.0f, 1.0f) *
           clamp((SR_KERNEL_Q1 - rq.y) / SR_KERNEL_Q_SPAN, 0.0f, 1.0f);
}

// Step 2's depth test: does the previous depth at the history's position belong to t's surface?
FGSR_INLINE bool history_depth_matches(ivec2 t, float d_now, float d_prev, SrParams p) {
    if (relative_depth_difference(d_now, d_prev) <= p.t_depth) return true;
    if ((p.flags & SR_DEPTH_MOTION) == 0u) return false;
    float moved = d_now * motion_depth_scale(t, d_now, p);
    return d_prev >= min(d_now, moved) / (1.0f + p.t_depth) && d_prev <= max(d_now, moved) * (1.0f + p.t_depth);
}

FGSR_INLINE vec4 super_resolve(ivec2 q, SrParams p) {
    vec2 qc = vec2(q) + vec2(0.5f);
    vec2 pos = qc / p.scale;
    ivec2 t = clamp_lr(ivec2(floor(pos)), p);
    vec2 jitter = vec2(p.jitter_x, p.jitter_y);

    // Current samples, their colour box and the Eq. 2 weights.
    vec4 lo = vec4(1.0e30f), hi = vec4(-1.0e30f), sum = vec4(0.0f);
    float wsum = 0.0f, n = 0.0f, nearest_depth = FGSR_FAR_DEPTH;
    ivec2 front = t;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 s = clamp_lr(t + ivec2(x, y), p);
            vec4 c = load_lr_color(s);
            lo = min(lo, c);
            hi = max(hi, c);
            float d = length(vec2(s) + vec2(0.5f) + jitter - pos);
            if (d < 1.0f) {
                float w = max(1.0f - p.b * d, 0.0f);
                sum += w * c;
                wsum += w;
                n += 1.0f;
            }
            float z = load_lr_depth(s);
            if (p.dilate != 0u && z < nearest_depth) {
                nearest_depth = z;
                front = s;
            }
        }
    // The spatial upsample (16 taps) is computed only where it is the answer (or, with
    // SR_SHARP_CURRENT, the current samples' term).
    if (p.has_history == 0u || n == 0.0f) return lr_upsample(pos - jitter, p);

    vec2 mv = load_lr_mv(p.dilate != 0u ? front : t);
    vec2 h = qc + mv * p.scale;
    bool on = h.x >= 0.0f && h.y >= 0.0f && h.x <= float(p.hr_width) && h.y <= float(p.hr_height);
    float d_now = load_lr_depth(t);
    float d_prev = load_prev_depth(clamp_lr(ivec2(floor(pos + mv)), p));
    if (!on || !history_depth_matches(t, d_now, d_prev, p)) return lr_upsample(pos - jitter, p);

    ivec2 hr_size = ivec2(int(p.hr_width), int(p.hr_height));
    // The host sets SR_NOISE_KERNEL for the LUT only, but static tiles read bilinearly (tiles.cpp).
    bool smoothed = (p.flags & SR_NOISE_KERNEL) != 0u && p.resample == RESAMPLE_LUT;
    vec4 hist = smoothed ? resample_lut_smoothed(h, hr_size, kernel_smoothing(load_noise(t))) : resample(h, hr_size, p.resample);
    hist = clamp(hist, lo, hi);
    float wh = 1.0f - p.a; // the history's weight (step 6 lowers it)
    if (p.disagree > 0.0f && wsum > 0.0f) {
        float e = length(vec3(hist) - vec3(sum) / wsum) / max(length(vec3(hi) - vec3(lo)), 1.0e-4f);
        wh *= max(0.0f, 1.0f - p.disagree * e);
    }
    // With a = 1 (or the history's weight 0) and every sample weighted 0 (b * d >= 1) Eq. 2 has
    // no term left (0 / 0).
    float a = (p.flags & SR_NOISE_AVERAGE) != 0u ? p.a * noise_weight(load_noise(t).x) : p.a;
    float wc = a * wsum / n;
    float norm = wc + wh;
    if (!(norm > 0.0f)) return lr_upsample(pos - jitter, p);
    if ((p.flags & SR_SHARP_CURRENT) != 0u) return (wc * lr_upsample(pos - jitter, p) + wh * hist) / norm;
    return (a * sum / n + wh * hist) / norm;
}
