// Motion of one frame-1 pixel to the generated instant (shared by splat and refine).
//
// Internal vectors point to the previous frame: mv1(p1) = p0 - p1. In the paper's notation the
// motion from frame 0 to frame 1 is m1 = p1 - p0 = -mv1(p1), and m0 = -mv0(p0) the motion from
// frame -1 to frame 0 of the same surface point, read at its frame-0 position p0.
//
// m0 must belong to the same surface: where p0 lies on another surface in frame 0 (the point was
// hidden then, or sits on an edge) its vector would describe the occluder. So m0 is read from the
// pixel under p0 if its frame-0 depth agrees with the point's frame-1 depth within 4 T_D
// (relative), a band that Params::accel_depth_motion extends to the depth change the motion
// implies (surface_band), else from the one of its 4 edge neighbours whose depth is closest and
// agrees; otherwise the motion falls back to uniform velocity for that pixel. In extrapolation,
// where that vector implies an acceleration, the edge neighbours of the same surface are searched
// for the smallest one (below, at the search). In interpolation the acceleration is the median of
// the pixel's own and those of its 3x3 frame-1 neighbours of the same surface (below, at the
// median). (A full 3x3 search was measured on lavapipe: ~25% more splat time, where SIMD groups
// with any miss pay for it, for no PSNR gain beyond 0.01 dB on the captures.)
//
// Entry provides:
//   vec2  load_mv1(ivec2 pixel)     frame 1 vectors
//   float load_depth1(ivec2 pixel)
//   vec2  load_mv0(ivec2 pixel)     frame 0 vectors (only called when frame0_has_mv != 0)
//   float load_depth0(ivec2 pixel)
//   vec4  load_source_motion(uint source)  splat's motion (m1, m0) of a frame-1 pixel (splat.h)

// source_motion returns vec4(p_target.xy, p0.xy) for the surface point at pixel `p1` of frame 1:
// its position at the generated time (alpha for interpolation, 1 + alpha for extrapolation) and in
// frame 0. Uniform acceleration: supplement Eqs. 1 and 2. Uniform velocity (or no frame-0 vectors,
// or a frame-0 position off screen): Eqs. 14 and 15. It is split in two so that splat reads and
// searches the vectors once for all alphas of a pair: source_velocities (alpha-independent), then
// motion_at per alpha.
// Whether the frame-0 vector is looked up (uniform acceleration with frame-0 vectors). The splat
// builds for the other calls (FGSR_SPLAT_LINEAR: uniform velocity, or no frame-0 vectors, as in
// every colour-only session) leave the lookup out: CPU devices run both sides of a branch with the
// inactive lanes masked off, so its 6 reads would cost every source pixel anyway.
#if defined(FGSR_SPLAT_LINEAR)
#define MOTION_LOOKS_UP_M0(g) false
#else
#define MOTION_LOOKS_UP_M0(g) ((g).quadratic != 0u && (g).frame0_has_mv != 0u)
#endif
#define MOTION_ACCEL_PX 2.0f // chosen on the train captures (docs/ACCURACY.md, "Changes", 3)
#define MOTION_ACCEL_RATIO 1.0f
#define MOTION_M0_SEARCH_PX 0.25f // chosen on the train captures (docs/ACCURACY.md, "Changes", 13)
#define MOTION_MEDIAN_MIN 5       // of 9; chosen on the train captures (docs/ACCURACY.md, "Changes", 18)
#define MOTION_SURFACE_TD 4.0f    // in T_D; chosen on the train captures (docs/ACCURACY.md, "Changes", 21)

