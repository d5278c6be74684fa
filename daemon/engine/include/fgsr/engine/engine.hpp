// The fgsr engine: Mob-FGSR frame generation on a Vulkan compute queue.
//
// Thread-safety: an Engine may be shared; each Session is used by one thread at a time.
// Lifetime: sessions must be destroyed before their engine.
#pragma once

#include <fgsr/engine/defaults.hpp>
#include <fgsr/engine/passes.hpp>
#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace fgsr {

struct DeviceOptions {
    // Device to use: a decimal index into the physical-device list, or a case-insensitive substring
    // of the device name. Empty: the FGSR_DEVICE environment variable, else the first non-CPU
    // device, else the first CPU device (Mesa lavapipe).
    std::string device;
    // Khronos validation layer; also enabled by FGSR_VALIDATION=1. Validation messages of
    // severity error are counted (Engine::validation_errors) and logged to stderr.
    bool validation = false;
    // Workgroup side of every pass, which also picks the CPU-device forms (32: generate in two
    // passes, generate_sr from a field written per input pixel, classify and ingest several pixels
    // per invocation) or the GPU forms (8). 0: by device type (32 on CPU devices that allow it).
    // Tests run the GPU forms on lavapipe with 8.
    uint32_t workgroup = 0;
};

enum class MotionModel : uint32_t {
    quadratic = 0, // uniform acceleration, supplement Eqs. 1-2 (needs the previous frame's vectors)
    linear = 1,    // uniform velocity, Eqs. 14-15
};

enum class BlendMode : uint32_t {
    select = 0, // paper Eq. 1: the temporally closer warped frame where both agree
    mix = 1,    // alpha-weighted mix where both agree (default: +0.2 to +0.3 dB on every capture
                // measured: toss-fg 28.20 -> 28.54, bunker LR 29.73 -> 29.95, synthetic 36.18 -> 36.46)
};

// History resampling of super resolution (shaders/resample.h).
enum class Resample : uint32_t {
    bilinear = 0,
    catmull_rom = 1, // bicubic
    lut = 2,         // learned 32x32x16 table (fgsr/engine/lut.hpp)
};

// sr's spatial upsample (shaders/sr.h step 5): where the history is rejected, and on the first frame.
enum class SrSpatial : uint32_t {
    automatic = 0,   // B-spline where the input measures aliased (Session::input_aliasing), else Catmull-Rom
    catmull_rom = 1, // interpolating
    bspline = 2,     // cubic B-spline: smooth, low-passes the point samples' aliasing
};

// The colour kernel of frame generation's warps at input resolution (shaders/warp.h).
enum class WarpKernel : uint32_t {
    automatic = 0, // cubic in interpolation with the client's vectors on input that measures
                   // antialiased (Session::input_aliasing), else bilinear (docs/ACCURACY.md, change 39)
    bilinear = 1,
    cubic = 2, // Catmull-Rom, clamped to the range of its inner 2x2 taps (no ringing)
};

// Algorithm parameters. Depth threshold is relative (|d0 - d1| / min(d0, d1)), so it holds for
// any linear depth unit; brightness threshold is on display-referred luma in [0, 1].
struct Params {
    MotionModel motion = MotionModel::quadratic;
    BlendMode blend = BlendMode::mix;
    float t_depth = defaults::t_depth;
    float t_bright = defaults::t_bright;
    bool fill_gaps = true;  // refine: fill the grid-like gaps of splatting
    bool fill_holes = true; // disocc: give holes a vector (skipped pass when false)
    // disocc: a hole pixel that the footprint of a splatted surface in front overlaps takes that
    // surface's vectors, so a moving edge keeps its sub-pixel profile (shaders/disocc.h,
    // hole_cover; docs/ACCURACY.md, change 14). Frame generation at input resolution only (not
    // ISR / ESR); with fill_holes.
    bool cover_edges = true;
    // disocc, extrapolation: a hole also takes the background's vector to frame 0, and the frame
    // takes frame 0 there where frame 1's sample (the paper's, along the path of the surface that
    // left) lies on that surface: small surfaces against their step, bending paths (shaders/warp.h,
    // frame0_behind; docs/ACCURACY.md, change 50). Frame generation and ESR; with fill_holes.
    bool hole_frame0 = true;
    // false: splat, then one fused pass (refine, disocc, warp, blend per pixel; the default, and on
    // CPU devices several times faster). true: each pass on its own, with per-pass timings and
    // intermediates kept for read_intermediates(). Both give the same frames.
    bool separate_passes = false;

