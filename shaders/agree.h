// Pass `agree` (Params::colour_agree): frame generation in a session with vectors that also
// estimates motion from colour, as colour-only sessions do, and generates the frame from both
// fields. Per pixel it takes the frame whose two warped inputs agree better (interpolation), or
// whose vectors explain the newest input better (extrapolation, stage 4 below).
//
// Where shading moves on its own (a shadow sweeping over still ground, the contact shadow of a
// rolling ball, sunlight that travels with the camera), no vector of the surface carries it: warped
// with the given vectors, frame 0 and frame 1 disagree at the same surface point (one lit, one in
// shadow) and their blend shows the shadow twice at half strength. Colour-only motion follows the
// shading, and its two warped frames agree there. Where the given vectors describe the colour,
// their warped frames agree and the given frame is kept (docs/ACCURACY.md, change 33).
//
//   1. e = (e_given, e_colour) per pixel: |brightness(W0) - brightness(W1)| of each field's warped
//      frames where both are on screen and of one surface: depths within depth_band x T_D
//      (relative), wider than blend's T_D, which a surface the camera approaches leaves between
//      the two frames (blend then takes the nearer frame, and its shading is still the wrong
//      one's); else 0 (an occlusion, a disocclusion, content leaving, a hole only frame 0 sees).
//      For the given field the band first expects the depth change its motion implies: a surface
//      patch's size on screen goes as 1 / depth, so frame 0's depth is frame 1's times
//      s = sqrt(det(I + grad v1) / det(I + grad v0)) for a patch facing the camera, v0 and v1 the
//      field's displacements to the two frames (central differences over the neighbours on the
//      pixel's surface: frame-1 depths within T_D; s clamped to [1/2, 2]). A slanted patch changes
//      by less, so frame 0's depth may lie anywhere between d1 and d1 x s before the band counts
//      (change 37; as the motion's frame-0 test does, change 21). Where the field neither expands
//      nor shrinks (s = 1) this is the plain test.
//      With gain > 1 (interpolation; change 42), a field's brightness gain between its two warped
//      frames is forgiven up to that factor: e = |b0 - g b1|, g = clamp(S0 / S1, 1 / gain, gain),
//      S0 and S1 the sums of b0 and b1 over the box of side 2 gain_radius + 1 around the pixel of
//      the pixels on screen in both frames (stages 5-7). A surface that turns towards or away from
//      the light (a pitched blade, a slat) changes its shading uniformly, by a few percent a frame:
//      its vectors still place it, and without the gain its warped frames would disagree as if its
//      shading moved on its own. A shadow changes the brightness by far more than the gain allows
//      (and pixels it does not cover, in the same box, by less): its sweep still counts, less at
//      most the gain.
//   2. Means of e over the box of side 2 radius + 1 around the pixel (clamped to the frame), as
//      two separable stages: rows, then columns, each a running sum along a segment of
//      AGREE_SEGMENT pixels per invocation.
//   3. w = 1 / (1 + exp((mean e_colour + centre - ratio x mean e_given) / softness)) x
//      clamp(1 - mean e_colour / colour_limit, 0, 1) (where neither field explains the colour, the
//      given frame is kept more; change 35); the result is mix(given frame, colour frame, w). The
//      logistic mixes the two frames evenly where the given field disagrees by centre more, and
//      where both agree equally still takes a small share (0.076 at the defaults) of the colour
//      frame: made from independent estimates, the two frames err differently, and a little of
//      the other lowers the error where neither disagreement tells them apart (change 43; until
//      then a ramp from 0 at a margin of 0.02 to 1 at 0.04, which kept the given frame alone there).
//
// Extrapolation has one warped frame, so no two to disagree: stage 1 is then the fields' residual
// at the newest input (stage 4, agree_residual), and stages 2 and 3 follow on the extrapolated frames:
//   4. e = (e_given, e_colour) at frame-1 pixel t: |brightness(frame 1 at t) - brightness(frame 0
//      at t + mv)| for each field's frame-1 vector mv (frame 0 read bilinearly); 0 where t + mv
//      leaves the frame, and for the given field where frame 0's depth there (nearest pixel) is not
//      t's surface (a disocclusion, which no vector explains): as in stage 1, the depth change the
//      field's frame-1 vectors imply is expected (change 37), then depth_band x T_D, a wider band
//      than stage 1's (change 36). The weights are
//      those of frame-1 pixels, applied at the extrapolated frame's pixels: the box spans 21
//      pixels, the half step of motion between them lies mostly inside it.

