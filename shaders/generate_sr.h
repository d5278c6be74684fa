// Pass `generate_sr` (paper 3.5, last paragraph): interpolation (Ours-ISR) and extrapolation
// (Ours-ESR) at output resolution. The motion field is reconstructed at input resolution (splat
// and refine / disocc, as in frame generation) and read at the input pixel under each output
// pixel; its vectors scale to output pixels. One reprojection serves both: the SR history warp
// (resample.h with s.resample = Params::warp_resample, bilinear by default: these positions come
// from frame generation's motion, and the sharp kernels lost to it, docs/ACCURACY.md change 10)
// replaces the plain warp.
//   ESR: the frame at 1 + alpha is the newest SR output (I_1^sr) resampled at q + v1 * scale;
//        a hole whose frame-1 sample lies on the surface that left takes input frame 0 instead
//        (warp.h, frame0_behind; docs/ACCURACY.md change 50).
//   ISR: frame 0 is the previous SR output (I_0^sr) resampled at q + v0 * scale; frame 1 is the
//        newest low-resolution frame itself (no wait for its SR), read bilinearly at its jittered
//        input position; blend.h selects / blends them with input-resolution depths.
//   Both: the resampled history is clipped per channel to mean +- clip * sd of the 3x3
//        neighbourhood of the low-resolution frame of the same instant (frame 0 for ISR, frame 1
//        for ESR) around the history position (variance clipping, as temporal antialiasing does).
//        The SR history is sharp and carries what the point-sampled inputs alias; where the
//        motion is fast it is also reprojected over two input intervals, and the clip keeps it
//        from straying further from the rendered samples than their own spread (street-sr isr
//        15.90 -> 17.13 dB, docs/ACCURACY.md change 2); on antialiased input the neighbourhood is
//        low-passed and the width wider (Params::sr_clip_antialiased, change 47). clip = 0: no
//        clipping. Frame 0's neighbourhood is centred without its jitter (the session keeps only
//        frame 1's): at most half an input pixel off, on a window of three.
//
// Entry provides the loads of refine.h and warp.h (input resolution), and of resample.h:
//   vec4 load_src(ivec2 out_pixel)   I_0^sr (ISR) or I_1^sr (ESR)

// `h` clipped to the mean +- s.clip standard deviations of frame `frame`'s LR 3x3 neighbourhood
// around the LR position `lr_pos` (pixel units); unchanged when s.clip is 0.
FGSR_INLINE vec4 clip_history(vec4 h, uint frame, vec2 lr_pos, GenParams g, SrParams s) {
    if (s.clip <= 0.0f) return h;
    ivec2 t = clamp_pixel(ivec2(floor(lr_pos)), g);
    vec4 m1 = vec4(0.0f), m2 = vec4(0.0f);
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 n = clamp_pixel(t + ivec2(x, y), g);
            vec4 c = frame == 0u ? load_color0(n) : load_color1(n);
            m1 += c;
            m2 += c * c;
        }
    vec4 mean = m1 / 9.0f;
    vec4 sd = sqrt(max(m2 / 9.0f - mean * mean, vec4(0.0f)));
    return clamp(h, mean - s.clip * sd, mean + s.clip * sd);
}

// The input pixel whose field output pixel q takes.
FGSR_INLINE ivec2 generate_sr_field_pixel(ivec2 q, GenParams g, SrParams s) {
    vec2 pos = (vec2(q) + vec2(0.5f)) / s.scale;
    return clamp(ivec2(floor(pos)), ivec2(0), ivec2(int(g.width) - 1, int(g.height) - 1));
}

// Output pixel q from the field vectors v and state of its input pixel (the part of
// generate_sr_pixel after refine / disocc; the CPU form of generate_sr reads both from the field
// the separate refine and disocc passes wrote, generate_sr.comp FGSR_SR_FIELD).
FGSR_INLINE vec4 generate_sr_finish(ivec2 q, vec4 v, uint state, GenParams g, SrParams s) {
    vec2 qc = vec2(q) + vec2(0.5f);
    vec2 pos = qc / s.scale;
    ivec2 out_size = ivec2(int(s.hr_width), int(s.hr_height));
    if (g.extrapolate != 0u) {
        if (hole_may_take_frame0(state, g)) {
            // A hole whose frame-1 sample lies on the surface that left (warp.h, frame0_behind):
            // input frame 0 (its SR output is not kept), as frame generation takes it.
            vec2 lr = pos - vec2(s.jitter_x, s.jitter_y);
            WarpSample w1 = warp_sample(1u, lr, vec2(v.z, v.w), g);
            WarpSample w0 = warp_sample(0u, lr, vec2(v.x, v.y), g);
            if (frame0_behind(w0.depth, w1.depth, g)) return w0.color;
        }
        vec2 h1 = qc + vec2(v.z, v.w) * s.scale;
        vec4 c1 = max(resample(h1, out_size, s.resample), vec4(0.0f));
        return clip_history(c1, 1u, h1 / s.scale - vec2(s.jitter_x, s.jitter_y), g, s);
    }

    vec2 p0 = qc + vec2(v.x, v.y) * s.scale;
    bool ok0 = p0.x >= 0.0f && p0.y >= 0.0f && p0.x <= float(s.hr_width) && p0.y <= float(s.hr_height);
    vec4 c0 = clip_history(max(resample(p0, out_size, s.resample), vec4(0.0f)), 0u, p0 / s.scale, g, s);
    float d0 = ok0 ? load_depth0(clamp_pixel(ivec2(floor(p0 / s.scale)), g)) : -1.0f;
    vec2 lr1 = pos - vec2(s.jitter_x, s.jitter_y);
    WarpSample w1 = warp_sample(1u, lr1, vec2(v.z, v.w), g);
    vec2 d = blend_depths(d0, w1.depth, w1.pixel, g);
    return select_blend(c0, d.x, w1.color, d.y, state, g);
}

FGSR_INLINE vec4 generate_sr_pixel(ivec2 q, GenParams g, SrParams s) {
    ivec2 t = generate_sr_field_pixel(q, g, s);
    FieldSample f = refine_field(t, g);
    if (f.state == FIELD_HOLE && g.fill_holes != 0u) f = fill_hole(t, g);
    return generate_sr_finish(q, f.v, f.state, g, s);
}
