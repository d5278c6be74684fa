// Stage `dilate` of pass ingest (after the ingest stage, sessions with the client's vectors and
// depth): pixels just behind a silhouette take the depth and vector of the surface in front. Two
// rules: around over-white content always (this first part; linear colour formats), and at every
// depth edge where the previous frame's colour says so (the edge rule, below).
//
// Why: the client's depth and vectors are point-sampled (one surface per pixel), its colour is
// antialiased, so the pixels just outside a bright object's silhouette hold part of its light. In
// display-referred output (clamped to white) a pixel that holds a twentieth of a lamp of strength
// 20 is white: its colour is the lamp's, and where it moves with the surface behind (its own
// vector) the generated frame leaves a white halo behind the lamp and a dark rim in front of it.
// So a pixel takes the depth and vector of the nearest over-white pixel of its 3x3 neighbourhood
// that lies in front of it (nearer by more than the relative tolerance). The ring around a lamp is
// often over-white itself (a tenth of strength 30 is 3): it counts as a source only with its own,
// undilated depth. Only behind over-white content: dilating every edge (the frontmost of 3x3, in
// the manner of QRISP's depth-informed dilation; the Mob-FGSR authors' code also dilates every
// input) gained 0.6 dB on alpha-tested foliage but lost 1.9-2.9 dB on the point-sampled
// synthetic scene and 0.1-0.3 dB on toss-fg's thin wires over a checker floor, whose rings carry mostly the
// floor's colour (docs/ACCURACY.md, change 11; QRISP's Table 3 also has PSNR fall with its
// dilation).
//
// Without races: depths and vectors are read as ingest stored them (the GPU build decodes them
// again from the client's planes, the CPU reference reads a copy), the results written over
// ingest's. The ingest stage flags every 16x16 tile with an over-white pixel in its 3x3
// (ingest.comp, note_bright): only pixels of flagged tiles can change, and the GPU build runs one
// invocation per tile, which returns after reading the flag or goes over its pixels (dilate.comp;
// the first form, one invocation per pixel and a store per pixel in ingest, cost ingest 1-2 ms
// more at 480x270 on lavapipe with no pixel over white; docs/ACCURACY.md, change 11).
//
// Entry provides:
//   vec4  load_frame_color(uint pixel) the ingested colour (linear)
//   float load_source_depth(uint pixel) depth and vector as ingest stored them (before this stage)
//   vec2  load_source_mv(uint pixel)
//   void  store_frame_depth_mv(uint pixel, float depth, vec2 mv)

FGSR_INLINE void dilate_pixel(uvec2 pix, IngestParams p) {
    if (pix.x >= p.width || pix.y >= p.height) return;
    uint i = pix.y * p.width + pix.x;
    float d = load_source_depth(i);
    float nearest = d;
    uint from = i;
    for (int k = 0; k < 9; ++k) {
        ivec2 q = ivec2(pix) + ivec2(k % 3 - 1, k / 3 - 1);
        if (k == 4 || q.x < 0 || q.y < 0 || q.x >= int(p.width) || q.y >= int(p.height)) continue;
        uint j = uint(q.y) * p.width + uint(q.x);
        if (linear_luminance(load_frame_color(j)) <= p.bright) continue;
        float dj = load_source_depth(j);
        if (dj < nearest && d - dj > p.dilate_depth * dj) {
            nearest = dj;
            from = j;
        }
    }
    if (from != i) store_frame_depth_mv(i, nearest, load_source_mv(from));
}

// The edge rule (Params::dilate_edges; p.edge_ratio > 0, frames with a previous one): at every
// depth edge, the pixel just behind a silhouette takes the depth and vector of the surface in front
// when the previous frame's colour says that its light moved with that surface.
//
// Why: the same antialiased ring as above, for content of any brightness. A pixel whose centre
// falls just outside a silhouette holds part of the front surface's light; moved with the surface
// behind, the generated frame tears that part off (leaf cards, thin wires). Dilating every edge
// (the rule above without the brightness test) gained alpha-tested foliage 0.6 dB but lost the
// point-sampled synthetic scene 2-3 dB, whose pixels behind hold none of the front's light. So
// each edge pixel tests both motions on the colour around it: the previous frame under its own
// vector and under the front neighbour's is sampled (bilinearly, display-referred colour: the
// square root of linear colour clamped to [0, 1], as blend.h) at a cross of 5 pixels centred on
// it, and the front's vector is taken where its colour difference is below edge_ratio times the
// own vector's. The front neighbour is the nearest of the 4 edge neighbours that lies in front by
// more than the relative tolerance (as above). Pixels next to over-white content are the rule
// above's (over-white light dominates a pixel whatever the test says, and the test compares
// colour clamped to white): neither the pixel nor its front neighbour may be over-white while that
// rule is on. Measured on the train captures and chosen there (docs/ACCURACY.md, change 12).
//
// Where: the GPU build of the stage with the rule (dilate.comp, FGSR_DILATE_EDGES) runs it per
// 16x16 tile, a depth test of every pixel that lists the edge pixels and then the colour test of
// the list (cheaper on CPU devices than a branch, docs/PERFORMANCE.md), before the over-white rule
// in the same invocation, whose writes take precedence. The CPU reference runs it on a copy of the
// ingested frame, before the other rule.
//
// Entry provides, besides the above:
//   vec4  load_prev_color(uint pixel) the previous frame's ingested colour (linear)

FGSR_INLINE vec3 dilate_display(vec4 c) { return sqrt(clamp(vec3(c), vec3(0.0f), vec3(1.0f))); }

