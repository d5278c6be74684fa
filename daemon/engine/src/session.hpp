// A session's state (Session::Impl) and the split of its work over files: session.cpp creates it
// (buffers), submits frames (ingest) and answers the accessors; generate.cpp records and assembles
// generated frames; sr.cpp the super-resolution history and LUT; denoise.cpp the denoise pass;
// tiles.cpp tile classification, the tile lists and the skip bookkeeping. Command recording is
// the Recorder's (recorder.hpp).
#pragma once

#include <fgsr/engine/color.hpp>
#include <fgsr/engine/defaults.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include "context.hpp"
#include "recorder.hpp"
#include "variants.hpp"
#include "vk.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <vector>

namespace fgsr {

constexpr uint32_t kMaxAlphas = 64;
constexpr uint32_t kQueriesPerFrame = 8; // start + up to 5 passes, rounded up
constexpr uint32_t kSetsPerFrame = 10;   // descriptor sets of one generated frame (at most 5), doubled

// Classification pays only where tiles can be skipped (on lavapipe at 720p, a fully moving
// session's classified call and the plain call after it cost 0.85-1.37x two plain calls,
// docs/TILES.md): after a classification that
// found less than kMinSkipShare of the tiles skippable (generated frames on CPU devices:
// kMinSkipShareCpu), the next calls (generate) or submits (sr) run every tile without classifying,
// then classify again. The first such run is kUnclassifiedRun long; each further miss in a row
// doubles it (7, 15, 31, then kUnclassifiedRunMax: about a second of calls at 60 a second), so a
// scene that keeps moving pays a classified call once in 64 instead of once in 8. A classification
// that finds the tiles worth skipping starts again at kUnclassifiedRun. Same frames either way.
constexpr double kMinSkipShare = 0.25;
// Generated frames on CPU devices, where classify costs about a fifth of a plain frame and a
// moving tile about 1.35x as much tiled as plain (the split form of generate over the listed
// tiles): skipping pays from about 45 % of the tiles skippable on lavapipe at 720p
// (`fgsr_tiles_bench`, band scenes: on / off 0.61-0.64 with 74 % skippable, 0.82-0.94 with 49 %,
// a loss with 24 %; docs/TILES.md).
constexpr double kMinSkipShareCpu = 0.45;
constexpr uint32_t kUnclassifiedRun = 7;
constexpr uint32_t kUnclassifiedRunMax = 63;

// When to classify, per kind of pass (the rule above).
class ClassifyBackoff {
  public:
    // Whether this call classifies; counts the call against the run left otherwise.
    bool due() {
        if (left_ == 0) return true;
        --left_;
        return false;
    }
    // After a classified call: whether it found enough of the tiles skippable.
    void classified(bool worth_it) {
        if (worth_it) {
            run_ = kUnclassifiedRun;
            return;
        }
        left_ = run_;
        run_ = std::min(2 * run_ + 1, kUnclassifiedRunMax);
    }
    // The last classification found too little to skip (a hit resets the run, a miss lengthens it).
    bool missed() const { return run_ != kUnclassifiedRun; }

  private:
    uint32_t left_ = 0;               // calls left to run unclassified
    uint32_t run_ = kUnclassifiedRun; // the run after the next miss
};

// A timing record of a pass, named.
inline PassTiming timing_of(PassId pass, PassTiming t = {}) {
    t.name = std::string(pass_name(pass));
    t.pass = pass;
    return t;
}

struct Session::Impl {
    Engine::Impl* engine = nullptr;
    vk::Context* ctx = nullptr;
    FrameFormat format;
    Params params;
    size_t n = 0;
    Recorder rec;