// With super resolution both fields' frames (ISR and ESR alike: the joint pass makes no warped frames
// at the input's size for stage 1) are at the output's size, and the weights are stage 4's (the
// residual of each field's frame-1 vectors, a property of the field rather than of the instant, so
// that it serves an interpolated frame as an extrapolated one); stages 4 and 2 run at the input's
// size, and stage 3 splits in two:
//   8. stage 3's box means along the columns, stored per input pixel (in place of stage 1's e,
//      which stage 2 has read);
//   9. per output pixel, the means read bilinearly at its position in the input, then stage 3's
//      weight and mix (docs/ACCURACY.md, change 45).
//
// Entry provides:
//   vec4  load_warped(uint field, uint frame, uint i)   field 0: given, 1: colour; frame 0 or 1
//   float load_warped_depth(uint field, uint frame, uint i)
//   uint  load_field_state(uint field, uint i)
//   vec2  load_e(uint i), load_rows(uint i)
//   void  store_rows(uint i, vec2 means)                 stage 2
//   vec4  load_given(uint i), load_colour(uint i)
//   void  store_agreed(uint i, vec4 colour)              stages 3 and 9 (9: i of the output's size)
//   void  store_means(uint i, vec2 means)                stage 8, into the e buffer
//   vec4  load_given_field(uint i)                       the given field's (v0, v1) (stage 1)
//   vec4  load_light(uint i), load_light_rows(uint i)    stages 5-7: (given b0, b1, colour b0, b1)
//   void  store_light(uint i, vec4), store_light_rows(uint i, vec4)  per pixel, its row sums; stage 7
//                                                        stores the box sums in the light buffer
// and for stage 4:
//   vec4  load_frame_colour(uint frame, uint i)          the inputs, frame 0 or 1 (newest)
//   float load_frame_depth(uint frame, uint i)
//   vec2  load_field_mv(uint field, uint i)              frame 1's vectors of each field
//   vec2  load_mv1(ivec2), float load_depth1(ivec2)      the given field's frame-1 vectors and
//                                                        frame 1's depth (depth_change.h)

#include "depth_change.h"

// Stage 1's expected depth change of the given field at pixel t, whose frame-1 depth is d1: the
// range (min(1, s), max(1, s)) of d0 / d1.
FGSR_INLINE vec2 given_depth_range(ivec2 t, float d1, AgreeParams p) {
    vec4 v = load_given_field(uint(t.y) * p.g.width + uint(t.x));
    vec4 g[2];
    for (int axis = 0; axis < 2; ++axis) {
        ivec2 step = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
        int lim = axis == 0 ? int(p.g.width) - 1 : int(p.g.height) - 1;
        int c = axis == 0 ? t.x : t.y;
        uint lo = uint(t.y - step.y) * p.g.width + uint(t.x - step.x);
        uint hi = uint(t.y + step.y) * p.g.width + uint(t.x + step.x);
        float d_lo = c > 0 ? load_warped_depth(0u, 1u, lo) : -1.0f;
        float d_hi = c < lim ? load_warped_depth(0u, 1u, hi) : -1.0f;
        bool lo_ok = d_lo >= 0.0f && relative_depth_difference(d_lo, d1) <= p.g.t_depth;
        bool hi_ok = d_hi >= 0.0f && relative_depth_difference(d_hi, d1) <= p.g.t_depth;
        vec4 v_lo = lo_ok ? load_given_field(lo) : v, v_hi = hi_ok ? load_given_field(hi) : v;
        float span = float(int(lo_ok) + int(hi_ok));
        g[axis] = span > 0.0f ? (v_hi - v_lo) / span : vec4(0.0f);
    }
    float det0 = (1.0f + g[0].x) * (1.0f + g[1].y) - g[1].x * g[0].y;
    float det1 = (1.0f + g[0].z) * (1.0f + g[1].w) - g[1].z * g[0].w;
    float s = sqrt(clamp(det1 / max(det0, 1.0e-3f), 0.25f, 4.0f));
    return vec2(min(1.0f, s), max(1.0f, s));
}

