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
// Entry provides:
//   vec4 load_frame_color(uint pixel)   the frame's ingested colour
//   vec4 load_prev_color(uint pixel)    the previous frame's
//   vec2 load_frame_mv(uint pixel)      the frame's ingested vectors (to the previous frame)
//   void store_cut_block(uint block, vec4 sad, vec4 level)   ref::CutBlock

FGSR_INLINE uint cut_blocks_x(IngestParams p) { return (p.width + CUT_BLOCK - 1u) / CUT_BLOCK; }
FGSR_INLINE uint cut_blocks_y(IngestParams p) { return (p.height + CUT_BLOCK - 1u) / CUT_BLOCK; }

FGSR_INLINE void cut_block(uvec2 block, IngestParams p) {
    if (block.x >= cut_blocks_x(p) || block.y >= cut_blocks_y(p)) return;
    const uint n_max = (CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP);
    float cur[(CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP)];
    float prv[(CUT_BLOCK / CUT_STEP) * (CUT_BLOCK / CUT_STEP)];
    float mean = 0.0f, mean_prev = 0.0f, sad_raw = 0.0f;
    uint n = 0u;
    ivec2 last = ivec2(int(p.width) - 1, int(p.height) - 1);
    for (uint k = 0u; k < n_max; ++k) {
        uvec2 q = block * CUT_BLOCK + CUT_STEP * uvec2(k % (CUT_BLOCK / CUT_STEP), k / (CUT_BLOCK / CUT_STEP));
        if (q.x >= p.width || q.y >= p.height) continue;
        uint i = q.y * p.width + q.x;
        float l = motion_luma(load_frame_color(i));
        ivec2 r = clamp(ivec2(floor(vec2(q) + vec2(0.5f) + load_frame_mv(i))), ivec2(0), last);
        float lp = motion_luma(load_prev_color(uint(r.y) * p.width + uint(r.x)));
        sad_raw += abs(l - lp);
        mean += l;
        mean_prev += lp;
        cur[n] = l;
        prv[n] = lp;
        ++n;
    }
    float inv = 1.0f / float(max(n, 1u));
    mean *= inv;
    mean_prev *= inv;
    float sad = 0.0f, contrast = 0.0f;
    for (uint k = 0u; k < n; ++k) {
        sad += abs((cur[k] - mean) - (prv[k] - mean_prev));
        contrast += abs(cur[k] - mean);
    }
    store_cut_block(block.y * cut_blocks_x(p) + block.x, vec4(sad_raw * inv, contrast * inv, sad * inv, 0.0f),
                    vec4(mean, mean_prev, 0.0f, 0.0f));
}