    // Super resolution (paper 3.5). scale > 1 makes the session upscale every submitted frame to
    // round(size * scale) (fixed at session creation); 1 disables it.
    float scale = 1.f;
    Resample resample = Resample::lut; // history resampling (the `sr` pass)
    // ISR / ESR (shaders/generate_sr.h): resampling of the SR outputs at the generated instant.
    // Unset (the default): automatic, bilinear except Catmull-Rom for ISR on input that measures
    // antialiased (params::warp_resample). Bilinear because there the positions come from frame
    // generation's motion, not from rendered vectors, and the LUT lost to it on 15 of 16 train
    // figures, by up to 0.35 dB (docs/ACCURACY.md, change 10); Catmull-Rom for ISR on antialiased
    // input, which scored higher with it on all six train captures, with the client's vectors and
    // with colour-only motion, while ESR and the jittered captures did not (change 48). Not carried
    // by the wire protocol.
    std::optional<Resample> warp_resample;
    std::vector<float> lut;            // kLutSize weights; empty: fgsr::default_lut(scale)
    float sr_a = defaults::sr_a;       // Eq. 2: weight of the current samples
    float sr_b = defaults::sr_b;       // Eq. 2: weight fall-off with sample distance (LR pixels)
    bool dilate_mvs = false;           // vector of the frontmost 3x3 neighbour (QRISP 4.1)
    // Sessions with vectors and depth in a linear colour format: a pixel that is not over-white
    // takes the depth and vector of the nearest over-white pixel of its 3x3 neighbourhood in front of
    // it (luminance above dilate_bright; ingest's dilate stage, shaders/dilate.h), so that the
    // antialiased light around lamps and glints moves with them. 0 turns it off. Not carried by
    // the wire protocol: fgsrd's sessions use the default.
    float dilate_bright = defaults::dilate_bright;
    // Sessions with vectors and depth (any colour format): at every depth edge, the pixel behind
    // takes the depth and vector of its front neighbour where, in the previous frame, the colour
    // it holds follows the front's motion: its colour difference there is below dilate_edges times
    // the one under its own vector (ingest's dilate stage, edge rule, shaders/dilate.h). 0 turns
    // it off. Not carried by the wire protocol: fgsrd's sessions use the default.
    float dilate_edges = defaults::dilate_edges;
    // Extrapolation with uniform acceleration (shaders/motion.h): where the frame-0 vector read
    // for a pixel implies an acceleration, its edge neighbours of the same surface are searched
    // for the smallest one (a slow mover's edge otherwise reads the still ground beside it).
    // About half again splat's time in extrapolation on CPU devices; off in the balanced and
    // performance presets. Not carried by the wire protocol: fgsrd's sessions use the default.
    bool accel_search = true;
    // Interpolation with uniform acceleration (shaders/motion.h): the acceleration of a pixel is
    // the median of its own and those of its 3x3 neighbours of the same surface, where at least
    // 5 of the 9 take part (an m0 read from another leaf or from the ground beside an edge is an
    // outlier there). splat 1.16-1.30x in interpolation on lavapipe (docs/PERFORMANCE.md); off
    // in the balanced and performance presets. Not carried by the wire protocol: fgsrd's sessions
    // use the default.
    bool accel_median = true;
    // Uniform acceleration (shaders/motion.h): a frame-0 pixel counts as the point's surface where
    // its depth lies within 4 T_D of the point's, a band extended to the depth change the local
    // motion implies (a surface the camera approaches was farther: 1 / sqrt(det J) of the frame-1
    // vectors' local map). It gains where the camera approaches fast (street renders); across an
    // unannounced camera cut it lost (a fresh render's extrapolation fell below uniform velocity),
    // which vector_cuts below prevents, so the two are defaults together (docs/ACCURACY.md,
    // changes 21, 23); off in the balanced and performance presets. Four more vector and depth
    // reads per source pixel in splat. Not carried by the wire protocol: fgsrd's sessions use the
    // default.
    bool accel_depth_motion = true;
    // Interpolation's blend: where the two warped depths differ by more than t_depth, frame 0's is
    // compared with what frame 1 may show at its sample, the depths of its pixel and edge neighbours
    // extended by the depth change frame 1's vectors imply (shaders/blend_depth.h). Each warped depth
    // is its own frame's nearest pixel's, so a surface the camera approaches by more than t_depth a
    // frame step, and pixels along edges, took one frame alone (docs/ACCURACY.md change 38). Reads
    // frame 1's vectors and depths only where the plain test fails. Not carried by the wire
    // protocol: fgsrd's sessions use the default.
    bool blend_depth_motion = true;
    // The warps' colour kernel (shaders/warp.h). Bilinear sampling at a fractional position
    // low-passes the frame; the cubic keeps an antialiased input's detail. automatic takes it in
    // interpolation with the client's vectors on input that measures antialiased (the measure of
    // Session::input_aliasing, over the first frames), and bilinear where the positions are less
    // sure than the blur costs: in extrapolation (predicted), with vectors estimated from colour
    // (colour-only sessions, the colour_agree twin), and on aliased input (the cubic interpolates
    // the aliasing): docs/ACCURACY.md change 39. Not carried by the wire protocol: fgsrd's sessions
    // use the default.
    WarpKernel warp_kernel = WarpKernel::automatic;
    // Sessions with vectors (ingest's cut stage, shaders/cut.h): a frame whose own vectors do not
    // explain its colour against the previous frame's (most of its 8x8 blocks without a match, a
    // jump from the session's typical share: ref::is_vector_cut) is a scene cut the client did not
    // announce: the session restarts as on FrameView::reset (no frame generated across it: the
    // pair is refused with not_ready, as colour-only sessions do at the cuts they find; the SR
    // history restarts, last_scene_cut() says so) and the frame's vectors are not read as the next
    // pair's frame-0 motion. On by default and in every preset (docs/ACCURACY.md, changes 22, 23).
    // A sequence that is not continuous on purpose (two inputs submitted in turn, a clean frame
    // after a frame of NaN) is a cut to it too: turn it off for such input. One more command
    // buffer per submit. Not carried by the wire protocol: fgsrd's sessions use the default.
    bool vector_cuts = true;
    // ISR / ESR (shaders/generate_sr.h): the warped SR history is clipped per channel to the mean
    // +- sr_clip standard deviations of the low-resolution frame's 3x3 neighbourhood at the same
    // instant (variance clipping); 0 turns it off. Not carried by the wire protocol: fgsrd's
    // sessions use the default.
    float sr_clip = defaults::sr_clip;
    // The same on input that measures antialiased (Session::input_aliasing): wider, since the
    // low-passed neighbourhood's spread is narrower than the detail the SR history restores
    // (docs/ACCURACY.md, change 47: train isr / esr +0.11 to +0.37 dB on foliage-, hdr-, shelf-sraa).
    // 0 turns it off. Not carried by the wire protocol.
    float sr_clip_antialiased = defaults::sr_clip_antialiased;
    // sr: on input without jitter that measures antialiased (Session::input_aliasing), the
    // history's weight is lowered where it disagrees with the new samples, by this factor of the
    // disagreement (shaders/sr.h step 6; 0 turns it off). Not carried by the wire protocol.
    float sr_disagree = defaults::sr_disagree;
    // sr: the history's depth test expects the depth change the local motion implies (a surface the
    // camera approaches was farther before; shaders/sr.h step 2); false: the plain relative test.
    // Not carried by the wire protocol.
    bool sr_depth_motion = true;
    // sr: the kernel of the spatial upsample (rejected history, first frame). Not carried by the
    // wire protocol.
    SrSpatial sr_spatial = SrSpatial::automatic;
    // sr: on input that measures aliased (Session::input_aliasing), the new samples' weight is
    // lowered where they scatter about the history like noise (detail finer than an output pixel),
    // so that more frames average them (shaders/sr.h step 7); false: Eq. 2's a everywhere. Opt-in:
    // sr gains 0.09-0.25 dB on the noisy train renders but fan-sr (validation) loses 0.04 and
    // isr / esr lose up to 0.03 on foliage, fan and cut (docs/ACCURACY.md, change 19). Not
    // carried by the wire protocol.
    bool sr_noise_average = false;
    // sr, on input that measures aliased: the history read with the LUT (Resample::lut) moves
    // towards the cubic B-spline where the new samples scatter about the history like noise and
    // the history there is smoother than they are (shaders/sr.h step 3). Off by default: it gains
    // on texture far finer than an output pixel (street-sr +0.04 dB, hdr-sr +0.02) and loses on
    // texture near the output's resolution (orbit-sr, foliage-sr -0.015; docs/ACCURACY.md,
    // change 20). Not carried by the wire protocol.
    bool sr_noise_kernel = false;
    // sr, on input that measures antialiased: Eq. 2's term of the current samples is the spatial
    // upsample (Catmull-Rom of the input at the output pixel) instead of the samples' tent weights
    // (shaders/sr.h step 4). Antialiased input is already low-passed, and the tent blurs it again,
    // frame after frame; Catmull-Rom restores what the reference shows. On by default: train sr
    // +0.22 / +0.57 dB on street-sraa / rotor-sraa (bunker LR -0.001), validation +0.35 to +0.43,
    // isr / esr +0.02 to +0.19 everywhere (docs/ACCURACY.md, change 46). Aliased input (point
    // samples) keeps the tent, which does not interpolate the aliasing. Not carried by the wire
    // protocol (the default applies).
    bool sr_sharp_current = true;
    // Sessions with vectors: estimate motion from colour as colour-only sessions do (luma, match,
    // flow passes) and replace, per pixel, the client's vector by the estimate where the colour
    // follows the estimate by far better (shading that moves on its own: shadows, reflections).
    // The depth stays the client's. Costs the motion estimation's passes (docs/MOTION.md). Only
    // with scale 1: on jittered, aliased SR input it loses (validate refuses it).
    bool correct_vectors = false;
    // Frame generation in sessions with vectors: also estimate motion from colour and generate the
    // frame from that field, as a colour-only session would (a second, colour-only session fed
    // the same frames without vectors or depth); per pixel take the colour-only frame where the
    // given field explains the colour worse than the colour-only field (pass `agree`,
    // shaders/agree.h): shading that moves on its own (shadows sweeping over still ground, contact
    // shadows, sunlight travelling with the camera), which no vector of the surface carries.
    // Interpolation compares each field's two warped frames (the given field's generation then
    // runs as separate passes), forgiving each a small brightness gain fitted over a box (a
    // surface turning towards the light: change 42), extrapolation each field's residual at the
    // newest input. Costs the motion estimation's passes at every submit and a second generated
    // frame. Off in sessions without vectors, which estimate their own motion; Session::params()
    // says which. With super resolution (scale other than 1) the twin upscales too (its own sr
    // pass at every submit), and interpolation (ISR) as extrapolation (ESR) mixes the two fields'
    // frames by each field's residual at the newest input: the residuals and their box means at
    // the input's size, the mix per output pixel (change 45); the upscaled frame is the one without
    // the flag, so a session that only upscales should leave it off (fgsr eval does in sr; fgsrd
    // takes the flag at a scale other than 1 only with FGSR_MODE_INTERPOLATE or
    // FGSR_MODE_EXTRAPOLATE). Nor from a session's first jittered frame on: the twin's estimate
    // follows each frame's aliasing (change 44: frame generation on the jittered renders, upscaled
    // 2x, lost 0.1-2.2 dB with it); Session::params() still reports the flag then, the frames are
    // those without it and the twin is no longer fed. On by
    // default and in the quality preset since the patch inverse search (change 40) made the
    // colour-only field good enough: train interp +8.67 dB summed over 11 captures, none lower by
    // more than 0.0001; extrap +7.48, none lower by more than 0.001 (docs/ACCURACY.md, change 41).
    // Off in balanced and performance: on CPU devices it costs several times a frame. fgsrd's
    // sessions take it only with the protocol flag FGSR_SESSION_COLOUR_AGREE (changes 33 to 35,
    // 41).
    bool colour_agree = true;
    float correct_ratio = defaults::correct_ratio;   // [0, 1]
    float correct_margin = defaults::correct_margin; // >= 0, luma units
    float correct_depth = defaults::correct_depth;   // >= 0, relative depth difference
    float correct_front = defaults::correct_front;   // >= 0, relative: the previous position in front
    // Sessions without vectors: estimate motion without the variational refinement of the
    // estimated vectors (shaders/polish.h), for CPU devices that cannot afford it. The refinement
    // is otherwise on up to 960x540 (ref::kPolishMaxPixels) on unjittered input; off, on lavapipe
    // the motion passes take 0.5-0.6x the time (a whole colour-only frame about 0.65-0.7x) and
    // frames lose 0.3-0.4 dB on average, up to 1.2 dB on a near-static scene (docs/MOTION.md,
    // "The fast setting"). No effect with vectors (the correction never refines).
    bool fast_motion = false;
    // Sessions without vectors: on the levels of the block matching above the finest, a block that
    // also matches a vector of a nearby block far from its own takes the one the most nearby
    // unambiguous blocks agree with (shaders/match.h, stages ambiguity and consensus): periodic
    // texture (checkers, stripes, tiles) otherwise locks one period off. fgsr-colour +1.6 dB on
    // the panning checker walls (pan seed 2, pan), +0.9 / +0.3 on builtin; about 3.7 ms a frame
    // at 480x270 on lavapipe (docs/MOTION.md, "The consensus of unambiguous blocks"). Not with
    // correct_vectors (it would pull moving shadows onto the still ground's vector). Not carried
    // by the wire protocol.
    bool motion_consensus = true;
    // Sessions without vectors: DIS's patch inverse search, propagation and densification on the
    // coarse levels of the coarse-to-fine field, between each level's seed and its sweeps
    // (shaders/search.h); with it the coarse levels are refined at any size (their sweeps and
    // level 0 still up to kPolishMaxPixels). fgsr-colour: train up on 22 of 24 rows
    // (+5.95 dB summed; mobfgsr-bunker HR +0.84 / +0.77 interp / extrap, at most -0.06), validation
    // up on all 12 (+4.14), the fresh seed-4 renders on 6 of 10 (+1.92, pan -0.11 the worst).
    // On lavapipe about 1.2x a 480x270 colour-only frame's GPU time and 1.4x a 1080p one's
    // (docs/ACCURACY.md, change 40). A default since change 40; fast_motion (no refinement) is the
    // way to leave it out through fgsrd. Not carried by the wire protocol.
    bool motion_search = true;
    // The client's vectors are differences of jittered positions (QRISP Eq. 1); ingest removes
    // the jitter: mv += jitter(previous) - jitter(current).
    bool mvs_contain_jitter = false;
    // Noisy input (shaders/denoise.h): a `denoise` pass estimates the noise of each rendered frame
    // (median absolute Laplacian) and, where it exceeds noise_floor, filters the frame with a 3x3
    // bilateral filter of range denoise_strength x (noise above the floor) before accumulation.
    // Noise is measured relative to the local brightness to the power denoise_gamma (0: in linear
    // colour units; 1: as a fraction of the brightness), and the filter's range scales with it.
    // Clean input (estimate at or below the floor) passes unchanged. SR sessions only.
    bool denoise = true;
    float denoise_strength = defaults::denoise_strength; // range in noise sigmas, [0, 64]
    float noise_floor = defaults::noise_floor;           // in the units of denoise_gamma, >= 0
    float denoise_gamma = defaults::denoise_gamma;       // [0, 2]

