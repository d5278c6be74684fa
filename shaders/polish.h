// Pass `polish`: variational refinement of the estimated vectors (colour-only sessions, after
// `flow`), the third stage of DIS optical flow (Kroeger et al., ECCV 2016) in a form that suits a
// compute pass. One invocation per pixel of one colour of a checkerboard (p.parity): the host runs
// it 2 x kPolishIterations times, alternating the colours (red-black Gauss-Seidel), so that each
// pixel reads only neighbours that the same dispatch does not write, and the vectors are updated in
// place.
//
// Energy of the field v (internal convention: pixels, current -> previous):
//   sum over pixels of psi_d( (I1(x + v) - I0(x))^2 / (|grad I0|^2 + zeta^2) )
//   + alpha x sum over neighbour pairs of psi_s( |v(x) - v(n)|^2 ),
// psi(s^2) = sqrt(s^2 + eps^2) (Charbonnier: robust to occlusions and motion boundaries), I0 the
// current frame's level-0 luma, I1 the previous frame's. The data term is normalised by the
// gradient (as DIS's refinement does), so that alpha means the same in dark and bright, flat and
// contrasted regions. Each update linearises the data term at the pixel's current vector (I1
// read bilinearly at x + v, the gradient taken from I0, which the match approximates there),
// takes the robust weights at the current values, and solves the pixel's 2x2 system for the
// increment, which is over-relaxed (p.omega: successive over-relaxation) and clamped to 1 px.
// Block matching leaves vectors constant over blocks, and wrong in pixels the per-pixel choice tore
// from their object; this pulls them toward what the colour and their neighbours say
// (docs/MOTION.md, "Variational refinement").
//
// Coarse to fine (polish_coarse, colour-only sessions): before `flow`, the same sweeps refine a
// dense field on the coarser levels of the pyramids, from the top one (kPolishCoarseTop) down to
// level 1, each level seeded (polish_seed_pixel) from the one above it, the top one from the
// finest matched blocks. A wrong block match of a few frame pixels is a fraction of a pixel there,
// within reach of the linearised data term, and the smoothness spreads the neighbours' motion over
// it; flow then takes the level-1 field, upsampled, as one more candidate per pixel, where it
// explains the pixel's colour better than flow's own choice. This is DIS's scheme (a refinement
// at every scale) on top of the block matching (docs/MOTION.md, "Coarse to fine").
//
// Entry provides:
//   float load_cur(uint pixel)   luma of the current frame at the level (p.luma_offset added)
//   float load_prev(uint pixel)  luma of the previous frame at the level
//   vec2  load_mv(uint index)    the vectors buffer: the frame's vectors (written by flow, then by
//                                this pass) or the coarse levels' fields (p.mv_offset)
//   void  store_mv(uint index, vec2 v)
//   vec4  load_field(uint index) the block field (polish_seed_pixel from the blocks only)
//   vec2  load_field_vector(uint index)  the same as load_mv (field_read.h: the seed's reads of the
//                                level above)

#define POLISH_STEP 1.0f // pixels: the largest change of a vector in one update

#include "luma_read.h"

FGSR_INLINE float polish_cur(ivec2 q, PolishParams p) {
    return luma_at(q, false, p.width, p.height);
}

// Invocation h covers the pixel of row h.y, column 2 h.x or 2 h.x + 1, whichever has the colour
// p.parity: the dispatch is (width + 1) / 2 wide, so that no invocation idles on the other colour.
FGSR_INLINE void polish_pixel(uvec2 h, PolishParams p) {
    uvec2 u = uvec2(2u * h.x + ((h.y + p.parity) & 1u), h.y);
    if (u.x >= p.width || u.y >= p.height) return;
    ivec2 q = ivec2(u);
    uint i = p.mv_offset + u.y * p.width + u.x;
    vec2 v = load_mv(i);
    float gx = 0.5f * (polish_cur(q + ivec2(1, 0), p) - polish_cur(q - ivec2(1, 0), p));
    float gy = 0.5f * (polish_cur(q + ivec2(0, 1), p) - polish_cur(q - ivec2(0, 1), p));
    float norm = 1.0f / (gx * gx + gy * gy + p.zeta * p.zeta);
    float it = luma_prev_bilinear(vec2(q) + v, p.width, p.height) - polish_cur(q, p);
    float wd = norm / sqrt(it * it * norm + p.eps_data * p.eps_data);
    // Smoothness toward the four neighbours (at the frame's edge the pixel itself: no pull).
    vec2 pull = vec2(0.0f);
    float ws = 0.0f;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = k == 0 ? ivec2(-1, 0) : (k == 1 ? ivec2(1, 0) : (k == 2 ? ivec2(0, -1) : ivec2(0, 1)));
        ivec2 n = luma_clamp(q + o, p.width, p.height);
        vec2 d = load_mv(p.mv_offset + uint(n.y) * p.width + uint(n.x)) - v;
        float w = 1.0f / sqrt(dot(d, d) + p.eps_smooth * p.eps_smooth);
        pull += w * d;
        ws += w;
    }
    float a11 = wd * gx * gx + p.alpha * ws;
    float a12 = wd * gx * gy;
    float a22 = wd * gy * gy + p.alpha * ws;
    float b1 = p.alpha * pull.x - wd * gx * it;
    float b2 = p.alpha * pull.y - wd * gy * it;
    float det = a11 * a22 - a12 * a12;
    if (!(det > 1.0e-20f)) return; // (a non-finite vector never comes from a finite one)
    vec2 step = vec2(a22 * b1 - a12 * b2, a11 * b2 - a12 * b1) / det;
    store_mv(i, v + clamp(p.omega * step, vec2(-POLISH_STEP), vec2(POLISH_STEP)));
}

#include "field_read.h"

// The initial field of a coarse level (in pixels of the level): the next coarser level's field
// doubled, or at the top level the finest matched blocks' vectors, both read bilinearly between
// their centres (edges clamped).
FGSR_INLINE vec2 polish_block_bilinear(vec2 b, PolishParams p) {
    vec2 fb = floor(b);
    vec2 f = b - fb;
    ivec2 c = ivec2(fb);
    ivec2 hi = ivec2(int(p.blocks_x) - 1, int(p.blocks_y) - 1);
    vec2 corner[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 q = clamp(c + ivec2(k & 1, k >> 1), ivec2(0), hi);
        vec4 v = load_field(p.block_offset + uint(q.y) * p.blocks_x + uint(q.x));
        corner[k] = vec2(v.x, v.y);
    }
    return mix(mix(corner[0], corner[1], f.x), mix(corner[2], corner[3], f.x), f.y);
}

FGSR_INLINE void polish_seed_pixel(uvec2 u, PolishParams p) {
    if (u.x >= p.width || u.y >= p.height) return;
    vec2 centre = vec2(u) + vec2(0.5f);
    vec2 v;
    if (p.src_width > 0u) {
        v = 2.0f * field_bilinear(centre * 0.5f - vec2(0.5f), p.src_offset, p.src_width, p.src_height);
    } else {
        // Block vectors are in pixels of level block_shift; blocks cover MOTION_BLOCK of its pixels.
        vec2 b = centre * (float(1u << p.level) / float(MOTION_BLOCK << p.block_shift)) - vec2(0.5f);
        v = polish_block_bilinear(b, p) * (float(1u << p.block_shift) / float(1u << p.level));
    }
    store_mv(p.mv_offset + u.y * p.width + u.x, v);
}