// Which frame-0 depths count as the point's surface: vec3(lo, hi, tolerance), a frame-0 depth d0
// of a point of frame-1 depth d1 belongs where its relative difference to [d1 lo, d1 hi] is below
// the tolerance (on_surface0; for positive depths d1 lo / (1 + tolerance) < d0 < d1 hi (1 +
// tolerance)). Without MOTION_DEPTH_MOTION: within 4 T_D of d1 either way (lo = hi = 1). With it
// (docs/ACCURACY.md, change 21), the depth change the motion implies, as the sr pass's history test
// expects it (sr.h step 2): a patch the camera approaches was farther in frame 0 by s = 1 /
// sqrt(det J), J = I + grad(mv1) the local map from frame-1 to frame-0 positions (central
// differences of the frame-1 vectors over p1's edge neighbours on its surface, depth within T_D;
// one-sided at an edge of it; det J clamped to [1/4, 4]); a patch at a slant changes by less (a
// ground plane by about s^(2/3)). So d0 is expected between d1 and d1 s, widened by
// MOTION_SURFACE_TD T_D either way: a street approached at speed keeps its frame-0 vector where its
// depth changed by more than 4 T_D. The band only ever grows (s = 1 is the plain test): a tighter
// one (2 T_D) kept another leaf or the ground behind an edge out, but lost more where a turning,
// approaching ball's depth changes unlike its vectors' area (docs/ACCURACY.md, change 21).
// frame1_depth_scale (s) and surface_distance0 are in depth_change.h.
#include "depth_change.h"
FGSR_INLINE vec3 surface_band(ivec2 p1, float d1, vec2 mv1, GenParams g) {
    if ((g.quadratic & MOTION_DEPTH_MOTION) == 0u) return vec3(1.0f, 1.0f, 4.0f * g.t_depth);
    float s = frame1_depth_scale(p1, d1, mv1, g);
    return vec3(min(1.0f, s), max(1.0f, s), MOTION_SURFACE_TD * g.t_depth);
}
// With lo = hi = 1 this is the plain test relative_depth_difference(d0, d1) < tolerance, to the bit.
FGSR_INLINE bool on_surface0(float d0, float d1, vec3 band) {
    return surface_distance0(d0, d1, band) < band.z;
}

// The acceleration m1 - m0 of the frame-1 pixel pn as the pixel under its own frame-0 position
// gives it: vec3(m1 - m0, 1) where pn lies on the surface of depth d1 (within `tolerance`), that
// frame-0 pixel on the same surface (on_surface0 with the centre's band), and the acceleration
// within the plausibility bound (below); vec3(0) otherwise.
FGSR_INLINE vec3 neighbour_acceleration(ivec2 pn, float d1, float tolerance, vec3 band, GenParams g) {
    if (!inside(pn, g)) return vec3(0.0f);
    float dn = load_depth1(pn);
    if (!(relative_depth_difference(dn, d1) < tolerance)) return vec3(0.0f);
    vec2 m1 = -load_mv1(pn);
    ivec2 q = ivec2(floor(vec2(pn) + vec2(0.5f) - m1));
    if (!inside(q, g) || !on_surface0(load_depth0(q), dn, band)) return vec3(0.0f);
    vec2 accel = m1 + load_mv0(q);
    return length(accel) <= MOTION_ACCEL_PX + MOTION_ACCEL_RATIO * length(m1) ? vec3(accel, 1.0f)
                                                                              : vec3(0.0f);
}