    // Per-tile work skipping (shaders/classify.h): a `classify` pass finds the tiles with no
    // motion; splat, generate, sr and generate_sr run only over the tiles that need them
    // (indirect dispatch over compacted tile lists) and the static tiles take a cheap path
    // (copy-through, or the history read at the pixel itself). The frames equal those with
    // skipping off up to float rounding (tests/test_tiles.cpp states the tolerance). Not applied
    // with separate_passes. After a classification that finds less than a quarter of the tiles
    // skippable (generated frames on CPU devices: 70 %), the next 7 calls (generate) or submits
    // (sr) run without classifying; each further such classification in a row doubles that run,
    // up to 63. Generate calls then only probe: they classify for the decision but run every
    // tile (docs/TILES.md).
    bool skip_tiles = true;
    // Tile side in pixels: 8, 16 or 32; 0 picks the measured default (docs/TILES.md).
    uint32_t tile_size = 0;
};

// Checks the documented ranges: t_depth and t_bright finite and >= 0, sr_a in [0, 1], sr_b,
// sr_clip, sr_clip_antialiased and sr_disagree finite and >= 0, correct_ratio in [0, 1],
// correct_margin finite and >= 0, correct_depth and correct_front >= 0 (correct_vectors only with
// scale 1), scale finite in [1, 4], lut empty or kLutSize finite weights, denoise_strength in
// [0, 64], noise_floor finite and >= 0, denoise_gamma in [0, 2], known enum values.
// Errors: invalid_argument naming the field and its value.
Result<void> validate(const Params& params);