    // Frames (session.cpp): client planes are copied here, then ingested.
    vk::Buffer color_raw, depth_raw, mv_raw;
    vk::Buffer bright;         // ingest's over-white flags per 16x16 tile (shaders/dilate.h)
    bool bright_clear = false; // cleared once; then the dilate stage clears what it reads
    // Scene cuts in sessions with vectors (ingest's cut stage, shaders/cut.h; Params::vector_cuts):
    // host-visible vec2(SAD, contrast) per 8x8 block; the running share of unmatched blocks since
    // the last restart (negative: no history yet), as Motion::typical_share for colour-only ones.
    vk::Buffer cut_blocks;
    float cut_typical_share = -1.f;
    float last_cut_share = -1.f;
    // Session::last_scene_cut: the last submit restarted at a cut it found (block matching's in
    // colour-only sessions, the cut stage's in sessions with vectors, corrected or not).
    bool last_scene_cut = false;
    float last_lighting_gain = -1.f; // Session::last_lighting_gain
    struct GpuFrame {
        vk::Buffer color, depth, mv;
        bool has_mv = false;
    };
    std::array<GpuFrame, 2> frames;
    int newest = 1; // index into frames of frame 1
    uint64_t submitted = 0;
    // Session::reset() was called: the next frame submitted starts afresh as with FrameView::reset.
    bool reset_pending = false;
    PassTiming ingest_timing = timing_of(PassId::ingest);
    float jitter_x = 0, jitter_y = 0; // of the newest frame

    // Super resolution (sr.cpp): the output size (the frame size without super resolution) and
    // the history.
    uint32_t out_w = 0, out_h = 0;
    struct SrHistory {
        std::array<vk::Buffer, 2> hr; // ping-pong outputs: the newest is hr[newest]
        int newest = 0;
        bool valid = false;                        // an output exists (no reset since)
        vk::Buffer lut;                            // kLutSize weights (Resample::lut)
        vk::Buffer noise;                          // vec2 per input pixel: sr.h's (r, q), variant sr_noise
        PassTiming timing = timing_of(PassId::sr); // of the last submit
    } sr_history;

    // The input's aliasing measure (fgsr/engine/color.hpp) over its first defaults::aliasing_frames
    // frames; jittered once any frame had jitter. They decide WarpKernel::automatic
    // (params::gen_params), Params::sr_disagree and the spatial upsample's kernel (params::sr_params).
    AliasingSums input_aliasing;
    bool input_jittered = false;
    params::InputMeasure input_measure() const {
        return params::InputMeasure{aliasing_ratio(input_aliasing), input_jittered};
    }

    // Params::denoise (denoise.cpp, shaders/denoise.h).
    struct Denoiser {
        vk::Buffer scratch; // the filter's output, copied back into the frame's colour
        vk::Buffer noise;   // host-visible: histogram, estimate, indirect dispatch (DENOISE_WORDS)
        PassTiming timing = timing_of(PassId::denoise);
        NoiseEstimate estimate; // of the last submit
    } denoiser;

    // Intermediates of one generated frame (generate.cpp), reused by each alpha in turn; keys
    // hold splat_slices slices of splat_stride elements (one per alpha of a splat dispatch,
    // FGSR_SPLAT_ALPHAS at most; one until a call asks for more frames). motion: the motion (m1, m0)
    // splat chose per frame-1 pixel (vec4; shaders/splat.h), one for all alphas.
    vk::Buffer keys, motion, field, field_depth, field_state, warped_color0, warped_depth0, warped_color1,
        warped_depth1;
    uint32_t splat_stride = 0, splat_slices = 0;
    // The empty pixels of a generated frame that generate's split form (CPU devices, shaders
    // generate.comp FGSR_GENERATE_SPLIT) finishes in its second pass: a tile list's header, then
    // one entry per pixel (created on first use).
    vk::Buffer gap_list;
    // Creates gap_list on first use and records the reset of its header (side: the tile side the
    // tiled split form's key reads take from it; 0 for the plain one), then a barrier.
    Result<void> reset_gap_list(uint32_t side);
    uint32_t last_slice = 0;         // slice of the keys of the last generated frame
    std::vector<vk::Buffer> outputs; // host-visible, one per alpha of a call
    bool last_extrapolate = false;
    bool last_separate = false;
    size_t last_output = 0;
    // The call runs separate passes whatever Params::separate_passes says (an agreeing call's
    // given field: the agree pass reads its warped frames).
    bool force_separate = false;
    bool separate() const { return params.separate_passes || force_separate; }