// The motion of the point: vec4(m1, m0), m0 = m1 for uniform velocity. d1: load_depth1(p1) (splat
// reads it once for this and for its key).
FGSR_INLINE vec4 source_velocities_at_depth(ivec2 p1, float d1, GenParams g) {
    vec2 c1 = vec2(p1) + vec2(0.5f);
    vec2 m1 = -load_mv1(p1);
    vec2 p0 = c1 - m1;
    vec2 m0 = m1;
    vec3 band = vec3(1.0f, 1.0f, 4.0f * g.t_depth);
    if (MOTION_LOOKS_UP_M0(g)) {
        ivec2 q = ivec2(floor(p0));
        band = surface_band(p1, d1, -m1, g);
        // The pixel whose vector is taken is chosen first and its vector read once: on CPU devices
        // each load in a branch costs every lane, taken or not.
        ivec2 from = q;
        bool found = inside(q, g) && on_surface0(load_depth0(q), d1, band);
        if (!found) {
            // The centre missed: the 4 edge neighbours on the surface, closest depth wins (first on
            // ties).
            float best = band.z;
            for (int k = 0; k < 4; ++k) {
                ivec2 qq = q + edge_neighbour_offset(k);
                if (inside(qq, g)) {
                    float rel = surface_distance0(load_depth0(qq), d1, band);
                    if (rel < best) {
                        best = rel;
                        from = qq;
                        found = true;
                    }
                }
            }
        }
        if (found) m0 = -load_mv0(from);
        // Extrapolation weights the acceleration 3x more than interpolation (0.375 against 0.125
        // of m1 - m0 at alpha 0.5), so there an m0 read from a neighbouring surface at a similar
        // depth costs most: the ground beside a slow mover's edge (zero motion, a false
        // deceleration), another leaf of a canopy. Where the chosen vector implies a change of
        // more than MOTION_M0_SEARCH_PX, the 4 edge neighbours of the same surface (on_surface0)
        // are searched too and the vector of the smallest acceleration wins. In
        // interpolation it lost as much as it gained on train (docs/ACCURACY.md, change 13). The
        // branch is uniform in interpolation; in extrapolation a SIMD group pays for the search
        // when any of its pixels needs it (splat about 1.5x on lavapipe), so it is a switch:
        // Params::accel_search, GenParams::quadratic's MOTION_ACCEL_SEARCH.
        if ((g.quadratic & MOTION_ACCEL_SEARCH) != 0u && g.extrapolate != 0u && found &&
            length(m1 - m0) > MOTION_M0_SEARCH_PX) {
            float best = length(m1 - m0);
            vec2 chosen = m0;
            for (int k = 0; k < 4; ++k) {
                ivec2 qq = q + edge_neighbour_offset(k);
                if (inside(qq, g) && on_surface0(load_depth0(qq), d1, band)) {
                    vec2 c = -load_mv0(qq);
                    float e = length(m1 - c);
                    if (e < best) {
                        best = e;
                        chosen = c;
                    }
                }
            }
            m0 = chosen;
        }
    }
    // An acceleration the model cannot follow (the motion changing by more than MOTION_ACCEL_PX
    // plus MOTION_ACCEL_RATIO times the newer speed in one frame): a camera cut between frames -1
    // and 0, whose frame-0 vectors then point into the other shot; wrong vectors; or motion that
    // turns back or jerks (a rolling ball's surface, swaying leaves, a glint), where a parabola
    // through three frames overshoots. Uniform velocity. Steady acceleration (a thrown object,
    // a camera speeding up, a turning fan) changes the motion by less and keeps the parabola.
    if (length(m1 - m0) > MOTION_ACCEL_PX + MOTION_ACCEL_RATIO * length(m1)) m0 = m1;
    // The median. An m0 read from another surface at a similar depth (another leaf of a canopy,
    // the ground beside a slow mover's edge) gives a pixel an acceleration its surface does not
    // have; its neighbours of the same surface, each followed to its own frame-0 position, mostly
    // land on their own surface. So in interpolation the acceleration is the componentwise median
    // of the pixel's own (0 where it fell back to uniform velocity) and those of its 3x3 frame-1
    // neighbours on its surface (depth within the tolerance) whose frame-0 pixel is on that
    // surface too and whose acceleration is plausible (neighbour_acceleration), where at least
    // MOTION_MEDIAN_MIN of the 9 take part (fewer: the pixel's own; a small object or a thin part
    // has no consensus to give). A pixel that does not move keeps its motion: a static source
    // stays one (classify.h). On a surface whose acceleration varies smoothly the median of its
    // 3x3 is its own or close to it (exactly for a field linear in x and y with all 9 taking part:
    // the values pair up about it). Not in extrapolation, where it lost on train
    // (docs/ACCURACY.md, change 18; the search above does that part there). splat 1.16-1.30x in
    // interpolation on lavapipe (docs/PERFORMANCE.md): Params::accel_median.
    if ((g.quadratic & MOTION_ACCEL_MEDIAN) != 0u && g.extrapolate == 0u && MOTION_LOOKS_UP_M0(g) &&
        m1 != vec2(0.0f)) {
        float tolerance = 4.0f * g.t_depth;
        float ax[9], ay[9];
        bool ok[9];
        int n = 0;
        for (int k = 0; k < 9; ++k) {
            vec3 a = k == 4
                         ? vec3(m1 - m0, 1.0f)
                         : neighbour_acceleration(p1 + ivec2(k % 3 - 1, k / 3 - 1), d1, tolerance, band, g);
            ax[k] = a.x;
            ay[k] = a.y;
            ok[k] = a.z != 0.0f;
            n += int(ok[k]);
        }
        if (n >= MOTION_MEDIAN_MIN) m0 = m1 - vec2(median9(ax, ok, n), median9(ay, ok, n));
    }
    return vec4(m1, m0);
}

FGSR_INLINE vec4 source_velocities(ivec2 p1, GenParams g) {
    return source_velocities_at_depth(p1, load_depth1(p1), g);
}

