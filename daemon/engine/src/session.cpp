// Session orchestration: creating a session (checks, buffers), the accessors, and submitting a
// frame (validation, upload or zero-copy ranges, ingest, then denoise and sr, their timings).
// Generated frames are generate.cpp's; the passes' parts are in sr.cpp, denoise.cpp, tiles.cpp.
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/params.hpp>

#include "session.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

namespace fgsr {

Session::Impl::~Impl() {
    if (ctx) {
        std::lock_guard lock(ctx->queue_mutex);
        vkDeviceWaitIdle(ctx->device);
    }
}

Result<void> Session::Impl::init() {
    FGSR_TRY(rec.init(*ctx, engine->pipelines, engine->group, kMaxAlphas * kSetsPerFrame + 4,
                      kMaxAlphas * kQueriesPerFrame));
    const VkDeviceSize px = n;
    auto make = [&](vk::Buffer& b, VkDeviceSize bytes, bool host) -> Result<void> {
        auto r = vk::Buffer::create(*ctx, bytes, host);
        if (!r) return r.error();
        b = std::move(*r);
        return {};
    };
    FGSR_TRY(make(color_raw, px * bytes_per_pixel(format.color_format), true));
    FGSR_TRY(make(depth_raw, px * 4, true));
    FGSR_TRY(make(mv_raw, px * bytes_per_pixel(format.mv_format), true));
    const VkDeviceSize tile = 1u << FGSR_BRIGHT_TILE_SHIFT;
    FGSR_TRY(make(bright, (format.width + tile - 1) / tile * ((format.height + tile - 1) / tile) * 4, false));
    if (format.has_vectors)
        FGSR_TRY(make(cut_blocks, VkDeviceSize(ref::cut_blocks(format.width, format.height)) * sizeof(ref::CutBlock),
                      true));
    for (GpuFrame& f : frames) {
        FGSR_TRY(make(f.color, px * 8, false)); // pack_color: 4 halves
        FGSR_TRY(make(f.depth, px * 4, false));
        FGSR_TRY(make(f.mv, px * 8, false));
    }
    // Slices of 32-element multiples: every slice offset is 256-byte aligned (storage buffer offsets).
    splat_stride = uint32_t((px + 31) / 32 * 32);
    FGSR_TRY(ensure_splat_slices(1));
    FGSR_TRY(make(field, px * 16, false));
    FGSR_TRY(make(field_depth, px * 4, false));
    FGSR_TRY(make(field_state, px * 4, false));
    FGSR_TRY(make(warped_color0, px * 16, false));
    FGSR_TRY(make(warped_depth0, px * 4, false));
    FGSR_TRY(make(warped_color1, px * 16, false));
    FGSR_TRY(make(warped_depth1, px * 4, false));
    if (sr()) {
        const VkDeviceSize hpx = VkDeviceSize(out_w) * out_h;
        for (vk::Buffer& b : sr_history.hr) FGSR_TRY(make(b, hpx * 16, false));
        FGSR_TRY(make(sr_history.lut, kLutSize * 4, true));
        // Whatever Params::sr_noise_* say now (8 bytes an input pixel): set_params may turn them on.
        FGSR_TRY(make(sr_history.noise, px * 8, false));
        FGSR_TRY(upload_lut());
        // Whatever Params::denoise says now: set_params may turn it on later.
        FGSR_TRY(make(denoiser.scratch, px * 8, false));
        FGSR_TRY(make(denoiser.noise, DENOISE_WORDS * 4, true));
    }
    if (estimates_motion()) FGSR_TRY(init_motion());
    return {};
}

Result<std::unique_ptr<Session>> Engine::create_session(const FrameFormat& format, const Params& params) {
    // Validate the format with an empty frame view of the right sizes.
    const size_t n = size_t(format.width) * format.height;
    if (n == 0)
        return make_error(Errc::empty_input, "session frame size is " + std::to_string(format.width) + "x" +
                                                 std::to_string(format.height));
    FGSR_TRY(params::validate_formats(format));
    auto impl = std::make_unique<Session::Impl>();
    impl->engine = impl_.get();
    impl->ctx = impl_->ctx.get();
    impl->format = format;
    impl->params = params;
    impl->n = n;
    FGSR_TRY(validate(params));
    impl->out_w = uint32_t(std::lround(double(format.width) * params.scale));
    impl->out_h = uint32_t(std::lround(double(format.height) * params.scale));
    if (impl->out_w > kMaxFrameSide || impl->out_h > kMaxFrameSide)
        return make_error(Errc::invalid_argument, "output size " + std::to_string(impl->out_w) + "x" +
                                                      std::to_string(impl->out_h) + " exceeds " +
                                                      std::to_string(kMaxFrameSide) + "x" +
                                                      std::to_string(kMaxFrameSide));
    if (params.tile_size != 0 && params.tile_size != 8 && params.tile_size != 16 && params.tile_size != 32)
        return make_error(Errc::invalid_argument,
                          "tile size " + std::to_string(params.tile_size) + " is not 0, 8, 16 or 32");
    // A view with planes of exactly the right size validates conventions and limits.
    std::vector<std::byte> c(n * bytes_per_pixel(format.color_format)), d(n * 4);
    FGSR_TRY(params::validate(format, FrameView{c, d, {}}));
    FGSR_TRY(impl->init());
    // Sessions without vectors estimate their own motion: colour_agree is off there (as
    // correct_vectors is), so that one Params serves every kind of session (fgsr eval's methods).
    impl->params.colour_agree = colour_agree_applies(format, params);
    if (impl->params.colour_agree) {
        // The twin: the same frames without vectors or depth, at the same scale (interpolating
        // with separate passes: the agree pass reads its warped frames).
        FrameFormat colour_format = format;
        colour_format.has_vectors = false;
        colour_format.has_depth = false;
        auto twin = create_session(colour_format, Session::Impl::twin_params(params));
        if (!twin) return twin.error();
        impl->colour_twin = std::move(*twin);
    }
    return std::unique_ptr<Session>(new Session(std::move(impl)));
}

Session::Session(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Session::~Session() = default;
const FrameFormat& Session::format() const {
    return impl_->format;
}
const Params& Session::params() const {
    return impl_->params;
}
void Session::set_params(const Params& p) {
    // The scale (and so every buffer size) is fixed at creation.
    const float scale = impl_->params.scale;
    Params checked = p;
    checked.scale = scale;
    checked.colour_agree = impl_->agrees();
    if (!validate(checked)) return;
    const bool lut_changed = p.lut != impl_->params.lut;
    impl_->params = p;
    impl_->params.scale = scale;
    impl_->params.colour_agree = impl_->agrees();
    if (p.tile_size != 8 && p.tile_size != 16 && p.tile_size != 32) impl_->params.tile_size = 0;
    if (lut_changed && impl_->sr()) (void)impl_->upload_lut();
    if (impl_->agrees()) impl_->colour_twin->set_params(Session::Impl::twin_params(impl_->params));
}
uint32_t Session::output_width() const {
    return impl_->out_w;
}
uint32_t Session::output_height() const {
    return impl_->out_h;
}
uint64_t Session::frames_submitted() const {
    return impl_->submitted;
}
float Session::input_aliasing() const {
    return aliasing_ratio(impl_->input_aliasing);
}
bool Session::input_jittered() const {
    return impl_->input_jittered;
}
NoiseEstimate Session::last_noise_estimate() const {
    return impl_->denoiser.estimate;
}
double Session::last_ingest_ms() const {
    return impl_->ingest_timing.ms;
}
PassTiming Session::last_ingest_timing() const {
    return impl_->ingest_timing;
}
uint32_t Session::tile_side() const {
    return impl_->tile_side();
}

void Session::reset() {
    if (impl_->agrees()) impl_->colour_twin->reset();
    impl_->submitted = 0;
    impl_->sr_history.valid = false;
    impl_->reset_pending = true;
    for (auto& f : impl_->frames) f.has_mv = false;
}

// Params::colour_agree: the twin sees the frame's colour, neither its vectors nor its depth.
static Result<void> submit_to_twin(Session::Impl& s, const FrameView& frame) {
    if (!s.agreeing()) return {};
    FrameView colour = frame;
    colour.depth = {};
    colour.mv = {};
    return s.colour_twin->submit(colour);
}

Result<void> Session::submit(const FrameView& frame) {
    FGSR_TRY(impl_->submit(frame, nullptr));
    return submit_to_twin(*impl_, frame);
}

Result<void> Session::submit(const FrameView& frame, const HostMemory& memory) {
    FGSR_TRY(impl_->submit(frame, &memory));
    return submit_to_twin(*impl_, frame);
}

Result<void> Session::Impl::submit(const FrameView& frame, const HostMemory* memory) {
    Impl& s = *this;
    FGSR_TRY(params::validate(s.format, frame));
    const bool has_mv = s.format.has_vectors && !frame.mv.empty();
    const bool has_depth = s.format.has_depth;
    // The raw planes ingest reads: the session's upload buffers, or (zero copy) ranges of the
    // imported memory, where they must lie at offsets the device can bind.
    BufRef color_in = s.color_raw, depth_in = s.depth_raw, mv_in = s.mv_raw;
    if (memory) {
        const std::byte* base = memory->data();
        const VkDeviceSize align =
            std::max<VkDeviceSize>(ctx->props.limits.minStorageBufferOffsetAlignment, 4);
        auto range = [&](std::span<const std::byte> plane, const char* what, BufRef& out) -> Result<void> {
            if (plane.data() < base || plane.data() + plane.size() > base + memory->size())
                return make_error(Errc::invalid_argument,
                                  std::string(what) + " plane lies outside the imported host memory");
            const VkDeviceSize offset = VkDeviceSize(plane.data() - base);
            if (offset % align != 0)
                return make_error(Errc::invalid_argument,
                                  std::string(what) + " plane offset " + std::to_string(offset) +
                                      " is not a multiple of " + std::to_string(align));
            out = BufRef(memory->impl()->buffer.handle(), offset, plane.size());
            return {};
        };
        FGSR_TRY(range(frame.color, "colour", color_in));
        if (has_depth)
            FGSR_TRY(range(frame.depth, "depth", depth_in));
        else
            depth_in = unused(color_in); // no depth: has_depth 0, not read
        if (has_mv)
            FGSR_TRY(range(frame.mv, "motion-vector", mv_in));
        else
            mv_in = unused(color_in); // no vectors: has_mv 0, not read
    } else {
        std::memcpy(s.color_raw.mapped(), frame.color.data(), frame.color.size());
        if (has_depth) std::memcpy(s.depth_raw.mapped(), frame.depth.data(), frame.depth.size());
        if (has_mv) std::memcpy(s.mv_raw.mapped(), frame.mv.data(), frame.mv.size());
    }
    if (!std::isfinite(frame.jitter_x) || !std::isfinite(frame.jitter_y) || std::abs(frame.jitter_x) > 1.f ||
        std::abs(frame.jitter_y) > 1.f)
        return make_error(Errc::invalid_argument, "jitter (" + std::to_string(frame.jitter_x) + ", " +
                                                      std::to_string(frame.jitter_y) +
                                                      ") is outside [-1, 1] pixels");
    // An announced cut: FrameView::reset, or Session::reset() before this frame.
    const bool announced_cut = frame.reset || s.reset_pending;
    bool restart = announced_cut || s.submitted == 0;
    const int slot = 1 - s.newest;
    GpuFrame& f = s.frames[size_t(slot)];
    const GpuFrame& prev = s.frames[size_t(s.newest)];
    gpu::IngestParams p = params::ingest_params(s.format, has_mv);
    if (s.params.mvs_contain_jitter && !restart) {
        p.mv_offset_x = s.jitter_x - frame.jitter_x;
        p.mv_offset_y = s.jitter_y - frame.jitter_y;
    }
    const auto b = make_slots<PassId::ingest>(at<INGEST_COLOR_RAW>(color_in), at<INGEST_DEPTH_RAW>(depth_in),
                                              at<INGEST_MV_RAW>(mv_in), at<INGEST_COLOR>(f.color),
                                              at<INGEST_DEPTH>(f.depth), at<INGEST_MV>(f.mv),
                                              at<INGEST_BRIGHT>(s.bright), at<INGEST_PREV_COLOR>(prev.color),
                                              at<INGEST_CUT>(s.cut_blocks.handle() ? BufRef(s.cut_blocks) : unused(color_in)));
    // The dilate stage (shaders/dilate.h): with the client's vectors and depth; its edge rule reads
    // the previous frame's colour. The correction of given vectors (flow.h step 4) then works on
    // the dilated ones.
    params::set_dilate(p, s.format, s.params, !restart);
    FGSR_TRY(s.rec.begin());
    // Timestamps: 0, after ingest (and its dilate stage), [after denoise], [after classify], after sr.
    uint32_t q = 0;
    s.rec.timestamp(q++);
    if (p.bright > 0.f && !s.bright_clear) {
        vkCmdFillBuffer(s.rec.cmd(), s.bright.handle(), 0, VK_WHOLE_SIZE, 0u);
        s.rec.barrier();
        s.bright_clear = true;
    }
    const bool denoise = s.denoise();
    // The build for the session's formats (shaders/ingest.comp); the generic ingest serves the same.
    constexpr std::array<std::array<Variant, 2>, 3> kIngestFormats = {{
        {Variant::ingest_c0_m0, Variant::ingest_c0_m1},
        {Variant::ingest_c1_m0, Variant::ingest_c1_m1},
        {Variant::ingest_c2_m0, Variant::ingest_c2_m1},
    }};
    constexpr std::array<Variant, 3> kIngestColourOnly = {
        Variant::ingest_c0_colour, Variant::ingest_c1_colour, Variant::ingest_c2_colour};
    const bool fixed = p.color_format < kIngestFormats.size() && p.mv_format < kIngestFormats[0].size();
    // Without vectors and depth, ingest stores the colour alone: flow writes the vectors and the
    // depth proxy, and where flow does not run they are filled below (shaders/ingest.comp).
    const bool colour_only = fixed && s.colour_only();
    const Variant ingest = colour_only ? kIngestColourOnly[p.color_format]
                           : fixed     ? kIngestFormats[p.color_format][p.mv_format]
                                       : Variant::ingest;
    const uint32_t span = fixed && s.rec.group() == 32 ? FGSR_INGEST_SPAN_CPU : 1u;
    FGSR_TRY(s.rec.dispatch_pixels(ingest, b, &p, groups(s.format.width, span), s.format.height));
    s.rec.barrier();
    if (p.bright > 0.f || p.edge_ratio > 0.f) {
        // One invocation per 16x16 tile (shaders/dilate.comp): the edge rule's build runs both rules.
        const uint32_t side = 1u << FGSR_BRIGHT_TILE_SHIFT;
        const uint32_t tiles_x = (s.format.width + side - 1) / side, tiles_y = (s.format.height + side - 1) / side;
        if (!(p.edge_ratio > 0.f)) {
            FGSR_TRY(s.rec.dispatch_pixels(Variant::ingest_dilate, b, &p, tiles_x, tiles_y));
        } else {
            const Variant v = p.depth_kind == uint32_t(DepthKind::linear) ? Variant::ingest_dilate_edges_linear
                                                                          : Variant::ingest_dilate_edges;
            FGSR_TRY(s.rec.dispatch(v, b, &p, (tiles_x + FGSR_DILATE_EDGES_GROUP_X - 1) / FGSR_DILATE_EDGES_GROUP_X,
                                    (tiles_y + FGSR_DILATE_EDGES_GROUP_Y - 1) / FGSR_DILATE_EDGES_GROUP_Y));
        }
        s.rec.barrier();
    }
    // With vectors: the cut stage (shaders/cut.h, Params::vector_cuts) ends a first command buffer;
    // the host reads its blocks and, on a cut, starts the session afresh before the SR pass, as
    // FrameView::reset would have. The denoise pass filters a frame's colour in place, so in
    // sessions that filter it runs first, and the stage compares the filtered frame with the
    // filtered previous one (unfiltered against filtered, the filter alone left half the blocks of
    // a static stretch of orbit-sr without a match). The stage is timed with ingest (its ms added).
    // (Sessions with vectors have their cut_blocks buffer.) Sessions that correct the client's
    // vectors run it too: their block matching's cut test only skips the correction, and without
    // the stage they carried vectors across cuts (cut-fg -0.84 / -1.21 dB with the correction;
    // docs/ACCURACY.md, change 27).
    const bool checks_cut =
        s.params.vector_cuts && has_mv && !restart && (!s.estimates_motion() || s.correction().on);
    s.rec.timestamp(q++);
    // Without vectors (motion.cpp): the pyramid, then against the previous frame matching in a
    // first command buffer, the host's summary (dominant motion, scene cut), and the per-pixel
    // vectors at the start of the second one. Timings gathered per command buffer.
    std::vector<PassTiming> first_times;
    PassTiming cut_ingest{}; // ingest with the cut stage, where the motion chain's times follow
    bool vector_cut = false;
    s.last_cut_share = -1.f;
    s.last_lighting_gain = -1.f;
    if (checks_cut) {
        if (denoise) {
            FGSR_TRY(s.record_denoise(f.color));
            s.rec.barrier();
            s.rec.timestamp(q++);
        }
        // One invocation per 8x8 block (cut.comp's small workgroups, as the edge rule's).
        const glm::uvec2 blocks = ref::cut_grid(s.format.width, s.format.height);
        FGSR_TRY(s.rec.dispatch(Variant::ingest_cut, b, &p,
                                (blocks.x + FGSR_DILATE_EDGES_GROUP_X - 1) / FGSR_DILATE_EDGES_GROUP_X,
                                (blocks.y + FGSR_DILATE_EDGES_GROUP_Y - 1) / FGSR_DILATE_EDGES_GROUP_Y));
        s.rec.barrier(); // also makes the blocks visible to the host
        s.rec.timestamp(q++);
        FGSR_TRY(s.rec.finish(true));
        auto t1 = s.rec.read_times(0, q - 1);
        if (!t1) return t1.error();
        first_times = std::move(*t1);
        cut_ingest = timing_of(PassId::ingest, first_times[0]);
        cut_ingest.ms += first_times.back().ms; // the cut stage
        const float share = ref::cut_share({static_cast<const ref::CutBlock*>(s.cut_blocks.mapped()),
                                            ref::cut_blocks(s.format.width, s.format.height)});
        // ref::is_vector_cut. The session's first comparison only sets the typical share: aliased,
        // point-sampled input (jittered or not) leaves 0.5-0.99 of its blocks without a match at
        // every frame (orbit-sr, street-sr, rotor-sr), so an absolute threshold would cut its second
        // frame.
        vector_cut = ref::is_vector_cut(share, s.cut_typical_share);
        s.last_cut_share = share;
        s.cut_typical_share = ref::update_typical_share(s.cut_typical_share, share, vector_cut);
        restart = restart || vector_cut;
        FGSR_TRY(s.rec.begin());
        q = 0;
        s.rec.timestamp(q++);
    }
    // With Params::correct_vectors the same chain corrects the client's vectors: a cut its block
    // matching detects only skips the correction; the cut stage above restarts the session, as
    // where nothing is corrected (with Params::vector_cuts). A frame that starts the
    // session afresh at a cut, announced (FrameView::reset) or detected, keeps no vectors: they
    // point into the shot before it, and the next pair would read them as frame-0 motion. (A
    // session's first frame keeps its own: the stream it describes goes on.)
    bool frame_has_mv = has_mv && !vector_cut && !announced_cut;
    const bool correcting = s.correction().on;
    bool flow_skipped = false;
    // The refinement (both its coarse levels and level 0) fits the colour: on jittered frames that
    // is their aliasing, different every frame (measured on the train captures: SR sessions' ISR /
    // ESR -0.01 to -0.06 dB with level 0 alone; orbit-sr's interpolation -0.19 with the coarse
    // levels; docs/MOTION.md, "Variational refinement", "Coarse to fine"), as the correction of given
    // vectors is refused there. Nor above ref::kPolishMaxPixels, for time, nor when the session
    // asked for fast motion estimation (Params::fast_motion).
    // With the patch inverse search (Params::motion_search) the coarse levels are refined at any
    // size; level 0 only up to ref::kPolishMaxPixels.
    const bool refines =
        !correcting && !s.params.fast_motion && frame.jitter_x == 0.f && frame.jitter_y == 0.f;
    const bool polishing = refines && ref::polishes(s.format.width, s.format.height);
    const bool coarse = refines && (polishing || s.params.motion_search);
    s.estimator.timings.clear();
    s.estimator.last_cut = vector_cut;
    if (s.estimates_motion()) {
        FGSR_TRY(s.record_luma(slot));
        s.rec.barrier();
        if (!restart) { // timed with luma
            FGSR_TRY(s.record_luma_gain(slot, s.newest));
            s.rec.barrier();
        }
        s.rec.timestamp(q++);
        if (!restart) {
            // The light cap only on unjittered frames: on jittered ones a block's aliasing changes
            // every frame and its mean is what holds (docs/MOTION.md, "Local changes of brightness").
            FGSR_TRY(s.record_match(slot, s.newest, frame.jitter_x == 0.f && frame.jitter_y == 0.f));
            s.rec.timestamp(q++);
        }
        FGSR_TRY(s.rec.finish(true));
        auto t1 = s.rec.read_times(0, q - 1);
        if (!t1) return t1.error();
        first_times = std::move(*t1);
        // After the cut stage's command buffer the motion chain's starts at luma, else at ingest.
        const size_t luma_at = checks_cut ? 0 : 1;
        s.estimator.timings.push_back(timing_of(PassId::luma, first_times[luma_at]));
        if (!restart) {
            s.last_lighting_gain = static_cast<const float*>(s.estimator.gain.mapped())[0];
            s.estimator.timings.push_back(timing_of(PassId::match, first_times[luma_at + 1]));
            ref::MotionSummary summary = s.summarise_motion(false);
            if (summary.cut) {
                // Before it counts as a cut: is it a change of the whole frame's lighting? The
                // blocks relit (ref::summarise_motion, shaders/cut.h), in a command buffer of its
                // own, only on such frames.
                FGSR_TRY(s.rec.begin());
                FGSR_TRY(s.record_cut_match(slot, s.newest));
                FGSR_TRY(s.rec.finish());
                summary = s.summarise_motion(true);
            }
            s.estimator.last_cut = summary.cut;
            s.estimator.global = summary.global;
            s.last_cut_share = summary.mismatch_share;
            if (correcting)
                flow_skipped = summary.cut || !has_mv;
            else
                restart = summary.cut;
            s.estimator.typical_share =
                ref::update_typical_share(s.estimator.typical_share, summary.mismatch_share, summary.cut);
        }
        FGSR_TRY(s.rec.begin());
        q = 0;
        s.rec.timestamp(q++);
        flow_skipped = flow_skipped || restart;
        if (flow_skipped && colour_only) {
            // What ingest would have stored: no motion, depth 1 (the frame is a new start).
            vkCmdFillBuffer(s.rec.cmd(), f.mv.handle(), 0, VK_WHOLE_SIZE, 0u);
            vkCmdFillBuffer(s.rec.cmd(), f.depth.handle(), 0, VK_WHOLE_SIZE, std::bit_cast<uint32_t>(1.0f));
            s.rec.barrier();
        }
        if (!flow_skipped) {
            // The coarse levels' refinement, which flow reads, is timed with the other sweeps.
            if (coarse) {
                FGSR_TRY(s.record_polish_coarse(slot, s.newest, s.params.motion_search, polishing));
                s.rec.timestamp(q++);
            }
            FGSR_TRY(s.record_flow(slot, s.newest, s.estimator.global, coarse));
            s.rec.barrier();
            s.rec.timestamp(q++);
            if (polishing) {
                FGSR_TRY(s.record_polish(slot, s.newest));
                s.rec.barrier();
                s.rec.timestamp(q++);
            }
        }
        if (!correcting) frame_has_mv = !restart;
        s.estimator.field_valid = !restart && !s.estimator.last_cut;
    }
    // What restarted the session: block matching's cut in colour-only sessions, the cut stage's in
    // sessions with vectors (a cut block matching finds there only skips the correction).
    s.last_scene_cut = s.estimates_motion() && !correcting ? s.estimator.last_cut : vector_cut;
    if (denoise && !checks_cut) {
        FGSR_TRY(s.record_denoise(f.color));
        s.rec.barrier();
        s.rec.timestamp(q++);
    }
    // The input's aliasing, measured on the host from the client's colour over the first frames
    // where something decides by it (super resolution; WarpKernel::automatic with the client's
    // vectors): strips of 4 rows, 16 rows apart up to 540 rows and about 32 strips above (1.3-1.8
    // ms a frame at 960x540 on the 2-core VM, busy).
    if (frame.jitter_x != 0.f || frame.jitter_y != 0.f) s.input_jittered = true;
    const bool measures = s.sr() || (s.params.warp_kernel == WarpKernel::automatic && s.format.has_vectors);
    if (measures && s.input_aliasing.frames < defaults::aliasing_frames)
        s.input_aliasing += aliasing_sums(s.format.width, s.format.height, s.format.color_format, frame.color,
                                          std::max(16u, (s.format.height / 32u) & ~3u));
    bool sr_tiled = false;
    if (s.sr()) {
        const gpu::SrParams sp =
            params::sr_params(s.format, s.params, s.out_w, s.out_h, frame.jitter_x, frame.jitter_y,
                              !restart && s.sr_history.valid && frame_has_mv, s.input_measure());
        auto tiled = s.record_sr(sp, f, prev, q);
        if (!tiled) return tiled.error();
        sr_tiled = *tiled;
    }
    FGSR_TRY(s.rec.finish(true));
    auto t = s.rec.read_times(0, q - 1);
    if (!t) return t.error();
    size_t ti = 0;
    if (s.estimates_motion()) {
        s.ingest_timing = checks_cut ? cut_ingest : timing_of(PassId::ingest, first_times[0]);
        const bool coarse_ran = !flow_skipped && coarse;
        const PassTiming coarse_time = coarse_ran ? timing_of(PassId::polish, (*t)[ti++]) : PassTiming{};
        if (!flow_skipped) s.estimator.timings.push_back(timing_of(PassId::flow, (*t)[ti++]));
        if (coarse_ran && polishing) {
            // One entry for both parts: its ms is their sum, its begin and end the level-0 sweeps'.
            PassTiming sweeps = timing_of(PassId::polish, (*t)[ti++]);
            sweeps.ms += coarse_time.ms;
            s.estimator.timings.push_back(sweeps);
        } else if (coarse_ran) {
            s.estimator.timings.push_back(coarse_time);
        }
    } else if (checks_cut) {
        s.ingest_timing = cut_ingest;
    } else {
        s.ingest_timing = timing_of(PassId::ingest, (*t)[ti++]);
    }
    s.denoiser.estimate = NoiseEstimate{};
    if (denoise) {
        s.denoiser.timing = timing_of(PassId::denoise, checks_cut ? first_times[1] : (*t)[ti++]);
        s.read_noise_estimate();
    }
    s.tiles.last_sr_tiled = sr_tiled;
    s.tiles.classify_sr_timing = timing_of(PassId::classify, sr_tiled ? (*t)[ti++] : PassTiming{});
    if (sr_tiled) s.count_sr_tiles();
    f.has_mv = frame_has_mv;
    s.newest = slot;
    s.jitter_x = frame.jitter_x;
    s.jitter_y = frame.jitter_y;
    if (restart) s.submitted = 0;
    ++s.submitted;
    s.reset_pending = false;
    if (s.sr()) s.finish_sr((*t)[ti]);
    return {};
}

Result<Session::InternalFrameData> Session::read_frame(int which) const {
    Impl& s = *impl_;
    if (which != 0 && which != 1) return make_error(Errc::invalid_argument, "frame index must be 0 or 1");
    const Impl::GpuFrame& f = s.frames[size_t(which == 1 ? s.newest : 1 - s.newest)];
    InternalFrameData out;
    auto c = s.rec.download<uint32_t>(f.color, s.n * 2); // pack_color
    if (!c) return c.error();
    auto d = s.rec.download<float>(f.depth, s.n);
    if (!d) return d.error();
    auto m = s.rec.download<float>(f.mv, s.n * 2);
    if (!m) return m.error();
    out.color.resize(s.n * 4);
    for (size_t i = 0; i < s.n; ++i) {
        const glm::vec4 v = gpu::unpack_color(glm::uvec2((*c)[2 * i], (*c)[2 * i + 1]));
        for (int k = 0; k < 4; ++k) out.color[4 * i + size_t(k)] = v[k];
    }
    out.depth = std::move(*d);
    out.mv = std::move(*m);
    out.has_mv = f.has_mv;
    return out;
}

} // namespace fgsr
