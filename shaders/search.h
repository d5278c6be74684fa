// Builds `polish_search` and `polish_densify` of pass `polish`: DIS's patch inverse search and
// densification (Kroeger et al., ECCV 2016, sections 2.1-2.2) on a coarse level of the
// coarse-to-fine field (polish.h, polish_coarse), between the level's seed and its variational
// sweeps. Colour-only sessions (Params::motion_search).
//
// Block matching tests whole-pixel displacements of disjoint 8x8 blocks, each alone; where a dark,
// low-contrast region matches a wrong displacement a little better than the right one, whole
// blocks take it, and the sweeps' linearised data term cannot pull a vector back from pixels away.
// DIS instead refines, from the seeded field, a vector for each of many overlapping patches by
// Gauss-Newton steps on the patch's mean-normalised colour difference (sub-pixel all the way), then
// gives each pixel the mean of the vectors of the patches that cover it, each weighted by how well
// it explains the pixel: a wrong vector survives only where it explains the colour better
// (docs/MOTION.md, "Patch inverse search").
//
//   1. search (one invocation per patch; SEARCH_PATCH pixels a side, origins p.patch_stride apart,
//      the last row and column moved inward to end at the level's edge): from u0, the seeded field
//      read bilinearly at the patch's centre, p.search_steps Gauss-Newton steps minimising
//        sum over the patch of ( (I1(x + u) - I0(x)) - mean )^2
//      (I0 the current level's luma, I1 the previous level's read bilinearly, the patch's mean
//      difference removed: a change of brightness costs nothing), with I0's gradient standing in
//      for I1's at x + u (DIS's inverse compositional form: the 2x2 system's matrix is the
//      template's, built once). The vector of the lowest cost seen is kept; a step that leaves
//      SEARCH_PATCH pixels of u0 ends the search (the patch has lost its content).
//      Propagation (p.patch_in set; ref::kSearchRounds rounds after the first): u0 is the cheapest
//      of the patch's own and its four neighbours' vectors of the round before, among those within
//      p.prop_reach pixels of its seed (DIS's spatial propagation, in rounds instead of a raster
//      scan, so that every patch runs in parallel; the reach keeps periodic texture from handing
//      a patch a period-off vector that costs less).
//   2. densify (one invocation per pixel): the patches covering the pixel, each weighted by
//      1 / max(SEARCH_WEIGHT_FLOOR, |I1(x + u_p) - I0(x)|).
//
// Entry provides what polish.h's entry provides, and
//   vec4 load_patch(uint index), void store_patch(uint index, vec4 value)  the patches' vectors
//        (xy) and costs per pixel (z), patches_x x patches_y of them from p.patch_in (read) and
//        p.patch_out (written by search, read by densify)

#define SEARCH_PIXELS 64
// Luma difference (display units, 0..1) below which a patch explains a pixel fully: DIS's 1 of 255.
#define SEARCH_WEIGHT_FLOOR (1.0f / 255.0f)

// The first pixel of patch i.
FGSR_INLINE ivec2 search_origin(uvec2 i, PolishParams p) {
    ivec2 last = max(ivec2(int(p.width), int(p.height)) - SEARCH_PATCH, ivec2(0));
    return min(ivec2(i) * int(p.patch_stride), last);
}

// The template: the current level's luma on the patch and a one-pixel ring around it (for the
// gradient), SEARCH_RING pixels a side, edges clamped. Read once per patch.
#define SEARCH_RING (SEARCH_PATCH + 2)
#define SEARCH_RING_PIXELS (SEARCH_RING * SEARCH_RING)
// The previous level's texels that a patch moved by a sub-pixel vector reads bilinearly.
#define SEARCH_SPAN (SEARCH_PATCH + 1)
#define SEARCH_SPAN_PIXELS (SEARCH_SPAN * SEARCH_SPAN)

// What one evaluation of a vector gives: the sums of the residual r = I1(x + u) - I0(x) and of its
// square over the patch, and of I0's gradient times r (the Gauss-Newton step's right-hand side).
struct SearchSums {
    float sr;
    float sr2;
    vec2 b;
};