// Positions vec4(p_target.xy, p0.xy) at alpha `a` of the point at pixel centre c1 with the motion
// `m` = vec4(m1, m0) of source_velocities.
FGSR_INLINE vec4 motion_at(vec2 c1, vec4 m, float a, GenParams g) {
    vec2 m1 = vec2(m.x, m.y);
    vec2 m0 = vec2(m.z, m.w);
    vec2 p0 = c1 - m1;
    vec2 accel = 0.5f * a * a * (m1 - m0);
    vec2 pt = g.extrapolate == 0u ? p0 + 0.5f * a * (m1 + m0) + accel
                                  : c1 + 0.5f * a * (3.0f * m1 - m0) + accel;
    return vec4(pt, p0);
}

FGSR_INLINE vec4 source_motion(ivec2 p1, GenParams g) {
    return motion_at(vec2(p1) + vec2(0.5f), source_velocities(p1, g), g.alpha, g);
}

// The field vectors (v0, v1) of the frame-1 pixel `source` (y * width + x) at the generated time
// g.alpha: the displacements from its position then to its position in frame 0 and in frame 1.
// splat stores a source's motion (m1, m0) once for all the alphas of a call
// (store_source_motion); refine, disocc, generate and generate_sr recompute a splatted pixel's
// vectors here with the same motion_at from the same values, so they are the position splat used.
// (Stored per alpha, the field vectors were two stores per source and alpha on lavapipe: about a
// fifth of a one-frame splat and most of what each further frame of a pair added to it.)
// p1: the source's pixel (tiles.h has it already).
FGSR_INLINE vec4 field_vectors_at(ivec2 p1, uint source, GenParams g) {
    vec2 c1 = vec2(p1) + vec2(0.5f);
    vec4 pos = motion_at(c1, load_source_motion(source), g.alpha, g);
    vec2 pt = vec2(pos.x, pos.y);
    return vec4(vec2(pos.z, pos.w) - pt, c1 - pt);
}
// Sources from frame 0 (splat.h, splat_leaving): content that leaves the frame before frame 1,
// keyed as source frame_pixels(g) + its frame-0 pixel p0. Its forward velocities: u0 = -mv0(p0)
// over [-1, 0], and u1 over [0, 1] = -mv1(p0) where frame 1 still shows the same surface at p0
// (depths within T_D), else u0 (the content has moved on; its frame-1 velocity is unknown). From
// its frame-0 position c0 it moves as the paper's model moves a point from p0 (uniform
// acceleration between u0 and u1): displacement 0.5 a (u1 + u0) + 0.5 a^2 (u1 - u0) at alpha a.
FGSR_INLINE uint frame_pixels(GenParams g) {
    return g.width * g.height;
}
// Frame 1 still shows frame-0 pixel p0's surface at p0 (d0, d1: the two frames' depths there).
FGSR_INLINE bool leaving_same_surface(float d0, float d1, GenParams g) {
    return relative_depth_difference(d0, d1) <= g.t_depth;
}
FGSR_INLINE vec2 leaving_displacement(vec2 u0, vec2 u1, float a) {
    return 0.5f * a * (u1 + u0) + 0.5f * a * a * (u1 - u0);
}
// The field vectors (v0, v1) of a frame-0 source at alpha: to its frame-0 position and to where
// it is at time 1 (off the frame).
FGSR_INLINE vec4 leaving_field_vectors(ivec2 p0, GenParams g) {
    vec2 u0 = -load_mv0(p0);
    vec2 u1 = leaving_same_surface(load_depth0(p0), load_depth1(p0), g) ? -load_mv1(p0) : u0;
    vec2 disp = leaving_displacement(u0, u1, g.alpha);
    return vec4(-disp, u1 - disp);
}
// The pixel of a source in its own frame (frame 0 for leaving content).
FGSR_INLINE ivec2 source_pixel(uint source, GenParams g) {
    uint s = source >= frame_pixels(g) ? source - frame_pixels(g) : source;
    uint y = udiv(s, g.width);
    return ivec2(int(s - y * g.width), int(y));
}
FGSR_INLINE vec4 source_field_vectors(uint source, GenParams g) {
    if (source >= frame_pixels(g)) return leaving_field_vectors(source_pixel(source, g), g);
    return field_vectors_at(source_pixel(source, g), source, g);
}
