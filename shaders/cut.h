// Stage cut of pass ingest (sessions with vectors, Params::vector_cuts, on by default): do the
// frame's own vectors explain its colour?
//
// A client that hands over vectors need not say when the camera cuts (FrameView::reset): across a
// cut its first frame's vectors point to where each surface point was under the other shot's
// camera (a real reprojection, usually far off and never zero), and the next pair would read them
// as frame 0's motion. Colour-only sessions find cuts in block matching (motion.cpp,
// summarise_motion); sessions with vectors run no matching, so this stage asks the same question
// of the given vectors instead: per CUT_BLOCK x CUT_BLOCK block, over every CUT_STEP-th pixel in
// each direction, the mean absolute difference between the frame's display luma (motion_luma) and
// the previous frame's at the pixel's previous position (its vector, nearest pixel, clamped to the
// frame: content entering at an edge compares with the edge and mismatches there, as it would in
// matching), the block's contrast (the mean absolute deviation of its own samples' luma), the
// same SAD with the block's mean difference taken out, and both means. The host counts the blocks
// that find no match under the same rule as block matching (SAD above kCutSad and above
// kCutContrast times the contrast), both on the colour as given and relit (a change of the whole
// frame's lighting fitted to the blocks' means: ref::fit_lighting, ref::cut_share), and calls the
// frame a cut where their share is most of the frame and jumps (ref::is_vector_cut). One
// invocation per block.
//
// Sessions that estimate motion run the same block statistics on their finest matched pyramid
// level, each block under its own matched vector and the integer offsets within CUT_MATCH_SEARCH
// of it (match.comp's build FGSR_MATCH_CUT), only for a frame that block matching's own SAD makes
// a cut: that SAD decides as given, and the host relights with these (ref::summarise_motion).
//
// Entry provides:
//   float load_cut_luma(uint pixel)       the frame's display luma (motion_luma)
//   float load_cut_prev_luma(uint pixel)  the previous frame's
//   vec2  load_cut_mv(uint pixel)         the pixel's vector to the previous frame
//   void  store_cut_block(uint block, vec4 sad, vec4 level)   ref::CutBlock

FGSR_INLINE uint cut_blocks_x(uint width) { return (width + CUT_BLOCK - 1u) / CUT_BLOCK; }
FGSR_INLINE uint cut_blocks_y(uint height) { return (height + CUT_BLOCK - 1u) / CUT_BLOCK; }

// CUT_SEARCH (the entry may set it): the previous frame is also read at the integer offsets within
// +-CUT_SEARCH of each sample's vector, and the block keeps the offset of the smallest SAD without
// its mean difference. Given vectors are checked as they are (0); block matching's vectors, whose
// SAD a change of lighting misleads, get a small search (match.comp).
#ifndef CUT_SEARCH
#define CUT_SEARCH 0
#endif

FGSR_INLINE void cut_block(uvec2 block, uint width, uint height) {
    if (block.x >= cut_blocks_x(width) || block.y >= cut_blocks_y(height)) return;
    const uint n_max = (CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP);
    float cur[(CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP)];
    ivec2 at[(CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP)]; // each sample's previous position
    float mean = 0.0f;
    uint n = 0u;
    ivec2 last = ivec2(int(width) - 1, int(height) - 1);
    ivec2 reach = ivec2(CUT_SEARCH); // within it of the frame: the offsets cannot overflow
    for (uint k = 0u; k < n_max; ++k) {
        uvec2 q = block * CUT_BLOCK + CUT_STEP * uvec2(k % (CUT_BLOCK / CUT_STEP), k / (CUT_BLOCK / CUT_STEP));
        if (q.x >= width || q.y >= height) continue;
        uint i = q.y * width + q.x;
        float l = load_cut_luma(i);
        at[n] = clamp(ivec2(floor(vec2(q) + vec2(0.5f) + load_cut_mv(i))), -reach, last + reach);
        mean += l;
        cur[n] = l;
        ++n;
    }
    float inv = 1.0f / float(max(n, 1u));
    mean *= inv;
    float contrast = 0.0f;
    for (uint k = 0u; k < n; ++k) contrast += abs(cur[k] - mean);
    float best_sad = 3.0e38f, best_raw = 0.0f, best_mean_prev = 0.0f;
    for (int dy = -CUT_SEARCH; dy <= CUT_SEARCH; ++dy)
        for (int dx = -CUT_SEARCH; dx <= CUT_SEARCH; ++dx) {
            float prv[(CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP)];
            float mean_prev = 0.0f, sad_raw = 0.0f;
            for (uint k = 0u; k < n; ++k) {
                ivec2 r = clamp(at[k] + ivec2(dx, dy), ivec2(0), last);
                float lp = load_cut_prev_luma(uint(r.y) * width + uint(r.x));
                sad_raw += abs(cur[k] - lp);
                mean_prev += lp;
                prv[k] = lp;
            }
            mean_prev *= inv;
            float sad = 0.0f;
            for (uint k = 0u; k < n; ++k) sad += abs((cur[k] - mean) - (prv[k] - mean_prev));
            if (sad < best_sad) {
                best_sad = sad;
                best_raw = sad_raw;
                best_mean_prev = mean_prev;
            }
        }
    store_cut_block(block.y * cut_blocks_x(width) + block.x, vec4(best_raw * inv, contrast * inv, best_sad * inv, 0.0f),
                    vec4(mean, best_mean_prev, 0.0f, 0.0f));
}
