// Pass `generate_sr` (paper 3.5, last paragraph): interpolation (Ours-ISR) and extrapolation
// (Ours-ESR) at output resolution. The motion field is reconstructed at input resolution (splat
// and refine / disocc, as in frame generation) and read at the input pixel under each output
// pixel; its vectors scale to output pixels. One reprojection serves both: the SR history warp
// (resample.h, the LUT by default) replaces the plain warp.
//   ESR: the frame at 1 + alpha is the newest SR output (I_1^sr) resampled at q + v1 * scale.
//   ISR: frame 0 is the previous SR output (I_0^sr) resampled at q + v0 * scale; frame 1 is the
//        newest low-resolution frame itself (no wait for its SR), read bilinearly at its jittered
//        input position; blend.h selects / blends them with input-resolution depths.
//
// Entry provides the loads of refine.h and warp.h (input resolution), and of resample.h:
//   vec4 load_src(ivec2 out_pixel)   I_0^sr (ISR) or I_1^sr (ESR)

FGSR_INLINE vec4 generate_sr_pixel(ivec2 q, GenParams g, SrParams s) {
    vec2 qc = vec2(q) + vec2(0.5f);
    vec2 pos = qc / s.scale;
    ivec2 t = clamp(ivec2(floor(pos)), ivec2(0), ivec2(int(g.width) - 1, int(g.height) - 1));
    FieldSample f = refine_field(t, g);
    if (f.state == FIELD_HOLE && g.fill_holes != 0u) f = fill_hole(t, g);
    ivec2 out_size = ivec2(int(s.hr_width), int(s.hr_height));
    if (g.extrapolate != 0u) return max(resample(qc + vec2(f.v.z, f.v.w) * s.scale, out_size, s.resample), vec4(0.0f));

    vec2 p0 = qc + vec2(f.v.x, f.v.y) * s.scale;
    bool ok0 = p0.x >= 0.0f && p0.y >= 0.0f && p0.x <= float(s.hr_width) && p0.y <= float(s.hr_height);
    vec4 c0 = max(resample(p0, out_size, s.resample), vec4(0.0f));
    float d0 = load_depth0(clamp_pixel(ivec2(floor(p0 / s.scale)), g));
    WarpSample w1 = warp_sample(1u, pos - vec2(s.jitter_x, s.jitter_y), vec2(f.v.z, f.v.w), g);
    return select_blend(c0, ok0 ? d0 : -1.0f, w1.color, w1.depth, f.state, g);
}
