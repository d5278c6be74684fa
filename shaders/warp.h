// Pass `warp` (paper 3.4): backward warps frame 1 (and frame 0 when interpolating) to the generated
// instant with the reconstructed field. Colour is sampled bilinearly, or with g.warp_cubic by the
// Catmull-Rom cubic clamped per channel to the range of its inner 2x2 taps (no ringing: the result
// stays within the colours bilinear mixes, and an HDR highlight casts no negative lobes), taps
// clamped to the image (never wrapped). Bilinear at a fractional position low-passes the frame (at
// half a pixel, a [1/2 1/2] filter per axis); the cubic keeps the detail of antialiased input
// (docs/ACCURACY.md, change 39). Depth is taken from the nearest pixel so that edges keep one
// surface's depth. A sample position outside the image is reported by a negative depth.
//
// Entry provides:
//   vec4  load_color0(ivec2 pixel), load_color1(ivec2 pixel)   internal colour (unpack_color)
//   float load_depth0(ivec2 pixel), load_depth1(ivec2 pixel)

FGSR_INLINE vec4 load_frame_color(uint frame, ivec2 q, GenParams g) {
    ivec2 c = clamp_pixel(q, g);
    return frame == 0u ? load_color0(c) : load_color1(c);
}

// Colour of frame `frame` at `pos` (pixel units, centres at +0.5): bilinear, or with g.warp_cubic
// the de-ringed Catmull-Rom cubic (the file's head).
FGSR_INLINE vec4 sample_color(uint frame, vec2 pos, GenParams g) {
    vec2 x = pos - vec2(0.5f);
    vec2 f = floor(x);
    vec2 w = x - f;
    ivec2 q = ivec2(f);
    vec4 c00 = load_frame_color(frame, q, g), c10 = load_frame_color(frame, q + ivec2(1, 0), g);
    vec4 c01 = load_frame_color(frame, q + ivec2(0, 1), g), c11 = load_frame_color(frame, q + ivec2(1, 1), g);
    if (g.warp_cubic == 0u) return mix(mix(c00, c10, w.x), mix(c01, c11, w.x), w.y);
    vec4 wx = catmull_rom_weights(w.x), wy = catmull_rom_weights(w.y);
    // The inner 2x2 taps, weighted as they are, then the outer ring of twelve.
    vec4 sum = wy[1] * (wx[1] * c00 + wx[2] * c10) + wy[2] * (wx[1] * c01 + wx[2] * c11);
    for (int j = 0; j < 4; ++j) {
        sum += wx[0] * wy[j] * load_frame_color(frame, q + ivec2(-1, j - 1), g);
        sum += wx[3] * wy[j] * load_frame_color(frame, q + ivec2(2, j - 1), g);
    }
    for (int i = 1; i < 3; ++i) {
        sum += wx[i] * wy[0] * load_frame_color(frame, q + ivec2(i - 1, -1), g);
        sum += wx[i] * wy[3] * load_frame_color(frame, q + ivec2(i - 1, 2), g);
    }
    return clamp(sum, min(min(c00, c10), min(c01, c11)), max(max(c00, c10), max(c01, c11)));
}

struct WarpSample {
    vec4 color;
    float depth; // negative: the sample position is off screen
    ivec2 pixel; // the pixel whose depth it reports (sample_pixel): blend_depths reads frame 1's there
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
    w.pixel = qn;
    return w;
}

// Extrapolation with FGSR_FILL_HOLES_FRAME0 (disocc.h, fill_hole; docs/ACCURACY.md, change 50): a
// hole of disocc's (FIELD_HOLE_FILLED) may take frame 0, sampled at the background's vector (v0).
FGSR_INLINE bool hole_may_take_frame0(uint state, GenParams g) {
    return state == FIELD_HOLE_FILLED && (g.fill_holes & FGSR_FILL_HOLES_FRAME0) != 0u;
}
// It does where that sample (depth d0) lies behind frame 1's sample along the path of the surface
// that left (d1) by more than T_D: frame 1's sample is on that surface, frame 0 shows what it uncovered.
FGSR_INLINE bool frame0_behind(float d0, float d1, GenParams g) {
    return d0 >= 0.0f && d1 >= 0.0f && d0 - d1 > g.t_depth * d1;
}

// The extrapolated colour of the pixel at `centre` with field vectors v (v0 used only by the
// holes above) and frame 1's sample w1.
FGSR_INLINE vec4 extrapolated_color(WarpSample w1, vec4 v, uint state, vec2 centre, GenParams g) {
    if (!hole_may_take_frame0(state, g)) return w1.color;
    WarpSample w0 = warp_sample(0u, centre, vec2(v.x, v.y), g);
    return frame0_behind(w0.depth, w1.depth, g) ? w0.color : w1.color;
}