// The sums of vector u for the patch at o. Every pixel of the patch shares u's fraction, so the
// bilinear reads of I1 come from one SEARCH_SPAN x SEARCH_SPAN window of texels (81 reads, not 4 a
// pixel); I0 and its gradient come from the template (central differences, as the matrix's).
FGSR_INLINE SearchSums search_sums(float tpl[SEARCH_RING_PIXELS], ivec2 o, vec2 u, PolishParams p) {
    vec2 f0 = floor(u);
    vec2 t = u - f0;
    ivec2 c = o + ivec2(f0);
    float w[SEARCH_SPAN_PIXELS];
    FGSR_UNROLL for (int k = 0; k < SEARCH_SPAN_PIXELS; ++k) w[k] =
        luma_at(c + ivec2(k % SEARCH_SPAN, k / SEARCH_SPAN), true, p.width, p.height);
    SearchSums m;
    m.sr = 0.0f;
    m.sr2 = 0.0f;
    m.b = vec2(0.0f);
    FGSR_UNROLL for (int k = 0; k < SEARCH_PIXELS; ++k) {
        int j = (k >> 3) * SEARCH_SPAN + (k & 7);
        int i = ((k >> 3) + 1) * SEARCH_RING + (k & 7) + 1;
        float r =
            mix(mix(w[j], w[j + 1], t.x), mix(w[j + SEARCH_SPAN], w[j + SEARCH_SPAN + 1], t.x), t.y) - tpl[i];
        m.sr += r;
        m.sr2 += r * r;
        m.b += 0.5f * vec2(tpl[i + 1] - tpl[i - 1], tpl[i + SEARCH_RING] - tpl[i - SEARCH_RING]) * r;
    }
    return m;
}

FGSR_INLINE void search_patch(uvec2 i, PolishParams p) {
    if (i.x >= p.patches_x || i.y >= p.patches_y) return;
    ivec2 o = search_origin(i, p);
    float tpl[SEARCH_RING_PIXELS];
    FGSR_UNROLL for (int k = 0; k < SEARCH_RING_PIXELS; ++k) tpl[k] =
        polish_cur(o + ivec2(k % SEARCH_RING - 1, k / SEARCH_RING - 1), p);
    // The template's matrix, its mean removed (the residual's mean is removed before each step).
    float h11 = 0.0f, h12 = 0.0f, h22 = 0.0f;
    vec2 gsum = vec2(0.0f);
    FGSR_UNROLL for (int k = 0; k < SEARCH_PIXELS; ++k) {
        int j = ((k >> 3) + 1) * SEARCH_RING + (k & 7) + 1;
        vec2 g = 0.5f * vec2(tpl[j + 1] - tpl[j - 1], tpl[j + SEARCH_RING] - tpl[j - SEARCH_RING]);
        h11 += g.x * g.x;
        h12 += g.x * g.y;
        h22 += g.y * g.y;
        gsum += g;
    }
    const float inv_n = 1.0f / float(SEARCH_PIXELS);
    h11 -= gsum.x * gsum.x * inv_n;
    h12 -= gsum.x * gsum.y * inv_n;
    h22 -= gsum.y * gsum.y * inv_n;
    float det = h11 * h22 - h12 * h12;
    vec2 seed =
        field_bilinear(vec2(o) + vec2(0.5f * float(SEARCH_PATCH) - 0.5f), p.mv_offset, p.width, p.height);
    // Propagation: the first n_cand evaluations are the four neighbours' vectors of the last round,
    // each against the patch's own (its stored cost); the steps start from the cheapest.
    vec2 u0 = seed;
    float c0 = 0.0f;
    int n_cand = 0;
    if (p.patch_in != MOTION_NONE) {
        vec4 pv = load_patch(p.patch_in + i.y * p.patches_x + i.x);
        u0 = vec2(pv.x, pv.y);
        c0 = pv.z;
        n_cand = 4;
    }
    vec2 u = u0, best = u0;
    float best_cost = 3.0e38f;
    // One loop, so that search_sums (81 reads and 64 pixels' sums) is compiled once: llvmpipe
    // compiles a pipeline at its first dispatch.
    FGSR_DONT_UNROLL for (int k = 0; k <= n_cand + int(p.search_steps); ++k) {
        vec2 v = u;
        if (k < n_cand) {
            ivec2 n = ivec2(i) + (k == 0 ? ivec2(-1, 0)
                                         : (k == 1 ? ivec2(1, 0) : (k == 2 ? ivec2(0, -1) : ivec2(0, 1))));
            if (n.x < 0 || n.y < 0 || n.x >= int(p.patches_x) || n.y >= int(p.patches_y)) continue;
            vec4 nv = load_patch(p.patch_in + uint(n.y) * p.patches_x + uint(n.x));
            v = vec2(nv.x, nv.y);
            if (length(v - seed) > p.prop_reach) continue;
        } else if (k == n_cand) {
            v = u = best = u0;
        }
        SearchSums m = search_sums(tpl, o, v, p);
        float cost = m.sr2 - m.sr * m.sr * inv_n;
        if (k < n_cand) {
            if (cost * inv_n < c0) {
                c0 = cost * inv_n;
                u0 = v;
            }
            continue;
        }
        if (cost < best_cost) {
            best_cost = cost;
            best = u;
        }
        // A flat patch (or one of a single edge's direction) has no step: the seed stays.
        if (k == n_cand + int(p.search_steps) || !(det > 1.0e-12f)) break;
        vec2 b = m.b - gsum * (m.sr * inv_n);
        u -= vec2(h22 * b.x - h12 * b.y, h11 * b.y - h12 * b.x) / det;
        // Written so that a vector that is not a number ends the search too.
        vec2 moved = abs(u - u0);
        if (!(max(moved.x, moved.y) <= float(SEARCH_PATCH))) break;
    }
    store_patch(p.patch_out + i.y * p.patches_x + i.x, vec4(best, best_cost * inv_n, 0.0f));
}