// Stage 1: one field's disagreement at pixel t, its frame-1 brightness scaled by g (the field's
// fitted gain, 1 without), and both fields' (given, colour).
FGSR_INLINE float field_disagreement(uint field, ivec2 t, float g, AgreeParams p) {
    uint i = uint(t.y) * p.g.width + uint(t.x);
    float d0 = load_warped_depth(field, 0u, i), d1 = load_warped_depth(field, 1u, i);
    if (load_field_state(field, i) == FIELD_HOLE_FILLED || !(d0 >= 0.0f) || !(d1 >= 0.0f)) return 0.0f;
    float band = p.depth_band * p.g.t_depth;
    // Beyond the plain band, the given field's frame 0 may still be the surface, where its motion
    // implies the depth change (the range contains 1, so it only ever accepts more).
    if (relative_depth_difference(d0, d1) > band &&
        (field != 0u || surface_distance0(d0, d1, vec3(given_depth_range(t, d1, p), 0.0f)) > band))
        return 0.0f;
    return abs(brightness(load_warped(field, 0u, i)) - g * brightness(load_warped(field, 1u, i)));
}
// A field's gain from its box sums of frame-0 and frame-1 brightness (stage 7), within the bound.
FGSR_INLINE float fitted_gain(float s0, float s1, AgreeParams p) {
    return s1 > 1.0e-4f ? clamp(s0 / s1, 1.0f / p.gain, p.gain) : 1.0f;
}
FGSR_INLINE vec2 agree_error(ivec2 t, AgreeParams p) {
    vec2 g = vec2(1.0f);
    if (p.gain > 1.0f) {
        vec4 sums = load_light(uint(t.y) * p.g.width + uint(t.x)); // (given S0, S1, colour S0, S1)
        g = vec2(fitted_gain(sums.x, sums.y, p), fitted_gain(sums.z, sums.w, p));
    }
    return vec2(field_disagreement(0u, t, g.x, p), field_disagreement(1u, t, g.y, p));
}

// Stages 2 and 3 walk AGREE_SEGMENT pixels of a row (stage 2) or a column (stage 3) per invocation
// with one running sum over the box's side: about 3 reads a pixel instead of 2 radius + 1 (the sum
// is started afresh each segment, so its rounding does not build up along the frame).

// Stage 2: the means of e along row s.y within radius of each pixel (clamped to the frame), for the
// pixels of segment s.x.
FGSR_INLINE void agree_rows_segment(uvec2 s, AgreeParams p) {
    int w = int(p.g.width), r = int(p.radius);
    int x0 = int(s.x * AGREE_SEGMENT);
    if (x0 >= w || s.y >= p.g.height) return;
    int x1 = min(x0 + int(AGREE_SEGMENT), w);
    uint row = s.y * p.g.width;
    int lo = max(x0 - r, 0), hi = min(x0 + r, w - 1);
    vec2 sum = vec2(0.0f);
    for (int x = lo; x <= hi; ++x) sum += load_e(row + uint(x));
    for (int x = x0; x < x1; ++x) {
        store_rows(row + uint(x), sum / float(hi - lo + 1));
        if (x - r >= 0) { // the box of x + 1 leaves x - r behind
            sum -= load_e(row + uint(x - r));
            lo = x - r + 1;
        }
        if (x + r + 1 < w) { // ... and reaches x + r + 1
            sum += load_e(row + uint(x + r + 1));
            hi = x + r + 1;
        }
    }
}

