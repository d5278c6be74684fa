// Pass `luma`: the luma pyramid of a submitted frame, for motion estimation from colour (colour-
// only sessions, FrameFormat::has_vectors false). Level 0 is the display-referred luma of the
// frame (the square root of linear luminance clamped to [0, 1], as blend.h's brightness: about
// perceptually even steps, so that a matching cost means the same in dark and bright regions);
// level k is level k - 1 low-passed and decimated by 2, of size ceil(size / 2). Every level lives in one float
// buffer per frame at offsets the host computes. One invocation per pixel of the level written.
//
// Lighting gain (luma_gain_lane, luma_gain; before block matching of a pair): block matching, the
// flow pass and the refinement compare luma, and a change of the whole frame's brightness (a fade,
// a flash, an exposure change) breaks that constancy: under a fade the matched vectors strayed by
// 0.5-18 px and its last steps were cut; a flash misled most blocks. The previous frame's pyramid,
// every level, is therefore scaled by k where k is more than LUMA_GAIN_GATE from 1: the median of
// the ratios current / previous of the coarsest level's texels (0.1-0.4 % of the pixels, already
// low-passed, so that the motion between two frames moves them little), counted in a histogram of
// 1/64-octave bins (ratios beyond 1/4 and 4 count in the end bins). A gain of linear light g is a
// gain of sqrt(g) of this luma at every pixel, so under a change of lighting most texels measure
// it; content that enters, leaves or is uncovered changes the frame's mean but only a minority of
// the texels, and the median stays at 1 (the frames' mean ratio, tried first, measured up to 4.5 %
// on train captures without any change of lighting, and scaling by it lost up to 0.32 dB there;
// docs/MOTION.md, "Fades and flashes").
// Texels darker than LUMA_GAIN_MIN measure nothing (near black the ratio is noise), and fewer
// than half the texels measuring leaves k = 1. The previous frame's pyramid is not read again
// after this pair (the next pair's previous frame is the current one), so it is scaled in place.
// A scene cut's ratios scatter: whatever k they give, its blocks still match nothing.
//
// Entry provides:
//   vec4  load_color(uint pixel)              the frame's colour (level 0)
//   float load_level(uint index)              the pyramid (levels > 0 read the finer level; the
//                                             gain: the current frame's)
//   void  store_level(uint index, float value)
//   float load_prev_level(uint index)         the gain: the previous frame's pyramid
//   void  add_to_bin(uint bin), uint load_bin(uint bin)   the gain's histogram

// motion_luma (common.h): that luma of one colour.

// Level 0 and the levels above it are separate builds on the GPU (luma_level0 defines
// FGSR_LUMA_LEVEL0): CPU devices run both sides of a branch with the inactive lanes masked off,
// and level 0 then paid the 16 reads of the low-pass as well. The CPU reference reads p.level.
#if defined(FGSR_LUMA_LEVEL0)
#define LUMA_LEVEL0(p) true
#elif defined(__cplusplus)
#define LUMA_LEVEL0(p) ((p).level == 0u)
#else
#define LUMA_LEVEL0(p) false
#endif

FGSR_INLINE void luma_pixel(uvec2 q, LumaParams p) {
    if (q.x >= p.dst_width || q.y >= p.dst_height) return;
    float v;
    if (LUMA_LEVEL0(p)) {
        v = motion_luma(load_color(q.y * p.src_width + q.x));
    } else {
        // Separable [1 3 3 1] / 8 over source pixels 2q - 1 .. 2q + 2 (edges clamped): a low-pass
        // before the decimation, so that fine periodic texture (checkers, bricks) fades on the
        // coarse levels instead of aliasing into false structure that block matching would lock on.
        v = 0.0f;
        for (int j = 0; j < 4; ++j) {
            int y = clamp(2 * int(q.y) - 1 + j, 0, int(p.src_height) - 1);
            float wy = (j == 0 || j == 3) ? 0.125f : 0.375f;
            for (int i = 0; i < 4; ++i) {
                int x = clamp(2 * int(q.x) - 1 + i, 0, int(p.src_width) - 1);
                float wx = (i == 0 || i == 3) ? 0.125f : 0.375f;
                v += wx * wy * load_level(p.src_offset + uint(y) * p.src_width + uint(x));
            }
        }
    }
    store_level(p.dst_offset + q.y * p.dst_width + q.x, v);
}

#define LUMA_GAIN_MIN 0.05f // luma (display-referred, as the pyramid) below which a texel measures no gain
#define LUMA_GAIN_OCTAVES 2.0f // the histogram spans ratios of 2^-2 .. 2^2 ...
#define LUMA_GAIN_BIN_SCALE 64.0f // ... in bins of 1/64 octave (1.1 %)
#define LUMA_GAIN_GATE 0.02f // |k - 1| at or below this: no gain (k = 1), the pyramid untouched

// The histogram bin of one coarsest-level texel's ratio now / before (current / previous);
// negative where either is too dark to measure (or not finite).
FGSR_INLINE int luma_gain_bin(float now, float before) {
    if (!(now >= LUMA_GAIN_MIN && before >= LUMA_GAIN_MIN)) return -1;
    float b = floor((log2(now / before) + LUMA_GAIN_OCTAVES) * LUMA_GAIN_BIN_SCALE);
    return int(clamp(b, 0.0f, float(LUMA_GAIN_BINS - 1u)));
}

// Adds the bins of one lane's texels (lane, lane + LUMA_GAIN_LANES, ... of the coarsest level;
// p.src_offset: the level's offset, p.src_width: its texels) to the histogram.
FGSR_INLINE void luma_gain_lane(uint lane, LumaParams p) {
    for (uint i = lane; i < p.src_width; i += LUMA_GAIN_LANES) {
        int b = luma_gain_bin(load_level(p.src_offset + i), load_prev_level(p.src_offset + i));
        if (b >= 0) add_to_bin(uint(b));
    }
}

// The gain from the histogram: the median ratio (the centre of the bin that holds it), where at
// least half the texels measured one; 1 within LUMA_GAIN_GATE of 1 or without enough texels.
FGSR_INLINE float luma_gain(uint texels) {
    uint measured = 0u;
    for (uint b = 0u; b < LUMA_GAIN_BINS; ++b) measured += load_bin(b);
    if (measured == 0u || 2u * measured < texels) return 1.0f;
    uint below = 0u, bin = 0u;
    for (; bin < LUMA_GAIN_BINS; ++bin) {
        below += load_bin(bin);
        if (2u * below >= measured) break;
    }
    float k = exp2((float(bin) + 0.5f) / LUMA_GAIN_BIN_SCALE - LUMA_GAIN_OCTAVES);
    return abs(k - 1.0f) > LUMA_GAIN_GATE ? k : 1.0f;
}