// The range of patch indices along one axis whose patches may cover coordinate x (the moved-in
// last patch included): the caller tests each.
FGSR_INLINE ivec2 search_cover(int x, uint count, uint stride) {
    int hi = min(x / int(stride) + 1, int(count) - 1);
    int lo = max((x - SEARCH_PATCH + 1 + int(stride) - 1) / int(stride) - 1, 0);
    return ivec2(lo, hi);
}

FGSR_INLINE void search_densify_pixel(uvec2 u, PolishParams p) {
    if (u.x >= p.width || u.y >= p.height) return;
    ivec2 q = ivec2(u);
    float i0 = polish_cur(q, p);
    ivec2 rx = search_cover(q.x, p.patches_x, p.patch_stride);
    ivec2 ry = search_cover(q.y, p.patches_y, p.patch_stride);
    vec2 sum = vec2(0.0f);
    float wsum = 0.0f;
    for (int y = ry.x; y <= ry.y; ++y)
        for (int x = rx.x; x <= rx.y; ++x) {
            ivec2 o = search_origin(uvec2(x, y), p);
            ivec2 d = q - o;
            if (d.x < 0 || d.y < 0 || d.x >= SEARCH_PATCH || d.y >= SEARCH_PATCH) continue;
            vec4 pv = load_patch(p.patch_out + uint(y) * p.patches_x + uint(x));
            vec2 v = vec2(pv.x, pv.y);
            float w =
                1.0f / max(SEARCH_WEIGHT_FLOOR, abs(luma_prev_bilinear(vec2(q) + v, p.width, p.height) - i0));
            sum += w * v;
            wsum += w;
        }
    // Every pixel lies in a patch (the last ones end at the edge); a level smaller than a patch has
    // one patch, whose reads outside it are clamped.
    if (wsum > 0.0f) store_mv(p.mv_offset + u.y * p.width + u.x, sum / wsum);
}
