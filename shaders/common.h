// Shared GLSL / C++ layer of the algorithm headers.
//
// Every pass is one `<pass>.comp` (bindings, main) plus one `<pass>.h` (the algorithm). The
// algorithm header only calls `load_*` / `store_*` functions its entry defines, so the very same
// text compiles as GLSL on the GPU and, with GLM, as the C++ CPU reference (in C++ the header is
// included inside a struct whose members provide load_/store_). Push-constant blocks are plain
// structs of 4-byte scalars written once here, static_assert'ed on the C++ side.
#ifndef FGSR_SHADERS_COMMON_H
#define FGSR_SHADERS_COMMON_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
namespace fgsr::gpu {
using namespace glm;
using uint = uint32_t;
using uint64_t = std::uint64_t;
} // namespace fgsr::gpu
#define FGSR_INLINE inline
#define FGSR_UNROLL
#define FGSR_DONT_UNROLL
#else
#extension GL_EXT_control_flow_attributes : require
#define FGSR_UNROLL [[unroll]]
// A loop kept a loop: its body (for example a 32-read block cost) is compiled once. llvmpipe
// compiles each pipeline at its first dispatch; unrolled copies of such bodies cost seconds there.
#define FGSR_DONT_UNROLL [[dont_unroll]]
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define FGSR_INLINE
#endif

// Workgroup size of every 2D pass (square, FGSR_GROUP x FGSR_GROUP). Each pass is built twice,
// with 8 (GPUs) and 32 (CPU devices such as lavapipe, whose cost per workgroup dominates; a
// specialization constant for the size was measured 15x slower there than a literal one).
#ifndef FGSR_GROUP
#define FGSR_GROUP 8
#endif

// Depth that marks "nothing here" (holes) and invalid depths after ingest.
#define FGSR_FAR_DEPTH 1.0e30

// Splat key of an empty pixel: all bits set (atomicMin never writes a larger value).
#define FGSR_EMPTY_KEY_LO 0xffffffffu