// Stage 3 at pixel i with its box means e: the colour frame's weight and the result.
FGSR_INLINE vec4 agree_mix_pixel(uint i, vec2 e, AgreeParams p) {
    float w = 1.0f / (1.0f + exp((e.y + p.centre - p.ratio * e.x) / p.softness));
    if (p.colour_limit > 0.0f) w *= clamp((p.colour_limit - e.y) / p.colour_limit, 0.0f, 1.0f);
    return mix(load_given(i), load_colour(i), w);
}

// Stage 3: the box means along column s.x (of stage 2's row means), then the mix, for the pixels of
// segment s.y; with means_only (stage 8), the means into the e buffer instead (store_means).
FGSR_INLINE void agree_column_segment(uvec2 s, bool means_only, AgreeParams p) {
    int h = int(p.g.height), r = int(p.radius);
    int y0 = int(s.y * AGREE_SEGMENT);
    if (s.x >= p.g.width || y0 >= h) return;
    int y1 = min(y0 + int(AGREE_SEGMENT), h);
    int lo = max(y0 - r, 0), hi = min(y0 + r, h - 1);
    vec2 sum = vec2(0.0f);
    for (int y = lo; y <= hi; ++y) sum += load_rows(uint(y) * p.g.width + s.x);
    for (int y = y0; y < y1; ++y) {
        uint i = uint(y) * p.g.width + s.x;
        if (means_only)
            store_means(i, sum / float(hi - lo + 1));
        else
            store_agreed(i, agree_mix_pixel(i, sum / float(hi - lo + 1), p));
        if (y - r >= 0) {
            sum -= load_rows(uint(y - r) * p.g.width + s.x);
            lo = y - r + 1;
        }
        if (y + r + 1 < h) {
            sum += load_rows(uint(y + r + 1) * p.g.width + s.x);
            hi = y + r + 1;
        }
    }
}

// Stage 9: the mix at output pixel t of frames of p.out_width x p.out_height (super resolution),
// by stage 8's box means at g's size, read bilinearly at t's position there (pixel centres
// aligned, clamped to the frame): the scale need not be an integer.
FGSR_INLINE void agree_mix_upscaled(ivec2 t, AgreeParams p) {
    vec2 to_input = vec2(float(p.g.width), float(p.g.height)) / vec2(float(p.out_width), float(p.out_height));
    vec2 last = vec2(float(p.g.width - 1u), float(p.g.height - 1u));
    vec2 q = clamp((vec2(t) + 0.5f) * to_input - 0.5f, vec2(0.0f), last);
    ivec2 a = ivec2(floor(q));
    ivec2 b = min(a + ivec2(1), ivec2(last));
    vec2 f = q - vec2(a);
    uint w = p.g.width;
    vec2 top = mix(load_e(uint(a.y) * w + uint(a.x)), load_e(uint(a.y) * w + uint(b.x)), f.x);
    vec2 bottom = mix(load_e(uint(b.y) * w + uint(a.x)), load_e(uint(b.y) * w + uint(b.x)), f.x);
    uint i = uint(t.y) * p.out_width + uint(t.x);
    store_agreed(i, agree_mix_pixel(i, mix(top, bottom, f.y), p));
}

// Stage 5: each field's brightness in its two warped frames where both are on screen, else 0:
// (given b0, given b1, colour b0, colour b1).
FGSR_INLINE vec4 agree_light(ivec2 t, AgreeParams p) {
    uint i = uint(t.y) * p.g.width + uint(t.x);
    vec4 l = vec4(0.0f);
    if (load_warped_depth(0u, 0u, i) >= 0.0f && load_warped_depth(0u, 1u, i) >= 0.0f) {
        l.x = brightness(load_warped(0u, 0u, i));
        l.y = brightness(load_warped(0u, 1u, i));
    }
    if (load_warped_depth(1u, 0u, i) >= 0.0f && load_warped_depth(1u, 1u, i) >= 0.0f) {
        l.z = brightness(load_warped(1u, 0u, i));
        l.w = brightness(load_warped(1u, 1u, i));
    }
    return l;
}