// Whether a session of `format` and `params` generates from both fields (Params::colour_agree): with
// vectors. Engine::create_session decides by it, and a client describing the same session to fgsrd
// sends FGSR_SESSION_COLOUR_AGREE by it (capture::session_desc; with a scale other than 1 only
// when the session generates frames).
inline bool colour_agree_applies(const FrameFormat& format, const Params& params) {
    return params.colour_agree && format.has_vectors;
}

struct PassTiming {
    // "splat", then "generate" (fused) or "refine", "disocc", "warp", "blend" (separate passes);
    // ingest is timed at submit (Session::last_ingest_ms).
    std::string name;
    double ms = 0; // GPU time from timestamp queries
    // The pass's begin and end timestamps in CLOCK_MONOTONIC ns: calibrated with
    // VK_EXT_calibrated_timestamps when Engine::calibrated_time(), else anchored by taking the
    // submission's first timestamp to be the CPU time just before vkQueueSubmit (so they may run
    // early by the queue's start-up latency).
    uint64_t begin_ns = 0;
    uint64_t end_ns = 0;
    // Tiles of the frame and how many of them the pass skipped or took a cheap path for
    // (Params::skip_tiles); both 0 when the pass does not classify tiles.
    uint32_t tiles_total = 0;
    uint32_t tiles_skipped = 0;
    // The pass (fgsr_pass_id numbering, fgsr/engine/passes.hpp); name is pass_name(pass).
    PassId pass = PassId::count;
};