#ifdef __cplusplus
namespace fgsr::gpu {
#endif
// ---- push-constant blocks (std430 scalars only; layout identical in GLSL and C++) ----

// ingest: client formats -> internal convention
// The cut stage's blocks (shaders/cut.h): CUT_BLOCK x CUT_BLOCK pixels, every CUT_STEP-th one in
// each direction sampled.
#define CUT_BLOCK 8u
#define CUT_STEP 2u
// The integer search of the colour-only sessions' build around each block's matched vector (cut.h).
#define CUT_MATCH_SEARCH 2
#define FGSR_BRIGHT_TILE_SHIFT 4u // the dilate stage's over-white flags: per 16x16 tile (shaders/dilate.h)
// The workgroup of the dilate stage's edge-rule build (one invocation per 16x16 tile): small, so
// that a small frame's few hundred tiles still spread over every CPU thread of lavapipe (one
// workgroup of FGSR_GROUP x FGSR_GROUP tiles would run a 480x270 frame's 510 on one).
#define FGSR_DILATE_EDGES_GROUP_X 8
#define FGSR_DILATE_EDGES_GROUP_Y 4

struct IngestParams {
    uint width;
    uint height;
    uint color_format; // fgsr::ColorFormat
    uint depth_kind;   // fgsr::DepthKind
    float near_plane;
    float far_plane; // <= 0 or inf: infinite
    uint mv_format;  // fgsr::MvFormat
    uint has_mv;     // 0: vectors unknown, written as 0
    float mv_scale_x; // internal = raw * scale + offset (units, direction and y axis folded in;
    float mv_scale_y; // the offset removes camera jitter from vectors that contain it, QRISP Eq. 1)
    float mv_offset_x;
    float mv_offset_y;
    uint has_depth; // 0: no depth plane (colour-only session): depth 1 until the motion passes set it
    // Stage dilate (shaders/dilate.h): luminance above which a pixel counts as over-white (0: no
    // flags, no over-white rule), the relative depth by which a source must lie in front (both
    // rules), the flag tiles per row; the edge rule's cost ratio (0: no edge rule, as for a frame
    // without a previous one).
    float bright;
    float dilate_depth;
    uint bright_tiles_x;
    float edge_ratio;
};

// GenParams::quadratic bits (motion.h): the model, extrapolation's search for the frame-0 vector,
// interpolation's median of the acceleration over the same surface, the frame-0 depth test
// expecting the depth change the motion implies.
#define MOTION_ACCEL 1u
#define MOTION_ACCEL_SEARCH 2u
#define MOTION_ACCEL_MEDIAN 4u
#define MOTION_DEPTH_MOTION 8u

// splat, refine, disocc, warp and blend share one parameter block per generated frame.
struct GenParams {
    uint width;
    uint height;
    float alpha;      // interpolation: (0,1); extrapolation: the a of 1+a, (0,1]
    uint extrapolate; // 0: interpolate between frame 0 and 1; 1: extrapolate after frame 1
    uint quadratic;   // 0: uniform velocity; else MOTION_ACCEL (uniform acceleration, needs
                      // frame 0 vectors) | MOTION_ACCEL_SEARCH | MOTION_ACCEL_MEDIAN |
                      // MOTION_DEPTH_MOTION (motion.h)
    uint frame0_has_mv;
    uint frame1_has_mv;
    float t_depth;  // T_D: relative depth difference (|d0-d1| / min(d0,d1)) that means disocclusion
    float t_bright; // T_B: luma difference (display-referred, [0,1]) that means a shading change
    uint blend_mode; // BLEND_MIX: weighted blend when similar (else paper Eq. 1: the temporally
                     // closer) | BLEND_DEPTH_MOTION (blend.h)
    uint fill_gaps;  // 1: refine fills grid-like gaps; 0: every empty pixel is a hole
    uint fill_holes; // 0: holes keep a zero vector; else bit 1 (disocc gives holes a vector) |
                     // FGSR_FILL_HOLES_COVER (a hole pixel that the footprint of a surface in
                     // front overlaps takes that surface's vectors) | FGSR_FILL_HOLES_FRAME0
                     // (extrapolation: a hole takes frame 0 where frame 1's sample lies on the
                     // surface that left; disocc.h, warp.h)
    uint warp_cubic; // 1: warp samples colour with the de-ringed Catmull-Rom cubic; 0: bilinear (warp.h)
};
#define FGSR_FILL_HOLES_COVER 2u
#define FGSR_FILL_HOLES_FRAME0 4u
// GenParams::blend_mode
#define BLEND_MIX 1u          // where the warped frames agree: the alpha-weighted mix (BlendMode::mix)
#define BLEND_DEPTH_MOTION 2u // the depth test: frame 0's depth against what frame 1 may show (blend_depth.h)

// `g` with the mode of a build that fixes it (FGSR_GENERATE_EXTRAPOLATE 0u or 1u: the CPU builds of
// generate and generate_sr per mode, variants.def), so that the other mode's branch is compiled
// out: CPU devices run both sides of a branch, the untaken one with its lanes masked off.
FGSR_INLINE GenParams fixed_mode(GenParams g) {
#ifdef FGSR_GENERATE_EXTRAPOLATE
    g.extrapolate = FGSR_GENERATE_EXTRAPOLATE;
#endif
    return g;
}

// splat: the generated frame's GenParams (g.alpha unused), then the alphas this dispatch splats,
// sharing the motion of each source pixel (splat.h). Alpha k writes its keys and field vectors
// at element offset k * stride of the keys and motion buffers.
#define FGSR_SPLAT_ALPHAS 4u
struct SplatParams {
    GenParams g;
    uint count;  // alphas in this dispatch, 1..FGSR_SPLAT_ALPHAS
    uint stride; // elements between the key (and field-vector) slices of consecutive alphas
    float alpha0;
    float alpha1;
    float alpha2;
    float alpha3;
};

// SrParams::flags
#define SR_DEPTH_MOTION 1u   // sr.h step 2: the depth test expects the depth change the motion implies
#define SR_SMOOTH_SPATIAL 2u // sr.h step 5: the spatial upsample is the cubic B-spline (aliased input)
#define SR_NOISE_AVERAGE 4u  // sr.h step 7: fewer new samples where they scatter about the history like noise
#define SR_NOISE_KERNEL 8u   // sr.h step 3: the LUT's history smoother where the samples scatter like noise
#define SR_SHARP_CURRENT                                                                                     \
    16u // sr.h step 4: the current samples' term is the spatial upsample (antialiased input)

// super resolution of one rendered frame (sr.h) and the joint ISR / ESR pass (generate_sr.h)
struct SrParams {
    uint lr_width;
    uint lr_height;
    uint hr_width;
    uint hr_height;
    float scale;      // hr / lr
    float jitter_x;   // sample offset of this frame from the LR pixel centre, LR pixels, y down
    float jitter_y;
    float a;          // Eq. 2: weight of the current samples
    float b;          // Eq. 2: fall-off of a sample's weight with its distance (LR pixels)
    float t_depth;    // history rejection: relative depth difference
    uint resample;    // RESAMPLE_* of the history
    uint has_history; // 0: first frame or reset: spatial upsample only
    uint dilate;      // 1: motion vector of the frontmost pixel of the 3x3 neighbourhood
    float clip;       // ISR / ESR: history clipped to mean +- clip * sd of the LR 3x3 (0: off)
    float disagree;   // sr: history weight falls by disagree x its disagreement (sr.h step 6; 0: off)
    uint flags;       // SR_*
};

// classify (classify.h): per-tile work classification. Tile lists are uint buffers: [0..2]
// workgroup counts for vkCmdDispatchIndirect (x grows with appends; y = z = 1), [3] number of
// tiles, [4] tile side, [5] side of the square of invocations each listed tile gets, [6..7] 0,
// then the tiles from TILE_LIST_HEADER on, packed x | y << 16 in tile units.
#define TILE_STATIC 1u  // every pixel is a static source (generate) / static LR pixel (sr)
#define TILE_DIRTY 2u   // with TILE_STATIC: a moving source splatted into the tile
#define TILE_MOVING 16u // some pixel is not static (set by classify's first stage, never cleared)
#define CLASSIFY_GENERATE 0u
#define CLASSIFY_SR 1u
#define TILE_LIST_HEADER 8u
// Pixels per invocation (a row segment inside one tile: at most the smallest tile side, a multiple
// of 4) of classify's stage 0 in the CPU-device build (FGSR_GROUP 32); GPU builds take 1 pixel.
#define FGSR_CLASSIFY_SPAN_CPU 8u
// Pixels per invocation (a row segment) of ingest's fixed-format builds for CPU devices (ingest.comp).
#define FGSR_INGEST_SPAN_CPU 4u

struct ClassifyParams {
    GenParams g;           // generate mode: the generated frame's; sr mode: width, height (LR), t_depth
    uint tile;             // tile side in pixels: 8, 16 or 32
    uint mode;             // CLASSIFY_*
    uint write_output;     // generate mode: 1 = write copy_through() for static tiles
    uint dilate;           // sr mode: vectors are dilated over 3x3
    uint work_invocations;   // invocations per tile of the pass over the work list (splat / sr)
    uint output_invocations; // invocations per tile of the passes over the generate / static lists
    uint stage;              // 0: per pixel, 1: per tile; informational (each stage is its own build)
    uint pad2;
};

// denoise (denoise.h): adaptive pre-filter of the low-resolution colour of SR sessions.
#define DENOISE_HISTOGRAM 0u // stage 0: noise histogram, one invocation per 2x2 block
#define DENOISE_LEVEL 1u     // stage 1: noise level and filter range, one invocation
#define DENOISE_FILTER 2u    // stage 2: the filter into a scratch buffer, one invocation per pixel
#define DENOISE_COPY 3u      // stage 3: the scratch buffer back into the frame, one invocation per pixel
#define DENOISE_BINS 128u    // histogram bins; the noise buffer holds them, then:
#define DENOISE_SIGMA DENOISE_BINS          // the estimated noise sigma (float bits)
#define DENOISE_RANGE (DENOISE_BINS + 1u)   // the filter's range (float bits)
#define DENOISE_DISPATCH (DENOISE_BINS + 4u) // 3 words: workgroups of stages 2 and 3 (0 when r = 0)
#define DENOISE_WORDS (DENOISE_BINS + 8u)

struct DenoiseParams {
    uint width;
    uint height;
    uint stage;     // DENOISE_*
    uint pad0;
    float strength; // filter range in estimated noise sigmas; 0: no filtering
    float noise_floor; // noise sigma (in the units gamma gives it) left unfiltered
    float gamma;       // noise measured relative to the local brightness to this power (0: absolute)
    float pad2;
};

// Motion estimation from colour (luma.h, match.h, flow.h): a luma pyramid per frame, block
// matching coarse to fine in both directions, then per-pixel vectors, consistency and depth proxy.
#define MOTION_BLOCK 8u       // block side in pixels of its pyramid level
#define MOTION_MAX_LEVELS 6u  // pyramid levels, the finest (full resolution) included
#define SEARCH_PATCH 8        // side in pixels of search.h's patches
#define MOTION_MIN_SIDE 16u   // a coarser level is added while its smaller side stays >= this
#define LUMA_GAIN_LANES 64u   // lanes of the lighting gain's histogram stage (luma.h; one workgroup)
#define LUMA_GAIN_BINS 256u   // bins of the lighting gain's histogram (luma.h)
#define LUMA_GAIN_ROW 1024u   // the gain's scaling: invocations per row (the pyramid's floats as rows)
#define LUMA_GAIN_DISPATCH 4u // the gain buffer: the gain (word 0), the scaling's groups (words 4-6)

struct LumaParams {
    uint src_width; // level 0: the frame; else the finer level
    uint src_height;
    uint dst_width;
    uint dst_height;
    uint src_offset; // floats into the pyramid buffer (level 0: unused)
    uint dst_offset;
    uint level;      // 0: luma of the frame's colour; k > 0: 2x2 mean of level k - 1
    uint pad0;
};

struct MatchParams {
    uint width;  // the level's size in pixels
    uint height;
    uint blocks_x; // its block grid (MOTION_BLOCK pixels)
    uint blocks_y;
    uint src_offset;   // the level in the pyramid whose blocks are matched
    uint dst_offset;   // the level in the pyramid searched
    uint field_offset; // this level's blocks in the field buffer (vec4 each)
    uint coarse_offset;   // the coarser level's blocks (same direction)
    uint coarse_blocks_x; // 0: the coarsest level, no prediction
    uint coarse_blocks_y;
    int radius;   // integer search window around the best candidate
    float lambda; // cost per pixel of distance from the prediction (luma units)
    uint same_offset;     // MOTION_NONE, or this level's blocks of a first pass: propagation
    uint temporal_offset; // MOTION_NONE, or this level's blocks of the previous submit
    uint store; // MATCH_STORE_* bits: what the pass stores besides the integer vector and its cost
    float zero_bias; // cost added to the zero displacement (below the coarsest level; match.h)
    float light_cap; // x the block's mean: the most its change of brightness costs (match_cost; < 0: plain)
};
#define MATCH_STORE_CONTRAST 1u // the block's contrast (read by the fill stage, flow.h's check field)
#define MATCH_STORE_SUBPIXEL 2u // a sub-pixel vector (else integer: a first pass's, read rounded)
#define MATCH_STORE_SAD 4u      // the full block's SAD instead of the cost (level 0: the cut test)
#define MOTION_NONE 0xffffffffu

struct FlowParams {
    uint width;
    uint height;
    uint blocks_x; // the finest matched level's block grid (motion_first_level)
    uint blocks_y;
    uint back_offset; // its blocks of the current -> previous field
    uint fwd_offset;  // its blocks of the previous -> current field
    float global_x;   // dominant motion, pixels, current -> previous
    float global_y;
    float fb_tolerance; // forward-backward mismatch (pixels) beyond which a pixel is occluded
    float depth_scale;  // motion difference from the dominant one (pixels) that halves the proxy
    uint write_depth;   // 1: write the depth proxy (the session has no depth)
    uint block_shift;   // the finest matched level: blocks of MOTION_BLOCK << shift pixels, vectors x 2^shift
    // 1: the frame has the client's vectors (correction, Params::correct_vectors): each pixel keeps
    // its given vector unless the estimated one matches its colour by far better (flow.h).
    uint correct;
    float correct_ratio;  // the estimated vector's cost must be below ratio x the given one's ...
    float correct_margin; // ... minus this margin (luma units)
    float correct_depth;  // and the given vector's previous position has the pixel's depth (relative)
    // The coarse-to-fine refined field (polish.h, polish_coarse): a further candidate of each pixel,
    // read bilinearly from level coarse_level (0: none), the first level of the coarse buffer.
    uint coarse_level;
    uint coarse_width;
    uint coarse_height;
    float correct_front; // ... nor in front of it by more than this (relative): a disocclusion
};

// polish.h: one red-black half-sweep of the variational refinement of estimated vectors.
struct PolishParams {
    uint width;
    uint height;
    uint parity;      // the checkerboard colour updated: (x + y) & 1
    float alpha;      // weight of the smoothness term
    float eps_data;   // Charbonnier epsilon of the (gradient-normalised) data term
    float eps_smooth; // Charbonnier epsilon of the smoothness term, pixels
    float zeta;       // luma gradient added to the data term's normalisation
    float omega;      // over-relaxation of each update (successive over-relaxation; 1: Gauss-Seidel)
    uint luma_offset; // the level's luma in both pyramids (0: level 0)
    uint mv_offset;   // the field's first vector in the vectors buffer (0: the frame's own)
    // The polish_seed build (polish.h, polish_seed_pixel) writes the field of a coarse level from
    // the next coarser level's field (src_width > 0), else from the finest matched blocks.
    uint level;     // the level the field belongs to: pixels of 2^level frame pixels
    uint src_width; // the coarser level's field: its size and first vector (0: from the blocks)
    uint src_height;
    uint src_offset;
    uint blocks_x; // the finest matched level's block grid (flow's)
    uint blocks_y;
    uint block_offset; // its current -> previous blocks in the block field
    uint block_shift;  // blocks of MOTION_BLOCK << shift frame pixels, vectors x 2^shift
    // The polish_search and polish_densify builds (search.h): the level's patch grid.
    uint patches_x;
    uint patches_y;
    uint patch_stride; // pixels between the patches' origins
    uint search_steps; // Gauss-Newton steps of each patch
    // The patches' vectors in the patch buffer: those read (MOTION_NONE: start from the seeded
    // field; else each patch starts from the best of its own and its four neighbours' there) and
    // those written (search), or read (densify).
    uint patch_in;
    uint patch_out;
    float prop_reach; // pixels: a neighbour's vector is taken only this close to the patch's seed
};

// Pixels per invocation of the agree pass's box stages (agree.h stages 2 and 3): a segment of a row,
// then of a column.
#define AGREE_SEGMENT 32u
// agree.h: interpolation in sessions with vectors that also generate from colour-only motion
// (Params::colour_agree), one stage per dispatch (agree.comp, AGREE_STAGE).
struct AgreeParams {
    GenParams g;  // the generated frame's (both fields' blend decisions: t_depth)
    uint radius;  // the box's half side, pixels
    float ratio;  // the given field's disagreement is scaled by this ...
    float centre; // ... and exceeds the colour field's by this where the two frames mix evenly
    float softness;   // the logistic's scale (brightness units): agree.h, stage 3
    float depth_band; // one surface within depth_band x g.t_depth (the two warped frames; stage 4: frame 0 at
                      // t + mv and frame 1 at t)
    float colour_limit; // the colour frame's weight falls to 0 as its field's mean reaches this (0: off)
    float gain;         // stage 1 forgives a field's brightness gain between its two warped frames up to
                        // this factor, fitted over the box of side 2 gain_radius + 1 (<= 1: off)
    uint gain_radius;
    // The size of the frames stage 9 mixes (super resolution: the output's; the means are g's size),
    // 0 where stage 3 mixes at g's size.
    uint out_width;
    uint out_height;
};

// Internal frame colour as stored between passes: RGBA as four IEEE half floats, 8 bytes per pixel
// (uvec2: packHalf2x16(r, g), packHalf2x16(b, a)). Ingest clamps channels to [0, 65504], so packing
// never overflows; the half rounding (relative error <= 2^-11) is far below what the metrics see,
// and halves the colour traffic of warp's bilinear gathers. Passes compute in float.
// Each channel is first rounded to the nearest half (ties to even) in float arithmetic, so the
// packing itself is exact and its rounding mode (implementation-defined in GLSL) does not matter.
FGSR_INLINE float round_to_half(float x) {
    if (x < 6.103515625e-05f) return roundEven(x * 16777216.0f) / 16777216.0f; // subnormal: 2^-24 steps
    uint b = floatBitsToUint(x);
    return uintBitsToFloat((b + 0xfffu + ((b >> 13u) & 1u)) & ~0x1fffu); // 10 mantissa bits
}
FGSR_INLINE uvec2 pack_color(vec4 c) {
    return uvec2(packHalf2x16(vec2(round_to_half(c.x), round_to_half(c.y))),
                 packHalf2x16(vec2(round_to_half(c.z), round_to_half(c.w))));
}
FGSR_INLINE vec4 unpack_color(uvec2 p) { return vec4(unpackHalf2x16(p.x), unpackHalf2x16(p.y)); }

// Rec. 709 luminance of linear colour, unclamped (1 = display white; the dilate stage's over-white test).
FGSR_INLINE float linear_luminance(vec4 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
// Display-referred luma: the square root of linear luminance clamped to [0, 1] (about perceptually
// even steps). What motion estimation matches (luma.h) and the scene-cut test compares (cut.h).
FGSR_INLINE float motion_luma(vec4 c) { return sqrt(clamp(linear_luminance(c), 0.0f, 1.0f)); }

// The Catmull-Rom cubic's weights of the 4 taps around t in [0, 1) (bicubic with a = -0.5;
// resample.h, warp.h).
FGSR_INLINE vec4 catmull_rom_weights(float t) {
    float t2 = t * t;
    float t3 = t2 * t;
    return vec4(-0.5f * t3 + t2 - 0.5f * t, 1.5f * t3 - 2.5f * t2 + 1.0f, -1.5f * t3 + 2.0f * t2 + 0.5f * t,
                0.5f * t3 - 0.5f * t2);
}

FGSR_INLINE bool inside(ivec2 q, GenParams g) {
    return q.x >= 0 && q.y >= 0 && q.x < int(g.width) && q.y < int(g.height);
}

// A position in pixels (centres at +0.5) on the frame, its far edges included (warp.h, disocc.h,
// splat.h).
FGSR_INLINE bool on_screen(vec2 pos, GenParams g) {
    return pos.x >= 0.0f && pos.y >= 0.0f && pos.x <= float(g.width) && pos.y <= float(g.height);
}

FGSR_INLINE ivec2 clamp_pixel(ivec2 q, GenParams g) {
    return clamp(q, ivec2(0), ivec2(int(g.width) - 1, int(g.height) - 1));
}

// The pixel under a position (pixel units), clamped to the image: whose depth warp.h's samples
// report, and where blend.h's depth test reads frame 1's vectors. Far-off positions are kept
// finite before the conversion to integers.
FGSR_INLINE ivec2 sample_pixel(vec2 pos, GenParams g) {
    pos = clamp(pos, vec2(-1.0f), vec2(float(g.width) + 1.0f, float(g.height) + 1.0f));
    return clamp_pixel(ivec2(floor(pos)), g);
}

// Edge neighbour k (0..3: left, right, up, down) of a pixel, as an offset: the frame-0 lookup of
// motion.h and classify.h's mirror of it search these.
FGSR_INLINE ivec2 edge_neighbour_offset(int k) { return k < 2 ? ivec2(2 * k - 1, 0) : ivec2(0, 2 * k - 5); }

// The median of the values v[i] with ok[i] (n of them, n >= 1): the middle one, or the mean of
// the two middle ones for even n (motion.h's acceleration, match.h's fill). By rank, without
// sorting: no indexing by a variable, which on CPU devices puts an array in memory.
FGSR_INLINE float median9(float v[9], bool ok[9], int n) {
    int lo = (n - 1) / 2, hi = n / 2;
    float sum = 0.0f;
    for (int i = 0; i < 9; ++i) {
        int rank = 0;
        for (int j = 0; j < 9; ++j) rank += int(ok[j] && (v[j] < v[i] || (v[j] == v[i] && j < i)));
        if (ok[i] && (rank == lo || rank == hi)) sum += rank == lo && rank == hi ? 2.0f * v[i] : v[i];
    }
    return 0.5f * sum;
}

// |a - b| relative to the nearer of the two (depths are positive).
FGSR_INLINE float relative_depth_difference(float a, float b) { return abs(a - b) / max(min(a, b), 1.0e-20f); }

// The factor by which a surface patch was farther in the previous frame, if it faces the camera:
// 1 / sqrt(det J), J = I + grad(mv) the local map from current to previous positions, gx and gy
// the vectors' derivatives along x and y (J's columns: step + d(mv)); det J clamped to [1/4, 4].
// The sr pass's history test (sr.h step 2) and the motion's frame-0 depth test (motion.h) expect
// the depth change it implies.
FGSR_INLINE float expansion_depth_scale(vec2 gx, vec2 gy) {
    float det = (1.0f + gx.x) * (1.0f + gy.y) - gy.x * gx.y;
    return inversesqrt(clamp(det, 0.25f, 4.0f));
}

// a / b for quotients below 2^23, b >= 1. Integer division by a non-constant is not vectorised on
// CPU devices (lavapipe scalarises it: the tiled passes were measured 2-3x slower with it), float
// division is; the float quotient is within 1 of the true one, and one integer step corrects it.
FGSR_INLINE uint udiv(uint a, uint b) {
    uint q = uint(float(a) / float(b));
    if (q * b > a) return q - 1u;
    return a - q * b >= b ? q + 1u : q;
}

#ifdef __cplusplus
static_assert(sizeof(IngestParams) == 68 && sizeof(GenParams) == 52 && sizeof(SrParams) == 64,
              "push constants are 4-byte scalars");
static_assert(sizeof(ClassifyParams) == 84 && offsetof(ClassifyParams, tile) == 52,
              "classify push constants");
static_assert(sizeof(DenoiseParams) == 32, "denoise push constants");
static_assert(sizeof(LumaParams) == 32 && sizeof(MatchParams) == 68 && sizeof(FlowParams) == 80 &&
                  sizeof(PolishParams) == 100,
              "motion push constants");
static_assert(sizeof(AgreeParams) == 92, "agree push constants");
} // namespace fgsr::gpu
#endif
#endif
