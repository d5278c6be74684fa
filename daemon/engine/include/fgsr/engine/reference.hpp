// CPU reference of the engine: the same algorithm headers (shaders/*.h) compiled as C++ with GLM.
// Each function runs one pass on explicit inputs, so a test can feed it exactly what the GPU pass
// saw and compare outputs pass by pass. Tools use ingest() to reach the internal convention. The
// push constants the passes take, and the checks of frames, come from fgsr/engine/params.hpp.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/engine/params.hpp>

#include "common.h" // shaders/: GenParams, IngestParams

#include <glm/glm.hpp>

#include <algorithm>
#include <span>
#include <vector>

namespace fgsr::ref {

using gpu::AgreeParams;
using gpu::ClassifyParams;
using gpu::DenoiseParams;
using gpu::FlowParams;
using gpu::GenParams;
using gpu::IngestParams;
using gpu::LumaParams;
using gpu::MatchParams;
using gpu::PolishParams;
using gpu::SrParams;

// One frame in the engine's internal convention (see types.hpp).
struct InternalFrame {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<glm::vec4> color; // linear RGBA, values representable as half (pack_color)
    std::vector<float> depth;     // linear view depth, larger is farther
    std::vector<glm::vec2> mv;    // pixels, y down, to previous; all zero when !has_mv
    bool has_mv = false;
};

// States of a reconstructed field pixel (the FIELD_* values of shaders/field.h).
enum FieldState : uint32_t { kFieldSplatted = 0, kFieldGapFilled = 1, kFieldHole = 2, kFieldHoleFilled = 3 };

// Output of splat: per target pixel the 64-bit key (depth bits << 32 | source index, all ones
// when empty), per frame-1 pixel its motion (m1, m0) as splat's motion model chose it
// (shaders/motion.h source_velocities; m0 = m1 for uniform velocity), the same for every alpha of
// the pair.
struct Splat {
    std::vector<uint64_t> keys;
    std::vector<glm::vec4> motion;
};

// Reconstructed motion field of one generated frame (see shaders/field.h).
struct Field {
    std::vector<glm::vec4> v;    // (v0.xy, v1.xy) per target pixel
    std::vector<float> depth;    // frame-1 depth of the surface, FGSR_FAR_DEPTH if unknown
    std::vector<uint32_t> state; // FIELD_* values
};

// Warped frames: index frame * N + pixel, frame 0 then frame 1; negative depth = off screen.
struct Warped {
    std::vector<glm::vec4> color;
    std::vector<float> depth;
};

// Converts a validated frame to the internal convention (the `ingest` pass on the CPU).
// mv_offset: IngestParams::mv_offset (the camera-jitter removal of Params::mvs_contain_jitter,
// jitter(previous) - jitter(current), pixels); zero when the vectors contain no jitter.
InternalFrame ingest(const FrameFormat& format, const FrameView& frame, glm::vec2 mv_offset = glm::vec2(0.f));

// Ingest's dilate stage on an ingested frame (shaders/dilate.h): with p.edge_ratio > 0 and a
// previous frame (its ingested colour), the edge rule; then with p.bright > 0, the over-white rule
// (params::set_dilate). Both read f as it was before the stage.
void dilate(InternalFrame& f, const InternalFrame* prev, const IngestParams& p);

// The `denoise` pass's noise estimate of one ingested frame (stages histogram and level).
NoiseEstimate noise_level(const InternalFrame& f, const DenoiseParams& p);

// The `denoise` filter of one ingested frame with the given range (stage filter); colours as the
// engine stores them (rounded to half).
std::vector<glm::vec4> denoise(const InternalFrame& f, const DenoiseParams& p, float range);

// One frame of super resolution on the CPU: `cur` the new LR frame, `prev_depth` the previous LR
// depth, `history` the previous output (out_width x out_height), `lut` for Resample::lut.
std::vector<glm::vec4> super_resolve(const InternalFrame& cur, const std::vector<float>& prev_depth,
                                     const std::vector<glm::vec4>& history, const SrParams& p,
                                     std::span<const float> lut);

// The joint pass: interpolation (ISR) or extrapolation (ESR) at output resolution from the
// motion field of `splat`; `src` is the previous SR output (ISR) or the newest one (ESR).
std::vector<glm::vec4> generate_sr(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat,
                                   const std::vector<glm::vec4>& src, const GenParams& g, const SrParams& s,
                                   std::span<const float> lut);

// Passes of frame generation; f0 is the older frame, f1 the newer one.
Splat splat(const InternalFrame& f0, const InternalFrame& f1, const GenParams& g);
// The field vectors (v0, v1) of frame-1 pixel `source` at g.alpha (shaders/motion.h,
// source_field_vectors): displacements from its position at the generated time to its positions in
// frame 0 and frame 1, as the passes after splat recompute them from `splat`'s motion.
glm::vec4 source_field_vectors(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat,
                               uint32_t source, const GenParams& g);
Field refine(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat, const GenParams& g);
void disocc(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat, Field& field,
            const GenParams& g);
Warped warp(const InternalFrame& f0, const InternalFrame& f1, const Field& field, const GenParams& g);
// Frame 1's vectors and depth: GenParams::blend_mode's BLEND_DEPTH_MOTION (shaders/blend.h).
std::vector<glm::vec4> blend(const InternalFrame& f0, const InternalFrame& f1, const Warped& warped,
                             const Field& field, const GenParams& g);
// The agree pass (Params::colour_agree, shaders/agree.h): the given field's warped frames (frame 0
// then frame 1, as warp writes them), field (its vectors and states; the depth is not read) and
// blended frame, the colour-only field's warped frames, states and blended frame; the frame the
// pass writes.
std::vector<glm::vec4> agree(const Warped& given_warped, const Field& given_field,
                             const std::vector<glm::vec4>& given, const Warped& colour_warped,
                             const std::vector<uint32_t>& colour_state, const std::vector<glm::vec4>& colour,
                             const AgreeParams& p);
// Its extrapolation (stage 4, agree_residual, then the same box and mix): the inputs (f1's vectors
// the given field's), the colour-only field's frame-1 vectors, both extrapolated frames. With
// p.out_width set (super resolution), both frames are p.out_width x p.out_height and so is the
// result (stages 8 and 9).
std::vector<glm::vec4> agree_extrapolated(const InternalFrame& f0, const InternalFrame& f1,
                                          const std::vector<glm::vec2>& colour_mv,
                                          const std::vector<glm::vec4>& given,
                                          const std::vector<glm::vec4>& colour, const AgreeParams& p);

// The fused pass (refine, disocc, warp and blend per pixel) on given splat keys.
std::vector<glm::vec4> generate_fused(const InternalFrame& f0, const InternalFrame& f1, const Splat& splat,
                                      const GenParams& g);

// The whole chain of separate passes: interpolated (blend output) or extrapolated (warped frame 1).
std::vector<glm::vec4> generate(const InternalFrame& f0, const InternalFrame& f1, const GenParams& g);

// Pass `classify` (shaders/classify.h): TILE_STATIC or TILE_MOVING per tile of c.tile pixels,
// row-major. Generate mode: f0, f1 the frames of the generated frame. SR mode: f1 the current
// frame, f0 the previous one (only its depth is read).
std::vector<uint32_t> classify(const InternalFrame& f0, const InternalFrame& f1, const ClassifyParams& c);
// The copy-through value generate mode gives a pixel of a static tile that splat left alone.
glm::vec4 copy_through(const InternalFrame& f0, const InternalFrame& f1, glm::ivec2 p, const GenParams& g);

// ---- Motion estimation from colour (shaders/luma.h, match.h, flow.h; docs/MOTION.md) ----
// The engine uses these same functions for its level layout, push constants and field summary.

inline constexpr int kMotionRadiusCoarsest = 4; // integer search of the coarsest level (+-4 of its pixels)
inline constexpr int kMotionRadiusMiddle = 2;   // around the best candidate, levels between
inline constexpr int kMotionRadiusFine = 1;     // around the best candidate, level 0
// Cost per pixel away from the coarse prediction; on the coarsest level, which has none, away from
// zero (it settles the near-ties of flat regions, which would otherwise drift to the window's edge).
// None on level 0: there the pull toward the parent's vector costs more than it settles (a zoom's
// field changes within a parent block; the fill and median stages settle flat regions instead).
// Chosen on the development captures only (docs/MOTION.md).
inline constexpr float kMotionLambda = 0.002f;
inline constexpr float kMotionLambdaFine = 0.0f;
inline constexpr float kMotionLambdaCoarsest = 0.004f;
// Below the coarsest level (both passes) the zero displacement costs this much more than its
// match: it must explain the block clearly better than the candidates taken from the coarser
// level, the neighbours and the previous submit. As the first candidate it would otherwise win
// every tie, and a tie with zero is what a periodic texture (a checker floor, a brick wall,
// stripes) gives when the motion is near a multiple of its period, and what low contrast gives
// under any motion; the finest level, which has no regulariser, then drifts to zero against the
// coarse motion. Chosen on the train captures (docs/MOTION.md, "The zero displacement's bias").
inline constexpr float kMotionZeroBias = 0.005f;
// The most a block's change of mean brightness between the frames adds to its match cost, relative
// to the block's mean (match.h match_cost: the cost with the means removed, plus this times the
// block's mean luma, where that is lower than the plain cost). Light and shadow that change over a
// surface, or a surface nearing a lamp, change the brightness of dark, low-contrast content by more
// than its texture; the plain cost then follows the brightness instead of the texture. A change of
// light scales linear luminance, so it moves this luma in proportion to it: the cap is relative.
// Not on jittered frames (kMotionNoLightCap): their blocks' aliasing changes every frame, and the
// block's mean is the part of it that holds. Chosen on the train captures (docs/MOTION.md, "Local
// changes of brightness").
inline constexpr float kMotionLightCap = 0.04f;
inline constexpr float kMotionNoLightCap = -1.f; // the plain cost only
inline constexpr float kMotionFbTolerance = 2.0f; // forward-backward mismatch (pixels) of occlusion
inline constexpr float kMotionDepthScale = 4.0f;  // motion difference (pixels) at half the proxy's range
inline constexpr float kMotionModeRadius = 1.0f;  // vectors this close vote for the same dominant motion
// Scene cut: a block "finds no match" when its best SAD (mean absolute luma difference,
// display-referred [0, 1]) exceeds both kCutSad and kCutContrast times the block's own contrast
// (its mean absolute deviation), so that a textured block is judged against its texture and a
// flat one against an absolute step. A frame is a cut when the share of such blocks jumps: above
// kCutShare and kCutJump times the session's typical share (a running mean over its frames,
// update_typical_share), or, with no history yet, above kCutShareAlone. Content that never matches
// well (aliased point-sampled frames, noise) has a high typical share and is not cut every frame.
inline constexpr float kCutSad = 0.04f;
inline constexpr float kCutContrast = 0.6f;
inline constexpr float kCutShare = 0.22f; // real content measured at most 0.09-0.15 (docs/MOTION.md)
inline constexpr float kCutJump = 3.0f;
inline constexpr float kCutShareAlone = 0.5f;

// One pyramid level: size, block grid, where its pixels start in a pyramid buffer (floats) and
// its blocks in the field (vec4s). The field buffer holds five regions of motion_field_blocks
// vec4s: the final current -> previous levels, the final previous -> current levels, the first
// (pre-propagation) pass of each of the two, and the previous submit's final current -> previous
// levels (the temporal candidates).
struct MotionLevel {
    uint32_t width = 0, height = 0, blocks_x = 0, blocks_y = 0, offset = 0, field_offset = 0;
};
std::vector<MotionLevel> motion_levels(uint32_t width, uint32_t height);
uint32_t motion_field_blocks(const std::vector<MotionLevel>& levels); // blocks of one direction
// The finest level block matching reaches: 0, or 1 for frames above kMotionHalfResPixels, whose
// blocks then cover 16x16 pixels of the frame (as DIS's MEDIUM preset stops at half resolution);
// the flow pass still chooses per pixel at full resolution. Measured in docs/MOTION.md.
inline constexpr uint32_t kMotionHalfResPixels = 1280 * 720 - 1;
size_t motion_first_level(const std::vector<MotionLevel>& levels);
// The field buffer's regions, each motion_field_blocks vec4: 0, 1 the final current -> previous and
// previous -> current blocks; 2, 3 the first passes' (then the fill stage's); 4 the previous
// submit's current -> previous (temporal candidates); 5 and 6 the cut statistics of the finest
// level's blocks (kCutRegion: two vec4 per block, ref::CutBlock, at twice the level's offset).
inline constexpr uint32_t kFieldRegions = 7;
inline constexpr uint32_t kCutRegion = 5;
// Push constants of level k's first pass (propagate false) or propagation pass (forward:
// previous -> current; temporal: the temporal region holds the previous submit's field; light: the
// light cap, kMotionLightCap, else kMotionNoLightCap), and of the flow pass.
MatchParams match_params(const std::vector<MotionLevel>& levels, size_t k, bool forward, bool propagate,
                         bool temporal, bool light = true);
// correct: the flow pass corrects the frame's given vectors (Params::correct_vectors, with its
// ratio and margin) instead of writing estimated ones.
struct VectorCorrection {
    bool on = false;
    float ratio = 0.f;
    float margin = 0.f;
    float depth = 0.f; // relative depth difference within which a surface counts as the same (T_D)
    float front = 0.f; // ... and within which the previous position may lie in front of the pixel
};
// coarse: flow reads the coarse-to-fine field's level 1 (polish_coarse) as a candidate.
FlowParams flow_params(const std::vector<MotionLevel>& levels, glm::vec2 global, bool write_depth,
                       VectorCorrection correct = {}, bool coarse = false);
// The fill stage of the first level (match.h fill_block): final blocks in, first-pass region out.
MatchParams fill_params(const std::vector<MotionLevel>& levels, bool forward);
// The cut statistics of the first level's blocks (match.comp's FGSR_MATCH_CUT, shaders/cut.h):
// its current -> previous blocks in, CutBlocks out at same_offset.
MatchParams cut_match_params(const std::vector<MotionLevel>& levels);
// Variational refinement of estimated vectors (shaders/polish.h; not when correcting given ones):
// kPolishIterations red-black sweeps (two dispatches each). Chosen on the train captures only
// (docs/MOTION.md, "Variational refinement").
// 5 before the coarse levels came (below); with them 3 score as well on train (PSNR within 0.02 dB,
// up on 5 of 8) at 40 % less of this pass's time.
inline constexpr uint32_t kPolishIterations = 3;
inline constexpr float kPolishAlpha = 0.5f;
inline constexpr float kPolishEpsData = 0.01f;
inline constexpr float kPolishEpsSmooth = 0.05f;
inline constexpr float kPolishZeta = 0.01f;
// Over-relaxation: 5 sweeps then gain about what 10 of plain Gauss-Seidel do.
inline constexpr float kPolishOmega = 1.5f;
// Frames above this many pixels are not refined: at 1280x720 the sweeps added 59-86 ms to 75 ms of
// the other motion passes, against 45-58 ms of ingest and interpolation (fgsr bench, two runs),
// which breaks issue 12's limit (motion at most 2x the rest); there they gained 0.02 dB.
inline constexpr uint32_t kPolishMaxPixels = 960 * 540;
inline bool polishes(uint32_t width, uint32_t height) {
    return uint64_t(width) * height <= kPolishMaxPixels;
}
PolishParams polish_params(uint32_t width, uint32_t height, uint32_t parity);
// Coarse to fine (polish.h, polish_coarse): before flow, kPolishCoarseIterations sweeps on each
// level from kPolishCoarseTop (or the pyramid's last, if lower) down to level 1, each seeded from
// the level above (the top one from the finest matched blocks); flow reads level 1's field as a
// candidate. Chosen on the train captures only (docs/MOTION.md, "Coarse to fine").
// Level 3: a block of level 0 is one pixel there. From level 4: interpolation up on train on average
// (+0.10 dB: pan s2 +0.63, builtin +0.19) but down on 8 of its 13 rows with extrapolation (bunker LR
// -0.07, hdr-fg extrap -0.08), as on validation (8 of 12; spin -0.42, pan +0.66). 20 sweeps instead
// of 10: hdr-fg +0.21 dB, builtin +0.06, the others level or -0.04 to -0.07; 5 on level 1 alone lost
// hdr-fg 0.15.
inline constexpr uint32_t kPolishCoarseTop = 3;
inline constexpr uint32_t kPolishCoarseIterations = 10;
// Patch inverse search and densification (shaders/search.h, Params::motion_search): on each coarse
// level from the top down to kSearchFinest (if searched), between its seed and its sweeps, patches
// of SEARCH_PATCH pixels kSearchStride apart, kSearchSteps Gauss-Newton steps each.
// After the first round (from the seeded field), kSearchRounds rounds of propagation: each patch
// starts from the best of its own and its four neighbours' vectors of the round before.
inline constexpr uint32_t kSearchStride = 4;
inline constexpr uint32_t kSearchSteps = 6;
inline constexpr uint32_t kSearchRounds = 2;
// A propagation round takes a neighbour's vector only within this many pixels of the level from
// the patch's seed: further, on periodic texture (checker walls), it takes a period-off vector
// that happens to cost less, and a wrong region that far off is the coarser levels' to mend.
inline constexpr float kSearchReach = 4.f;
inline constexpr uint32_t kSearchFinest = 1;
// Levels whose smaller side is below this many pixels are not searched: there a patch spans too
// much of the frame (at 480x270, level 3's 60x34 pixels).
inline constexpr uint32_t kSearchMinSide = 64;
// Patches along a side of `side` pixels, `stride` apart (the last one ends at the edge).
uint32_t search_patches(uint32_t side, uint32_t stride = kSearchStride);
// The patch regions round `round` reads and writes (p.patch_in, p.patch_out), for p.patches_x x
// p.patches_y patches: the rounds ping-pong between two regions; round 0 reads none.
void search_round_regions(PolishParams& p, uint32_t round);
// Round `round` (0 .. kSearchRounds) of the search on coarse level `level`; the densification's
// are the last round's (it reads what that one wrote).
PolishParams search_params(const std::vector<MotionLevel>& levels, uint32_t level, uint32_t round);
// Whether level `level` of the coarse field is searched, and the patches of the largest one.
bool searches_level(const std::vector<MotionLevel>& levels, uint32_t level);
uint32_t search_patch_capacity(const std::vector<MotionLevel>& levels);
// The top coarse level of a pyramid (0: none, the pyramid has one level).
uint32_t polish_coarse_top(const std::vector<MotionLevel>& levels);
// The coarse fields' buffer: levels 1..top in the pyramid's layout less level 0 (vec2 each).
uint32_t polish_coarse_vectors(const std::vector<MotionLevel>& levels);
// A sweep over level `level` (>= 1) of the coarse fields; its seed (seed true: parity unused).
PolishParams polish_coarse_params(const std::vector<MotionLevel>& levels, uint32_t level, uint32_t parity,
                                  bool seed);

// A block that finds no match: SAD above kCutSad and above kCutContrast times its contrast.
inline bool block_unmatched(float sad, float contrast) { return sad > kCutSad && sad > kCutContrast * contrast; }
// Scene cuts relit (shaders/cut.h): ingest's cut stage in sessions with vectors, match's cut build
// on the matched blocks in sessions that estimate motion. The number of 8x8 blocks of a frame; the
// stage on the CPU, one CutBlock per block of `f` (ingested, its vectors after the dilate stage)
// against the previous frame's colour.
struct CutBlock {
    glm::vec4 sad;   // SAD, the block's contrast, the SAD with the block's mean difference taken out
    glm::vec4 level; // the block's mean luma, the mean of the previous frame's at the vectors' positions
};
static_assert(sizeof(CutBlock) == 32, "two vec4 per block in cut.comp's buffer");
glm::uvec2 cut_grid(uint32_t width, uint32_t height); // blocks across, down
uint32_t cut_blocks(uint32_t width, uint32_t height);
std::vector<CutBlock> cut_stage(const InternalFrame& f, const InternalFrame& prev);
// A change of the whole frame's lighting (a fade, a flash, an exposure step) leaves the vectors
// right and the luma wrong everywhere by the same law. The blocks' means fitted as
// mean = gain x mean_prev + offset (least squares over the blocks, the gain clamped to
// [kCutLightGainMin, kCutLightGainMax] of display luma, a factor of 1/4 to 4 in linear light): a cut
// puts unrelated content at each place, whose means the fit does not predict (its gain falls
// towards zero and is clamped), while a change of lighting moves them together.
inline constexpr float kCutLightGainMin = 0.5f;
inline constexpr float kCutLightGainMax = 2.0f;
struct LightingFit {
    float gain = 1.f, offset = 0.f;
};
LightingFit fit_lighting(std::span<const CutBlock> blocks);
// A block that finds no match relit: its SAD without its mean difference plus what the fit leaves
// of that difference.
inline bool relit_unmatched(const CutBlock& b, const LightingFit& fit) {
    const float bias = b.level.x - fit.gain * b.level.y - fit.offset;
    return block_unmatched(b.sad.z + (bias < 0.f ? -bias : bias), b.sad.y);
}
// The share of blocks that find no match (block_unmatched), both as the colour was given and
// relit: with the SAD without the block's mean difference plus what the fitted lighting leaves of
// that difference. Where the lighting does not change, the fit is near (1, 0) and the relit SAD is
// at least the given one, so the share is that of the given colour.
float cut_share(std::span<const CutBlock> blocks);

// What the host reads from the level-0 current -> previous blocks between the match and flow
// passes: the dominant motion (mean of the vectors within kMotionModeRadius of the most common
// one) and whether the frame is a scene cut.
struct MotionSummary {
    glm::vec2 global{0.f};
    float mismatch_share = 0; // level-0 blocks that found no match (kCutSad, kCutContrast), relit too
    float matched_share = 0;  // ... as matched alone (before 2026-12-05 the cut rule's share)
    bool cut = false;
};
// typical_share: the session's running mean share (negative: no history yet). relit: the blocks'
// cut statistics (kCutRegion; none: the SAD as matched alone): a block counts where it finds no
// match both as matched and relit (relit_unmatched), so that a change of the whole frame's
// lighting is no cut (cut_share).
MotionSummary summarise_motion(std::span<const glm::vec4> blocks, float typical_share = -1.f,
                               std::span<const CutBlock> relit = {});
// The same over the final current -> previous blocks of motion_first_level in `field` (the whole
// field buffer), with the dominant motion in pixels of the frame; relit: with the cut statistics
// of kCutRegion. The estimator computes those only for a frame that is a cut as matched (a stage
// of its own, after the host's first summary), so that other frames pay nothing for them.
MotionSummary summarise_motion(const std::vector<MotionLevel>& levels, const glm::vec4* field,
                               float typical_share = -1.f, bool relit = false);
// The running mean after a frame: updated by frames that were not cuts; a cut re-seeds it with its
// own share (the new scene's baseline: content that never matches well is cut once and then
// judged against itself, not cut at every frame). It outlives restarts.
inline float update_typical_share(float typical, float share, bool cut) {
    if (typical < 0.f || cut) return share;
    return 0.7f * typical + 0.3f * share;
}
// The cut rule on a frame's share of unmatched blocks (kCutShare, kCutJump, kCutShareAlone).
inline bool is_cut(float share, float typical_share) {
    return typical_share < 0.f ? share > kCutShareAlone : share > std::max(kCutShare, kCutJump * typical_share);
}
// Sessions with vectors (ingest's cut stage): a frame is a cut where the share of its blocks that
// its own vectors leave without a match is above kCutShareVectors and kCutJump times the session's
// typical share; the session's first comparison only sets the typical share. The given vectors
// are not a search: a patch they do not describe (an effect drawn without vectors, shading that
// moves, wrong vectors) leaves its blocks unmatched without any cut, so the share must be most of
// the frame (measured: at most 0.28 without a cut on the captures, 0.75-0.79 at their cuts).
inline constexpr float kCutShareVectors = 0.5f;
inline bool is_vector_cut(float share, float typical_share) {
    return typical_share >= 0.f && share > std::max(kCutShareVectors, kCutJump * typical_share);
}

// The passes on the CPU: the pyramid of a frame; one level of matching into `field` (both
// directions share it, as on the GPU); the flow pass writing f.mv (and f.depth with write_depth).
std::vector<float> luma_pyramid(const InternalFrame& f, const std::vector<MotionLevel>& levels);
// The lighting gain of a pair (shaders/luma.h, the GPU's histogram): the factor that scales the
// previous frame's pyramid, 1 for none.
float luma_gain_of(const std::vector<float>& cur, const std::vector<float>& prev,
                   const std::vector<MotionLevel>& levels);
void match_level(const std::vector<float>& src, const std::vector<float>& dst, std::vector<glm::vec4>& field,
                 const MatchParams& p);
void fill_level(std::vector<glm::vec4>& field, const MatchParams& p);
// prev_frame: the previous frame, whose depth the correction of given vectors reads (p.correct).
// coarse: the coarse fields (read where p.coarse_level > 0).
void flow(const std::vector<float>& cur, const std::vector<float>& prev, const std::vector<glm::vec4>& field,
          const FlowParams& p, InternalFrame& f, const InternalFrame* prev_frame = nullptr,
          const std::vector<glm::vec2>* coarse = nullptr);
// The consensus of unambiguous blocks on one level above the finest (match.h ambiguity_block, then
// consensus_block); p: the level's propagation pass (match_params), whose first-pass region the
// stages use for the blocks' copy.
void consensus_level(const std::vector<float>& src, const std::vector<float>& dst,
                     std::vector<glm::vec4>& field, const MatchParams& p);
// Block matching of a pair's pyramids, coarse to fine, both directions, each level's propagation
// (and with `consensus` its consensus stages), as the engine's match pass runs it. `field`: the
// previous pair's (its current -> previous levels become the temporal candidates), or empty for a
// first pair; it is resized to kFieldRegions regions. light: as match_params.
void match_pyramids(const std::vector<float>& cur, const std::vector<float>& prev,
                    const std::vector<MotionLevel>& levels, std::vector<glm::vec4>& field, bool consensus,
                    bool light = true);
// The refinement's sweeps (both colours, kPolishIterations times) over f.mv (whatever its size:
// estimate_motion applies polishes()).
void polish(const std::vector<float>& cur, const std::vector<float>& prev, InternalFrame& f);
// The coarse levels' fields (polish_coarse_vectors of them), refined from the field's blocks.
// search: each level's patch inverse search and densification before its sweeps (search_params);
// sweep false: no sweeps (the engine's above kPolishMaxPixels).
std::vector<glm::vec2> polish_coarse(const std::vector<float>& cur, const std::vector<float>& prev,
                                     const std::vector<glm::vec4>& field,
                                     const std::vector<MotionLevel>& levels, bool search = false,
                                     bool sweep = true);
// The whole estimation of f1's vectors against f0 (the engine's chain); returns the summary. On a
// cut f1 keeps its input (has_mv false). `field`: the field buffer carried from the previous call
// (the engine's temporal candidates), or empty for a first frame; it is resized and updated. With
// correct.on, f1's given vectors are corrected instead (a cut leaves them as they are). fast: no
// refinement at any size (Params::fast_motion).
// typical_share: the session's (summarise_motion; negative: none yet). consensus: the consensus of
// unambiguous blocks on the levels above the finest (Params::motion_consensus, consensus_level);
// never while correcting (as the engine). light: block costs with the light cap (kMotionLightCap;
// the engine's on unjittered frames), else plain (kMotionNoLightCap). search: the coarse levels'
// patch inverse search (Params::motion_search; with it the coarse levels are refined at any size).
MotionSummary estimate_motion(const InternalFrame& f0, InternalFrame& f1, bool write_depth,
                              std::vector<glm::vec4>& field, VectorCorrection correct = {}, bool fast = false,
                              float typical_share = -1.f, bool consensus = true, bool light = true,
                              bool search = false);
inline MotionSummary estimate_motion(const InternalFrame& f0, InternalFrame& f1, bool write_depth) {
    std::vector<glm::vec4> field;
    return estimate_motion(f0, f1, write_depth, field);
}

// Resamples `src` (w x h) at every pixel centre + shift (pixels, x right, y down), with the
// engine's resampling (shaders/resample.h): out(x, y) = resample(src, (x + 0.5, y + 0.5) + shift).
// `lut` (kLutSize weights) is read only for Resample::lut.
std::vector<glm::vec4> resample_image(const std::vector<glm::vec4>& src, uint32_t w, uint32_t h,
                                      glm::vec2 shift, Resample kind, std::span<const float> lut = {});

// One resampled value of `src` (w x h) at `pos` (pixels, centres at +0.5); for spatial upscaling.
glm::vec4 resample_at(const std::vector<glm::vec4>& src, uint32_t w, uint32_t h, glm::vec2 pos, Resample kind,
                      std::span<const float> lut = {});

} // namespace fgsr::ref