// Noise of a rendered frame as the `denoise` pass estimated it (shaders/denoise.h).
struct NoiseEstimate {
    float sigma = 0; // standard deviation of the per-pixel noise, linear colour units over the
                     // brightness scale (Params::denoise_gamma; 0: linear colour units)
    float range = 0; // range of the bilateral filter applied (0: the frame was not filtered)
};

struct GeneratedFrame {
    float time = 0;  // alpha for interpolation, 1 + alpha for extrapolation
    ImageRGBA color; // linear RGBA, the session's resolution
    std::vector<PassTiming> passes;
    double gpu_ms = 0; // sum of passes
};

class Session;

// Host memory imported into the device (VK_EXT_external_memory_host), e.g. a shared-memory pool a
// client process writes: Session::submit(frame, memory) ingests planes that lie inside it without a
// host copy. The memory must stay mapped while this object lives; destroy it after every session
// that submitted from it has returned from submit (submits are synchronous). Another process may
// write the memory at any time: ingest reads whatever bytes are there (and sanitises them).
class HostMemory {
  public:
    ~HostMemory();
    HostMemory(const HostMemory&) = delete;
    HostMemory& operator=(const HostMemory&) = delete;
    const std::byte* data() const;
    size_t size() const;

    struct Impl;
    const Impl* impl() const { return impl_.get(); }