// The previous frame's display colour at pixel q, clamped to the frame.
FGSR_INLINE vec3 dilate_tap(ivec2 q, IngestParams p) {
    q = clamp(q, ivec2(0), ivec2(int(p.width) - 1, int(p.height) - 1));
    return dilate_display(load_prev_color(uint(q.y) * p.width + uint(q.x)));
}

FGSR_INLINE vec3 dilate_bilinear(vec3 c00, vec3 c10, vec3 c01, vec3 c11, vec2 frac) {
    vec3 top = c00 * (1.0f - frac.x) + c10 * frac.x;
    vec3 bottom = c01 * (1.0f - frac.x) + c11 * frac.x;
    return top * (1.0f - frac.y) + bottom * frac.y;
}

// Colour difference between the cross window around pix (display colours: centre, left, right,
// up, down) and the previous frame at the window's pixels shifted by `o`. The five bilinear
// samples share one fraction and 12 taps (a 4x4 block without its corners) of the previous frame.
FGSR_INLINE float dilate_cost(vec3 c, vec3 l, vec3 r, vec3 u, vec3 d, uvec2 pix, vec2 o, IngestParams p) {
    vec2 at = vec2(pix) + o;
    ivec2 b = ivec2(floor(at));
    vec2 frac = at - vec2(b);
    vec3 t00 = dilate_tap(b, p);
    vec3 t10 = dilate_tap(b + ivec2(1, 0), p);
    vec3 t01 = dilate_tap(b + ivec2(0, 1), p);
    vec3 t11 = dilate_tap(b + ivec2(1, 1), p);
    vec3 e = abs(c - dilate_bilinear(t00, t10, t01, t11, frac));
    vec3 ta = dilate_tap(b + ivec2(-1, 0), p);
    vec3 tb = dilate_tap(b + ivec2(-1, 1), p);
    e += abs(l - dilate_bilinear(ta, t00, tb, t01, frac));
    ta = dilate_tap(b + ivec2(2, 0), p);
    tb = dilate_tap(b + ivec2(2, 1), p);
    e += abs(r - dilate_bilinear(t10, ta, t11, tb, frac));
    ta = dilate_tap(b + ivec2(0, -1), p);
    tb = dilate_tap(b + ivec2(1, -1), p);
    e += abs(u - dilate_bilinear(ta, tb, t00, t10, frac));
    ta = dilate_tap(b + ivec2(0, 2), p);
    tb = dilate_tap(b + ivec2(1, 2), p);
    e += abs(d - dilate_bilinear(t01, t11, ta, tb, frac));
    return e.x + e.y + e.z;
}

#define DILATE_NO_FRONT 0xffffffffu

// The front neighbour of the pixel at pix with depth d: the nearest of its 4 edge neighbours that
// lies in front by more than the relative tolerance, or DILATE_NO_FRONT.
FGSR_INLINE uint dilate_front(uvec2 pix, float d, IngestParams p) {
    float nearest = d;
    uint from = DILATE_NO_FRONT;
    for (int k = 0; k < 4; ++k) {
        ivec2 q = ivec2(pix) + ivec2(k == 0 ? -1 : (k == 1 ? 1 : 0), k == 2 ? -1 : (k == 3 ? 1 : 0));
        if (q.x < 0 || q.y < 0 || q.x >= int(p.width) || q.y >= int(p.height)) continue;
        uint j = uint(q.y) * p.width + uint(q.x);
        float dj = load_source_depth(j);
        if (dj < nearest && d - dj > p.dilate_depth * dj) {
            nearest = dj;
            from = j;
        }
    }
    return from;
}

// The colour test of the pixel at pix against its front neighbour `from`: true where the pixel
// takes the front's depth and vector.
FGSR_INLINE bool dilate_takes_front(uvec2 pix, uint from, IngestParams p) {
    uint i = pix.y * p.width + pix.x;
    if (p.bright > 0.0f &&
        (linear_luminance(load_frame_color(i)) > p.bright || linear_luminance(load_frame_color(from)) > p.bright))
        return false;
    uint x0 = pix.x > 0u ? pix.x - 1u : 0u, x1 = min(pix.x + 1u, p.width - 1u);
    uint y0 = pix.y > 0u ? pix.y - 1u : 0u, y1 = min(pix.y + 1u, p.height - 1u);
    vec3 c = dilate_display(load_frame_color(i));
    vec3 l = dilate_display(load_frame_color(pix.y * p.width + x0));
    vec3 r = dilate_display(load_frame_color(pix.y * p.width + x1));
    vec3 u = dilate_display(load_frame_color(y0 * p.width + pix.x));
    vec3 dn = dilate_display(load_frame_color(y1 * p.width + pix.x));
    float cost_own = dilate_cost(c, l, r, u, dn, pix, load_source_mv(i), p);
    float cost_front = dilate_cost(c, l, r, u, dn, pix, load_source_mv(from), p);
    return cost_front < p.edge_ratio * cost_own;
}

// The edge rule for one pixel, through the entry's loads and store (the CPU reference; the GPU
// build runs the two steps per tile, dilate.comp).
FGSR_INLINE void dilate_edge_pixel(uvec2 pix, IngestParams p) {
    if (pix.x >= p.width || pix.y >= p.height || !(p.edge_ratio > 0.0f)) return;
    uint from = dilate_front(pix, load_source_depth(pix.y * p.width + pix.x), p);
    if (from != DILATE_NO_FRONT && dilate_takes_front(pix, from, p))
        store_frame_depth_mv(pix.y * p.width + pix.x, load_source_depth(from), load_source_mv(from));
}