// Stages 6 and 7: the box sums of stage 5 within gain_radius of each pixel (clamped to the frame),
// separable, with a running sum as stages 2 and 3: along row s.y for the pixels of segment s.x
// (stage 6, the light buffer into the row sums), then along column s.x for the pixels of segment
// s.y (stage 7, the row sums into the light buffer, over stage 5's values, which stage 6 has read:
// the box sums stage 1 reads).
FGSR_INLINE vec4 agree_light_in(bool columns, uint i) {
    return columns ? load_light_rows(i) : load_light(i);
}
FGSR_INLINE void agree_light_segment(uvec2 s, bool columns, AgreeParams p) {
    int len = int(columns ? p.g.height : p.g.width), r = int(p.gain_radius);
    uint line = columns ? s.x : s.y;
    int a0 = int((columns ? s.y : s.x) * AGREE_SEGMENT);
    if (a0 >= len || line >= (columns ? p.g.width : p.g.height)) return;
    int a1 = min(a0 + int(AGREE_SEGMENT), len);
    uint base = columns ? line : line * p.g.width, stride = columns ? p.g.width : 1u;
    vec4 sum = vec4(0.0f);
    for (int a = max(a0 - r, 0); a <= min(a0 + r, len - 1); ++a)
        sum += agree_light_in(columns, base + uint(a) * stride);
    for (int a = a0; a < a1; ++a) {
        uint i = base + uint(a) * stride;
        if (columns)
            store_light(i, sum);
        else
            store_light_rows(i, sum);
        if (a - r >= 0) sum -= agree_light_in(columns, base + uint(a - r) * stride);
        if (a + r + 1 < len) sum += agree_light_in(columns, base + uint(a + r + 1) * stride);
    }
}

// Stage 4: one field's residual at frame-1 pixel t, and both fields' (given, colour).
FGSR_INLINE float frame_brightness(uint frame, ivec2 q, AgreeParams p) {
    return brightness(load_frame_colour(frame, uint(q.y) * p.g.width + uint(q.x)));
}
FGSR_INLINE float field_residual(uint field, ivec2 t, AgreeParams p) {
    uint i = uint(t.y) * p.g.width + uint(t.x);
    vec2 q = vec2(t) + load_field_mv(field, i); // frame 0, pixel centres at integers
    vec2 last = vec2(float(p.g.width - 1u), float(p.g.height - 1u));
    if (!(q.x >= 0.0f && q.y >= 0.0f && q.x <= last.x && q.y <= last.y)) return 0.0f;
    if (field == 0u) {
        ivec2 c = ivec2(floor(q + vec2(0.5f)));
        float d1 = load_frame_depth(1u, i), d0 = load_frame_depth(0u, uint(c.y) * p.g.width + uint(c.x));
        if (!(d0 > 0.0f) || !(d1 > 0.0f)) return 0.0f;
        float band = p.depth_band * p.g.t_depth;
        if (relative_depth_difference(d0, d1) > band) { // as in stage 1, then the motion's depth change
            float s = frame1_depth_scale(t, d1, load_field_mv(0u, i), p.g);
            if (surface_distance0(d0, d1, vec3(min(1.0f, s), max(1.0f, s), 0.0f)) > band) return 0.0f;
        }
    }
    ivec2 a = ivec2(floor(q));
    ivec2 b = min(a + ivec2(1), ivec2(last));
    vec2 f = q - vec2(a);
    float top = mix(frame_brightness(0u, a, p), frame_brightness(0u, ivec2(b.x, a.y), p), f.x);
    float bottom = mix(frame_brightness(0u, ivec2(a.x, b.y), p), frame_brightness(0u, b, p), f.x);
    return abs(frame_brightness(1u, t, p) - mix(top, bottom, f.y));
}
FGSR_INLINE vec2 agree_residual(ivec2 t, AgreeParams p) {
    return vec2(field_residual(0u, t, p), field_residual(1u, t, p));
}
