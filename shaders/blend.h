// Pass `blend` (paper 3.4, Eq. 1): selects or blends the two warped frames of an interpolation.
//   dD = (d0 - d1) / min(d0, d1)   relative depth difference of the warped frames
//   dB = luma(display(c0)) - luma(display(c1)), display = sRGB-encoded, clamped to [0,1]
//   dD >  T_D                  -> frame 0 (frame 1 sees an occluder that is not here at alpha)
//   dD < -T_D                  -> frame 1
//   similar depth, |dB| <= T_B -> the temporally closer frame (alpha <= 0.5: frame 0), or with
//                                 blend_mode 1 the alpha-weighted mix
//   similar depth, |dB| >  T_B -> lerp(c0, c1, alpha) (shading change)
// A sample whose position left the screen loses to the other; holes seen only by frame 0
// (FIELD_HOLE_FILLED) take frame 0.
//
// Entry provides:
//   vec4  load_warped_color(uint index, uint frame)
//   float load_warped_depth(uint index, uint frame)
//   uint  load_field_state(ivec2 pixel)
//   void  store_output(uint index, vec4 color)

FGSR_INLINE float display_luma(vec4 c) {
    vec3 s = clamp(vec3(c.x, c.y, c.z), vec3(0.0f), vec3(1.0f));
    vec3 e = vec3(s.x <= 0.0031308f ? 12.92f * s.x : 1.055f * pow(s.x, 1.0f / 2.4f) - 0.055f,
                  s.y <= 0.0031308f ? 12.92f * s.y : 1.055f * pow(s.y, 1.0f / 2.4f) - 0.055f,
                  s.z <= 0.0031308f ? 12.92f * s.z : 1.055f * pow(s.z, 1.0f / 2.4f) - 0.055f);
    return dot(e, vec3(0.2126f, 0.7152f, 0.0722f));
}

FGSR_INLINE vec4 select_blend(vec4 c0, float d0, vec4 c1, float d1, uint state, GenParams g) {
    bool ok0 = d0 >= 0.0f;
    bool ok1 = d1 >= 0.0f;
    if (state == FIELD_HOLE_FILLED) return ok0 || !ok1 ? c0 : c1;
    if (ok0 != ok1) return ok0 ? c0 : c1;
    float dd = (d0 - d1) / max(min(d0, d1), 1.0e-20f); // signed relative_depth_difference
    if (dd > g.t_depth) return c0;
    if (dd < -g.t_depth) return c1;
    float db = abs(display_luma(c0) - display_luma(c1));
    if (db > g.t_bright || g.blend_mode != 0u) return mix(c0, c1, g.alpha);
    return g.alpha <= 0.5f ? c0 : c1;
}

FGSR_INLINE void blend_pixel(ivec2 t, GenParams g) {
    if (t.x >= int(g.width) || t.y >= int(g.height)) return;
    uint i = uint(t.y) * g.width + uint(t.x);
    store_output(i, select_blend(load_warped_color(i, 0u), load_warped_depth(i, 0u), load_warped_color(i, 1u),
                                 load_warped_depth(i, 1u), load_field_state(t), g));
}