  private:
    friend class Engine;
    explicit HostMemory(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

class Engine {
  public:
    static Result<std::unique_ptr<Engine>> create(const DeviceOptions& options = {});
    ~Engine();
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;

    std::string device_name() const;
    bool is_cpu_device() const;
    // The workgroup side of the passes (DeviceOptions::workgroup): 32 selects the CPU-device forms.
    uint32_t workgroup() const;
    uint64_t validation_errors() const;
    // True when PassTiming begin/end come from calibrated timestamps (VK_EXT_calibrated_timestamps
    // with the CLOCK_MONOTONIC domain).
    bool calibrated_time() const;
    // minImportedHostPointerAlignment in bytes when host memory can be imported, else 0.
    size_t host_import_alignment() const;
    // Imports size bytes at data (both multiples of host_import_alignment()). Errors: unsupported
    // (no VK_EXT_external_memory_host), invalid_argument (alignment), vulkan.
    Result<std::unique_ptr<HostMemory>> import_host_memory(void* data, size_t size);

    // Pipelines (one per shader variant) are created at their first use or by warm_up: how many
    // exist so far, of pipeline_variants().
    uint32_t pipelines_created() const;
    static uint32_t pipeline_variants();

    // Lists the Vulkan devices "index: name (type)" for --list-devices.
    static Result<std::vector<std::string>> list_devices();

    Result<std::unique_ptr<Session>> create_session(const FrameFormat& format, const Params& params = {});

    // Creates every pipeline on all cores (otherwise each is created at its first use, 50-280 ms
    // apiece on lavapipe), then runs small sessions through the passes the usual sessions take
    // (colour-only in 8-bit sRGB and half float, half float with vectors and depth; 1, 2 and 3
    // frames a pair interpolated and extrapolated; super resolution x2 with ISR and ESR; a mover
    // over a still and over a panning background, so that tiles both skip and do not), so that a
    // driver that compiles a pipeline at its first dispatch (llvmpipe) does it here, not during a
    // client's first frames. Returns the frames generated. Takes about as long as the first frames
    // would have; with the driver's shader cache warm, mostly the pipelines' creation (lavapipe on
    // 2 cores: about 4 s).
    Result<uint32_t> warm_up();

    struct Impl;

  private:
    explicit Engine(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// A stream of frames of one format. Frame 1 is the newest submitted frame, frame 0 the one before.
class Session {
  public:
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const FrameFormat& format() const;
    const Params& params() const;
    // Parameters for the next calls; the scale and colour_agree stay those of creation (a session
    // that agrees keeps its colour-only twin, which takes the new parameters too). Parameters that
    // validate() refuses are ignored: the session keeps its previous ones.
    void set_params(const Params& p);

    // Copies, validates and ingests a frame; it becomes frame 1. An empty mv plane means the
    // vectors are unknown (e.g. the first frame after a cut). Errors leave the session unchanged.
    Result<void> submit(const FrameView& frame);
    // The same with planes inside imported host memory: ingest reads them in place (zero copy).
    // Plane offsets from memory.data() must be multiples of the device's
    // minStorageBufferOffsetAlignment (FGSR_PLANE_ALIGNMENT satisfies it). Same frames as submit.
    Result<void> submit(const FrameView& frame, const HostMemory& memory);
    // Forgets the submitted frames (scene cut): the next frame submitted starts afresh as with
    // FrameView::reset (its vectors, which point into the shot before the cut, are not kept).
    void reset();
    uint64_t frames_submitted() const;
    // GPU time of the last submit's ingest pass.
    double last_ingest_ms() const;
    // Timing of the last submit's ingest pass (with CLOCK_MONOTONIC begin/end).
    PassTiming last_ingest_timing() const;
    // Sessions without vectors (FrameFormat::has_vectors false), or that estimate motion beside
    // them (Params::correct_vectors, colour_agree): the timings of the last submit's motion passes
    // (luma, then match and flow when there was a previous frame; empty otherwise). With
    // colour_agree they are the colour-only twin's, after the twin's own ingest of the frame, and
    // with super resolution its sr pass last.
    std::vector<PassTiming> last_motion_timings() const;
    // Whether the last submit was found to be a scene cut (then it started afresh, as with
    // FrameView::reset: frames before it are not interpolated from): by block matching in sessions
    // without vectors, by the cut stage in sessions with them (Params::vector_cuts).
    bool last_scene_cut() const;
    // The share of the last submit's 8x8 blocks that found no match, as the scene-cut test counts
    // them (both as given and relit: a change of the whole frame's lighting is no cut): in sessions
    // with vectors those whose vectors did not explain their colour (the cut stage, shaders/cut.h),
    // in sessions that estimate motion (without vectors, or correcting them) those of block
    // matching's finest level, relit only where they make a cut as matched. Negative where no test
    // ran (the first frame or a reset; given vectors with Params::vector_cuts off; a session with
    // vectors whose frame has none).
    float last_cut_share() const;
    // Sessions that estimate motion: the gain the last submit's motion estimation applied to the
    // previous frame's luma for a change of the whole frame's brightness (a fade, a flash;
    // shaders/luma.h), 1 where none was measured or it was within LUMA_GAIN_GATE of 1. Negative
    // where no pair was estimated (the first frame, a reset, a session with given vectors
    // that it does not correct: Params::correct_vectors).
    float last_lighting_gain() const;
    // The last submit's noise estimate (Params::denoise; zeros without it).
    NoiseEstimate last_noise_estimate() const;
    // The aliasing measure of the input's first frames (fgsr/engine/color.hpp, aliasing_ratio):
    // below defaults::antialiased_aliasing WarpKernel::automatic takes the cubic in interpolation,
    // and in super-resolution sessions without jitter Params::sr_disagree applies; at or above it
    // SrSpatial::automatic takes the B-spline. Negative before the first frame, and in sessions
    // that decide nothing by it (no super resolution, and a fixed warp kernel or no client vectors).
    float input_aliasing() const;
    // Whether some frame so far carried jitter.
    bool input_jittered() const;
    // TILE_* flags of the last submit's super-resolution classification (empty when it was not
    // classified: no history, or Params::skip_tiles off), tiles of tile_side() pixels.
    std::vector<uint32_t> last_sr_tile_flags() const;
    // The tile side in use (Params::tile_size or the default).
    uint32_t tile_side() const;
    // Output size: the frame size times Params::scale (the frame size without super resolution).
    uint32_t output_width() const;
    uint32_t output_height() const;
    // The super-resolved (output-size) frame of the last submit, with the timing of its `sr` pass
    // (time = 1). Needs Params::scale > 1 and a submitted frame.
    Result<GeneratedFrame> super_resolved();

    // Frames between frame 0 and frame 1 at each alpha in (0, 1), in one GPU submission. With
    // super resolution they are output-sized (Ours-ISR / Ours-ESR, always the fused pass).
    Result<std::vector<GeneratedFrame>> interpolate(std::span<const float> alphas);
    // Frames after frame 1 at 1 + alpha for each alpha in (0, 1].
    Result<std::vector<GeneratedFrame>> extrapolate(std::span<const float> alphas);

    // Test and diagnostics access: the internal frames and the intermediate buffers of the last
    // generated frame (the last alpha of the last call). Only the keys exist after a fused call;
    // the other vectors are filled when Params::separate_passes was set.
    struct Intermediates {
        // With Params::skip_tiles, static tiles hold only what moving tiles splatted there (their
        // own keys and zero vectors are implied, shaders/tiles.h).
        std::vector<uint64_t> keys;
        std::vector<float> motion; // 4 per frame-1 pixel: m1.xy, m0.xy, its motion (see ref::Splat)
        std::vector<float> field;  // 4 per pixel: v0.xy, v1.xy
        std::vector<float> field_depth;
        std::vector<uint32_t> field_state;
        std::vector<float> warped_color0, warped_color1; // 4 per pixel
        std::vector<float> warped_depth0, warped_depth1;
        // TILE_* flags (shaders/common.h) per tile, row-major, of the last generated frame when it
        // was classified (Params::skip_tiles); empty otherwise. Tile side: tile_side.
        std::vector<uint32_t> tile_flags;
        uint32_t tile_side = 0;
        // Params::colour_agree, after a call whose last frame the agree pass made: the
        // colour-only twin's intermediates (its field, warped frames). The warped frames above are the given
        // field's; the frame returned is the agree pass's.
        std::shared_ptr<Intermediates> colour;
    };
    Result<Intermediates> read_intermediates() const;
    struct InternalFrameData {
        std::vector<float> color; // 4 per pixel (the stored halves, unpacked)
        std::vector<float> depth;
        std::vector<float> mv; // 2 per pixel
        bool has_mv = false;
    };
    // which = 1: newest frame, 0: the one before.
    Result<InternalFrameData> read_frame(int which) const;

    struct Impl;

  private:
    friend class Engine;
    explicit Session(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace fgsr
