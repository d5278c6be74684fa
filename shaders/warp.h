// Pass `warp` (paper 3.4): backward warps frame 1 (and frame 0 when interpolating) to the generated
// instant with the reconstructed field. Colour is sampled bilinearly with taps clamped to the
// image (never wrapped); depth is taken from the nearest pixel so that edges keep one surface's
// depth. A sample position outside the image is reported by a negative depth.
//
// Entry provides:
//   vec4  load_color0(ivec2 pixel), load_color1(ivec2 pixel)   internal colour (unpack_color)
//   float load_depth0(ivec2 pixel), load_depth1(ivec2 pixel)

// Bilinear colour of frame `frame` at `pos` (pixel units, centres at +0.5).
FGSR_INLINE vec4 sample_color(uint frame, vec2 pos, GenParams g) {
    vec2 x = pos - vec2(0.5f);
    vec2 f = floor(x);
    vec2 w = x - f;
    ivec2 q = ivec2(f);
    ivec2 q00 = clamp_pixel(q, g), q10 = clamp_pixel(q + ivec2(1, 0), g);
    ivec2 q01 = clamp_pixel(q + ivec2(0, 1), g), q11 = clamp_pixel(q + ivec2(1, 1), g);
    vec4 c00 = frame == 0u ? load_color0(q00) : load_color1(q00);
    vec4 c10 = frame == 0u ? load_color0(q10) : load_color1(q10);
    vec4 c01 = frame == 0u ? load_color0(q01) : load_color1(q01);
    vec4 c11 = frame == 0u ? load_color0(q11) : load_color1(q11);
    return mix(mix(c00, c10, w.x), mix(c01, c11, w.x), w.y);
}

struct WarpSample {
    vec4 color;
    float depth; // negative: the sample position is off screen
};

FGSR_INLINE WarpSample warp_sample(uint frame, vec2 centre, vec2 v, GenParams g) {
    vec2 pos = centre + v;
    bool ok = on_screen(pos, g);
    // Keep far-off positions finite (as sample_pixel does).
    pos = clamp(pos, vec2(-1.0f), vec2(float(g.width) + 1.0f, float(g.height) + 1.0f));
    ivec2 qn = sample_pixel(pos, g);
    float d = frame == 0u ? load_depth0(qn) : load_depth1(qn);
    WarpSample w;
    w.color = sample_color(frame, pos, g);
    w.depth = ok ? d : -1.0f;
    return w;
}
