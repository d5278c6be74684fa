// Pass `blend` (paper 3.4, Eq. 1): selects or blends the two warped frames of an interpolation.
//   dD = (d0 - d1) / min(d0, d1)   relative depth difference of the warped frames; with
//        BLEND_DEPTH_MOTION, where that exceeds T_D, d1 is replaced by the depth nearest d0 that
//        frame 0 may show of what frame 1 shows at its sample: the range of depths of frame 1's
//        pixel and its edge neighbours (the sample lies up to half a pixel from its nearest pixel),
//        extended by the depth change frame 1's vectors imply (blend_depth.h, blend_depths). Each
//        warped depth is its own frame's nearest pixel's: on a surface the camera approaches by
//        more than T_D a frame step, and along edges, the plain test takes one frame alone where
//        both may show the same surface (docs/ACCURACY.md, change 38).
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

// d0, d1: the warped depths, or with BLEND_DEPTH_MOTION blend_depth.h's blend_depths of them.
FGSR_INLINE vec4 select_blend(vec4 c0, float d0, vec4 c1, float d1, uint state, GenParams g) {
    bool ok0 = d0 >= 0.0f;
    bool ok1 = d1 >= 0.0f;
    if (state == FIELD_HOLE_FILLED) return ok0 || !ok1 ? c0 : c1;
    if (ok0 != ok1) return ok0 ? c0 : c1;
    float dd = (d0 - d1) / max(min(d0, d1), 1.0e-20f); // signed relative_depth_difference
    if (dd > g.t_depth) return c0;
    if (dd < -g.t_depth) return c1;
    float db = abs(brightness(c0) - brightness(c1));
    if (db > g.t_bright || (g.blend_mode & BLEND_MIX) != 0u) return mix(c0, c1, g.alpha);
    return g.alpha <= 0.5f ? c0 : c1;
}