    // Params::colour_agree (generate.cpp, shaders/agree.h): a colour-only session fed the same
    // frames without vectors or depth, which generates with separate passes; the agree pass's
    // disagreement and its row means (vec2 per pixel), created on first use; the warped frames'
    // brightness and its row sums (vec4 per pixel, AgreeParams::gain), at the first interpolation.
    std::unique_ptr<Session> colour_twin;
    vk::Buffer agree_e, agree_rows, agree_light, agree_light_rows;
    bool last_agreed = false; // the last generated frame is the agree pass's (read_intermediates)
    bool agrees() const { return colour_twin != nullptr; }
    // ... and generates from both fields: not once the input was jittered (input_jittered), where
    // the twin's estimate follows each frame's aliasing, as the refinement of estimated motion does
    // not run there; the twin is then no longer fed (docs/ACCURACY.md, change 44: frame generation
    // on the jittered renders, scored after a bicubic 2x upscale, lost 0.1-2.2 dB with both fields).
    bool agreeing() const { return agrees() && !input_jittered; }
    // The twin's parameters: this session's, estimating motion without correcting anything (its
    // interpolation runs separate passes, generate_agreed's force_separate).
    static Params twin_params(Params p) {
        p.colour_agree = false;
        p.correct_vectors = false;
        return p;
    }
    // Interpolation of an agreeing session: per alpha, the given field's frame (separate passes),
    // the twin's, then the agree pass over both into the given one's output.
    Result<std::vector<GeneratedFrame>> generate_agreed(std::span<const float> alphas);
    Result<PassTiming> record_agree(const gpu::GenParams& g, Session::Impl& colour);
    // Extrapolation of an agreeing session, and with super resolution interpolation too: both
    // fields' frames of every alpha, then the agree pass from the fields' residuals at the newest
    // input (agree_residual) into the given ones.
    Result<std::vector<GeneratedFrame>> agree_by_residual(std::span<const float> alphas, bool extrapolate);
    Result<void> ensure_agree_buffers(bool light); // light: also the gain's (interpolation)

    // Motion estimation from colour (motion.cpp): sessions without vectors.
    struct Motion {
        std::vector<ref::MotionLevel> levels;
        std::array<vk::Buffer, 2> pyramid; // luma pyramid of frames[i]
        vk::Buffer field;                  // host-visible block vectors, both directions
        vk::Buffer coarse;                 // the coarse levels' refined fields (polish_coarse)
        vk::Buffer patches;                // the patch inverse search's vectors (search.h)
        vk::Buffer gain;                   // host-visible: the pair's lighting gain, its dispatch (luma.h)
        std::vector<PassTiming> timings;   // of the last submit: luma, match, flow, polish (those run)
        bool last_cut = false;             // block matching found a cut (sessions that correct: no restart)
        bool field_valid = false;   // the field holds the previous submit's vectors (temporal candidates)
        float typical_share = -1.f; // running mean of unmatched blocks since the restart (scene cuts)
        glm::vec2 global{0.f};
    } estimator;

    // Tile skipping (tiles.cpp, shaders/classify.h).
    struct TileSet {
        vk::Buffer flags, work, generate, statics;
    };
    struct Tiles {
        // Per generated frame of a call (and index 0 for the sr pass of a submit), the TILE_* flags
        // and the tile lists, host-visible (the host writes their headers in the command buffer
        // and reads the counts after the fence).
        std::vector<TileSet> sets;
        bool last_tiled = false;    // the last generated frame was classified
        bool last_sr_tiled = false; // the last submit's sr pass was classified
        uint32_t last_side = 0;     // tile side of the last classification
        uint32_t sr_total = 0, sr_skipped = 0;
        PassTiming classify_sr_timing = timing_of(PassId::classify);
        ClassifyBackoff gen_backoff, sr_backoff; // when generate calls / sr submits classify
    } tiles;

    ~Impl();

    // session.cpp
    Result<void> init();
    Result<void> submit(const FrameView& frame, const HostMemory* memory);
    bool sr() const { return out_w != format.width || out_h != format.height; }
    bool denoise() const { return sr() && params.denoise; }

