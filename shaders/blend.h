// Pass `blend` (paper 3.4, Eq. 1): selects or blends the two warped frames of an interpolation.
//   dD = (d0 - e) / min(d0, e)   relative depth difference of the warped frames, e = d1 or, with
//        BLEND_DEPTH_MOTION, d0 clamped to the depths at which frame 0 may show the surface frame 1
//        shows: [d1 lo, d1 hi], from the depth change frame 1's vectors imply and the surface's
//        slope (depth_change.h, blend_depth_band). Each warped depth is its own frame's: on a
//        surface the camera approaches by more than T_D a frame step the plain test takes frame 0
//        alone and never mixes (docs/ACCURACY.md, change 38).
//   dB = brightness(c0) - brightness(c1), brightness = sqrt of linear luminance clamped to [0,1]
//        (display-referred lightness with a gamma of 2, close to sRGB and 6 pow() cheaper)
//   dD >  T_D                  -> frame 0 (frame 1 sees an occluder that is not here at alpha)
//   dD < -T_D                  -> frame 1
//   similar depth, |dB| <= T_B -> the temporally closer frame (alpha <= 0.5: frame 0), or with
//                                 BLEND_MIX the alpha-weighted mix
//   similar depth, |dB| >  T_B -> lerp(c0, c1, alpha) (shading change)
// A sample whose position left the screen loses to the other; holes seen only by frame 0
// (FIELD_HOLE_FILLED) take frame 0.

FGSR_INLINE float brightness(vec4 c) {
    return sqrt(clamp(dot(vec3(c.x, c.y, c.z), vec3(0.2126f, 0.7152f, 0.0722f)), 0.0f, 1.0f));
}

// band: depth_change.h's blend_depth_band of the samples ((1, 1): the plain test).
FGSR_INLINE vec4 select_blend(vec4 c0, float d0, vec4 c1, float d1, vec2 band, uint state, GenParams g) {
    bool ok0 = d0 >= 0.0f;
    bool ok1 = d1 >= 0.0f;
    if (state == FIELD_HOLE_FILLED) return ok0 || !ok1 ? c0 : c1;
    if (ok0 != ok1) return ok0 ? c0 : c1;
    float e = clamp(d0, d1 * band.x, d1 * band.y);
    if (relative_depth_difference(d0, e) > g.t_depth) return d0 > e ? c0 : c1;
    float db = abs(brightness(c0) - brightness(c1));
    if (db > g.t_bright || (g.blend_mode & BLEND_MIX) != 0u) return mix(c0, c1, g.alpha);
    return g.alpha <= 0.5f ? c0 : c1;
}
