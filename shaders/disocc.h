// Pass `disocc` (paper 3.4, supplement 4): gives the holes that refine left a vector.
//
// Extrapolation (disocclusion, the paper's method): a hole at t was covered at time 1 by a surface
// that has since moved on; frame 1's own vector at t points back along that surface's path, where
// frame 1 shows what the surface uncovered, so v1 = alpha * mv1(t).
// Interpolation (occlusion: visible at alpha, covered by time 1, so only frame 0 sees it): the
// surface is the background next to the hole; take the vectors of the farthest splatted pixel on
// a sparse ring pattern (8 directions, radii 1, 2, 4, 8, 16) around t. Blend then reads frame 0
// only. Only splat keys are read (and, at the frame's edge, frame 0's vectors: leaving_frame0),
// so the pass needs no other pass's output but splat's.
// Entry provides refine.h's and motion.h's loads.

// Does frame 0's content at t + v0 (its vector to frame -1: mv0) reach t by alpha? Its own
// velocity, taken as constant, moves it by -alpha * mv0, so it does where v0 = alpha * mv0 within
// 2 px plus half of that displacement (acceleration, and frame 0's field being that of a
// neighbour's surface).
FGSR_INLINE bool frame0_reaches(vec2 v0, vec2 mv0, GenParams g) {
    return length(v0 - g.alpha * mv0) <= 2.0f + 0.5f * g.alpha * length(mv0);
}

// Interpolation, content leaving the frame (docs/ACCURACY.md, change 28): a hole whose fill (the
// background's vectors v = (v0, v1)) reaches frame 1 off screen shows content that frame 1 no
// longer has, so only frame 0 can give it. Where a faster surface crosses the edge (a near post
// under a panning camera), the background's v0 lands frame 0's sample on that surface, which has
// left by alpha: frame 0's own vector there says so (frame0_reaches fails). The hole then takes
// the frame-0 content that does reach t, by one fixed-point step v0' = alpha * mv0(t + v0), where
// that content moves (at least a pixel a frame: still content is the background's own case) and
// its own vector agrees. Otherwise the fill stays as it was. Needs frame 0's vectors.
FGSR_INLINE vec4 leaving_frame0(ivec2 t, vec4 v, GenParams g) {
    vec2 centre = vec2(t) + vec2(0.5f);
    if (on_screen(centre + vec2(v.z, v.w), g) || g.frame0_has_mv == 0u) return v;
    ivec2 last = ivec2(int(g.width) - 1, int(g.height) - 1);
    vec2 v0 = vec2(v.x, v.y);
    vec2 p0 = centre + v0;
    if (!on_screen(p0, g)) return v;
    vec2 m = load_mv0(clamp(ivec2(floor(p0)), ivec2(0), last));
    if (frame0_reaches(v0, m, g)) return v;
    vec2 moved = g.alpha * m;
    vec2 p = centre + moved;
    if (!on_screen(p, g)) return v;
    vec2 m2 = load_mv0(clamp(ivec2(floor(p)), ivec2(0), last));
    if (length(m2) < 1.0f || !frame0_reaches(moved, m2, g)) return v;
    return vec4(moved, v.z, v.w);
}

// The farthest splatted pixel on the sparse ring pattern around t (8 directions, radii 1, 2, 4, 8,
// 16): its key (an empty key where none is).
FGSR_INLINE uint64_t farthest_on_ring(ivec2 t, GenParams g) {
    float farthest = -1.0f;
    uint64_t best = uint64_t(FGSR_EMPTY_KEY_LO);
    for (int r = 1; r <= 16; r *= 2)
        for (int d = 0; d < 8; ++d) {
            ivec2 dir = ivec2(d < 3 ? -1 : (d == 3 || d == 7 ? 0 : 1), d == 1 || d == 5 ? 0 : (d < 1 || d > 5 ? -1 : 1));
            ivec2 q = t + r * dir;
            if (inside(q, g)) {
                uint64_t k = load_key(q);
                if (!key_empty(k) && key_depth(k) > farthest) {
                    farthest = key_depth(k);
                    best = k;
                }
            }
        }
    return best;
}