    // motion.cpp
    bool estimates_motion() const { return !format.has_vectors || params.correct_vectors; }
    // Neither vectors nor depth from the client: both planes come from the motion passes.
    bool colour_only() const { return !format.has_vectors && !format.has_depth; }
    // Given vectors corrected by colour (Params::correct_vectors) rather than estimated.
    ref::VectorCorrection correction() const {
        return {format.has_vectors && params.correct_vectors, params.correct_ratio, params.correct_margin,
                params.correct_depth, params.correct_front};
    }
    Result<void> init_motion();
    Result<void> record_luma(int slot);
    // The lighting gain of frames cur and prev (shaders/luma.h): prev's pyramid scaled in place.
    Result<void> record_luma_gain(int cur, int prev);
    // light: block costs with the light cap (unjittered frames; ref::kMotionLightCap).
    Result<void> record_match(int cur, int prev, bool light);
    ref::MotionSummary summarise_motion(bool relit) const;
    // The cut statistics of the finest level's blocks (match.comp FGSR_MATCH_CUT, kCutRegion).
    Result<void> record_cut_match(int cur, int prev);
    // coarse: flow reads the coarse levels' field (record_polish_coarse, recorded before it).
    Result<void> record_flow(int cur, int prev, glm::vec2 global, bool coarse);
    // The variational refinement's sweeps over the estimated vectors (after record_flow and a barrier).
    Result<void> record_polish(int cur, int prev);
    // The coarse-to-fine refinement before flow (polish.h, polish_coarse): seed and sweeps per level.
    // search: each level's patch inverse search and densification first (Params::motion_search);
    // sweep: the variational sweeps (up to ref::kPolishMaxPixels).
    Result<void> record_polish_coarse(int cur, int prev, bool search, bool sweep);

    // generate.cpp
    // The bindings (GEN_*) of frame 1, frame 0 and the splat keys and motion that splat, refine,
    // disocc, generate, generate_sr and classify (generate mode) share.
    // `slice`: the keys of that slice only; kAllSlices: the whole buffer (splat).
    static constexpr uint32_t kAllSlices = ~0u;
    using GenFrames = At<GEN_MV1, GEN_MV0, GEN_DEPTH1, GEN_DEPTH0, GEN_KEYS, GEN_MOTION>;
    GenFrames generated_frames(uint32_t slice = 0) const {
        const GpuFrame& f1 = frames[size_t(newest)];
        const GpuFrame& f0 = frames[size_t(1 - newest)];
        if (slice == kAllSlices) return GenFrames{{f1.mv, f0.mv, f1.depth, f0.depth, keys, motion}};
        const VkDeviceSize at = VkDeviceSize(slice) * splat_stride;
        return GenFrames{
            {f1.mv, f0.mv, f1.depth, f0.depth, BufRef(keys.handle(), at * 8, VkDeviceSize(n) * 8), motion}};
    }
    // Grows keys to `count` slices (contents lost); creates motion.
    Result<void> ensure_splat_slices(uint32_t count);
    // splat's push block for alphas[first, first + count) (tiled: count 1).
    gpu::SplatParams splat_params(const gpu::GenParams& g, std::span<const float> alphas) const;
    // splat's build for `count` frames of one dispatch (tiled: count 1), without the frame-0 vector
    // lookup where the call cannot use it (shaders/motion.h, MOTION_LOOKS_UP_M0).
    static Variant splat_variant(const gpu::GenParams& g, size_t count, bool tiled);
    // The field of a generated frame at input resolution (field, field_depth, field_state) from
    // the keys of splat slice `slice`: refine, disocc (record_field: both, disocc where holes are
    // filled); each dispatch followed by a barrier.
    Result<void> record_refine(uint32_t slice, const gpu::GenParams& g);
    Result<void> record_disocc(uint32_t slice, const gpu::GenParams& g);
    Result<void> record_field(uint32_t slice, const gpu::GenParams& g);
    Result<std::vector<GeneratedFrame>> generate(std::span<const float> alphas, bool extrapolate);
    // The checks of a call (two frames submitted, 1..kMaxAlphas alphas in range), then the frames;
    // generate_frames records them (checked), one alpha at a time in an agreeing call.
    Result<void> check_generate(std::span<const float> alphas, bool extrapolate) const;
    Result<std::vector<GeneratedFrame>> generate_frames(std::span<const float> alphas, bool extrapolate);
    Result<void> ensure_outputs(size_t count);