// Extrapolation with FGSR_FILL_HOLES_FRAME0 (docs/ACCURACY.md, change 50): the paper's sample
// lands on the surface that left where that surface is small against its step or its path bends
// (a lamp on a circle, a turning vane), and shows it twice. The fill then also carries, as its v0,
// the vector to frame 0 of the background (the farthest splatted pixel on the ring, as in
// interpolation): where frame 0 shows something behind frame 1's sample there, the frame takes
// frame 0 (warp.h, extrapolated_color). Without the bit (or with no splatted pixel on the ring) v0
// is v1, as before.
FGSR_INLINE FieldSample fill_hole(ivec2 t, GenParams g) {
    if (g.extrapolate != 0u) {
        vec2 v1 = g.alpha * load_mv1(t);
        vec2 v0 = v1;
        if ((g.fill_holes & FGSR_FILL_HOLES_FRAME0) != 0u) {
            uint64_t k = farthest_on_ring(t, g);
            if (!key_empty(k) && key_depth(k) > 0.0f) {
                vec4 m = load_motion(key_source(k));
                v0 = vec2(m.x, m.y);
            }
        }
        return field_sample(vec4(v0, v1), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
    }
    uint64_t best = farthest_on_ring(t, g);
    float farthest = key_empty(best) ? -1.0f : key_depth(best);
    if (farthest > 0.0f)
        return field_sample(leaving_frame0(t, load_motion(key_source(best)), g), farthest, FIELD_HOLE_FILLED);
    return field_sample(vec4(0.0f), FGSR_FAR_DEPTH, FIELD_HOLE_FILLED);
}

// Edge cover (GenParams::fill_holes & FGSR_FILL_HOLES_COVER; docs/ACCURACY.md, change 14).
// Splatting writes a source to the one pixel under its centre, so the pixel beside a moving edge
// is a hole (its fill: the background, or in extrapolation what the surface uncovered) even where
// the surface's footprint, the pixel square around where its source landed, overlaps it; which side
// of a pixel border the edge's centre falls on then turns on a fraction of a pixel of motion (pan
// seed 2's leading edge, docs/ACCURACY.md). Such a hole takes the field of its nearest edge
// neighbour that lies in front of its fill (nearer by more than T_D) and whose footprint overlaps
// it. Warped with the front's vectors, the pixel then samples frame 1 just beyond the front's edge
// there, whose antialiased colour holds the part of the front that covers it: the edge keeps its
// sub-pixel profile instead of being cut at the pixel border. Not where frame 1 is over white in
// the 2x2 that the pixel would sample (hdr's lamps, whose rings the dilate stage already moves with
// them: there the cover drew a second ring). Edge neighbours only: the diagonals measured no better
// on train. Returns the chosen neighbour's field, or f (the hole's fill) where none is.
FGSR_INLINE FieldSample hole_cover(ivec2 t, FieldSample f, GenParams g) {
    float hole_depth = f.depth;
    vec2 centre = vec2(t) + vec2(0.5f);
    float front = FGSR_FAR_DEPTH;
    int nearest = -1;
    vec4 front_v = vec4(0.0f);
    for (int n = 0; n < 4; ++n) {
        ivec2 q = t + edge_neighbour_offset(n);
        if (!inside(q, g)) continue;
        uint64_t k = load_key(q);
        if (key_empty(k)) continue;
        float dq = key_depth(k);
        if (!(hole_depth - dq > g.t_depth * dq) || !(dq < front)) continue;
        uint src = key_source(k);
        vec4 v = load_motion(src);
        vec2 own = src >= frame_pixels(g) ? vec2(v.x, v.y) : vec2(v.z, v.w); // to its own frame
        vec2 landed = vec2(source_pixel(src, g)) + vec2(0.5f) - own;
        vec2 d = abs(landed - centre);
        if (!(d.x < 1.0f && d.y < 1.0f)) continue; // the footprints do not overlap
        front = dq;
        nearest = n;
        front_v = v;
    }
    if (nearest < 0) return f;
    ivec2 base = ivec2(floor(centre + vec2(front_v.z, front_v.w) - vec2(0.5f)));
    for (int j = 0; j < 4; ++j) {
        ivec2 s = clamp(base + ivec2(j & 1, j >> 1), ivec2(0), ivec2(int(g.width) - 1, int(g.height) - 1));
        if (linear_luminance(load_color1(s)) > 1.0f) return f;
    }
    return field_sample(front_v, front, FIELD_SPLATTED);
}

// fill_hole, then the edge cover where the parameters ask for it.
FGSR_INLINE FieldSample fill_hole_covered(ivec2 t, GenParams g) {
    FieldSample f = fill_hole(t, g);
    return (g.fill_holes & FGSR_FILL_HOLES_COVER) != 0u ? hole_cover(t, f, g) : f;
}