    // sr.cpp
    Result<void> upload_lut();
    // Records the sr pass of frame f (previous frame prev) into the history's next output, tiled
    // when classification may pay; writes timestamp `query` after classify when tiled. Returns
    // whether it was tiled.
    Result<bool> record_sr(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev, uint32_t& query);
    // The sr pass's own bindings (before the tiled ones) for frame f into `out`.
    Result<void> record_sr_noise(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                 const vk::Buffer& history, const vk::Buffer& out);
    using SrInputs = At<SR_COLOR, SR_DEPTH, SR_MV, SR_PREV_DEPTH, SR_HISTORY, SR_LUT, SR_OUTPUT, SR_NOISE>;
    SrInputs sr_inputs(const GpuFrame& f, const GpuFrame& prev, const vk::Buffer& history,
                       const vk::Buffer& out) const;
    // After the submit's fence: the sr timing, the history swap.
    void finish_sr(const PassTiming& t);
    // The generate_sr push block of generated frames (the newest frame's jitter, with history).
    GenSrPush gen_sr_push(const gpu::GenParams& g) const;
    // The SR output generate_sr reads: the previous one (interpolation) or the newest one.
    const vk::Buffer& gen_sr_source(bool extrapolate) const;

    // denoise.cpp
    Result<void> record_denoise(const vk::Buffer& color);
    void read_noise_estimate();

    // tiles.cpp
    uint32_t tile_side() const;
    uint32_t tiles_x() const;
    uint32_t tiles_total() const;
    Result<void> ensure_tile_sets(size_t count);
    void reset_lists(const TileSet& t, uint32_t work_span, uint32_t output_span);
    // The header of an empty list (common.h, TILE_LIST_HEADER): no workgroups yet (0, 1, 1), no
    // entries, the tile side (0: entries are pixels) and the span of invocations per entry.
    static std::array<uint32_t, TILE_LIST_HEADER> empty_list_header(uint32_t side, uint32_t span) {
        return {0, 1, 1, 0, side, span, 0, 0};
    }
    static uint32_t list_count(const vk::Buffer& list);
    // empty_keys: also empty the keys for the tiled splat (generate mode, not in a probe).
    Result<void> classify(gpu::ClassifyParams c, const Slots<PassId::classify>& s, bool empty_keys = true);
    Result<void> record_sr_tiled(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                 const vk::Buffer& history, const vk::Buffer& out, uint32_t query);
    Result<void> classify_frame(const TileSet& ts, const gpu::GenParams& g, const vk::Buffer* out);
    Result<void> record_tiled(size_t k, const gpu::GenParams& g, bool extrapolate, uint32_t& q);
    // Skip bookkeeping: whether this call (generate) or submit (sr) classifies. A generate call
    // due after a miss only probes: it classifies frame 0's tiles for the decision and runs every
    // pass over every tile (on lavapipe the probe costs ~1.2x a plain call, docs/TILES.md); the
    // next call skips tiles if the probe found enough.
    enum class GenTiles { none, tiled, probe };
    GenTiles classify_generate();
    Result<void> record_probe(const gpu::GenParams& g, uint32_t& q);
    uint32_t probe_skippable() const;
    bool classify_sr(bool has_history);
    // After the fence: the tiles counts of a tiled generated frame k (passes classify, splat,
    // generate(_sr)) and of a tiled sr pass (which also tells sr_backoff).
    void count_generate_tiles(size_t k, GeneratedFrame& gf) const;
    // Whether `skippable` tiles reach min_generate_skip_share() of the frame's: a generated frame
    // worth classifying.
    bool generate_worth_skipping(uint32_t skippable) const;
    double min_generate_skip_share() const;
    void count_sr_tiles();
};

} // namespace fgsr
