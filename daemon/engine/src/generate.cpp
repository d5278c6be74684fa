// Generated frames: recording interpolation and extrapolation (splat, then the fused generate
// pass, generate_sr with super resolution, or the separate passes; tile-skipping forms are
// tiles.cpp's), an agreeing session's interpolation and extrapolation (Params::colour_agree: the
// given field's and the colour-only twin's frames, then the agree pass), and assembling the results: frames,
// pass timings, intermediates.
#include <fgsr/engine/params.hpp>

#include "session.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace fgsr {
namespace {
// Invocations along a row or column of `pixels` in the agree pass's box stages (one per segment).
uint32_t agree_segments(uint32_t pixels) {
    return (pixels + AGREE_SEGMENT - 1) / AGREE_SEGMENT;
}
} // namespace

Result<void> Session::Impl::ensure_outputs(size_t count) {
    while (outputs.size() < count) {
        auto r = vk::Buffer::create(*ctx, VkDeviceSize(out_w) * out_h * 16, true);
        if (!r) return r.error();
        outputs.push_back(std::move(*r));
    }
    return {};
}

Result<void> Session::Impl::ensure_splat_slices(uint32_t count) {
    if (!motion.handle()) {
        auto r = vk::Buffer::create(*ctx, VkDeviceSize(n) * 16, false); // (m1, m0) per source
        if (!r) return r.error();
        motion = std::move(*r);
    }
    if (splat_slices >= count) return {};
    auto r = vk::Buffer::create(*ctx, VkDeviceSize(splat_stride) * count * 8, false);
    if (!r) return r.error();
    keys = std::move(*r);
    splat_slices = count;
    return {};
}

gpu::SplatParams Session::Impl::splat_params(const gpu::GenParams& g, std::span<const float> alphas) const {
    gpu::SplatParams sp{};
    sp.g = g;
    sp.count = uint32_t(alphas.size());
    sp.stride = splat_stride;
    float* a[FGSR_SPLAT_ALPHAS] = {&sp.alpha0, &sp.alpha1, &sp.alpha2, &sp.alpha3};
    for (size_t k = 0; k < alphas.size() && k < FGSR_SPLAT_ALPHAS; ++k) *a[k] = alphas[k];
    return sp;
}

Result<void> Session::Impl::record_refine(uint32_t slice, const gpu::GenParams& g) {
    const auto b =
        make_slots<PassId::refine>(generated_frames(slice), at<REFINE_FIELD>(field),
                                   at<REFINE_FIELD_DEPTH>(field_depth), at<REFINE_FIELD_STATE>(field_state));
    FGSR_TRY(rec.dispatch_pixels(Variant::refine, b, &g, format.width, format.height));
    rec.barrier();
    return {};
}

Result<void> Session::Impl::record_disocc(uint32_t slice, const gpu::GenParams& g) {
    const auto b = make_slots<PassId::disocc>(generated_frames(slice), at<DISOCC_FIELD>(field),
                                              at<DISOCC_FIELD_DEPTH>(field_depth),
                                              at<DISOCC_FIELD_STATE>(field_state),
                                              at<DISOCC_COLOR1>(frames[size_t(newest)].color));
    FGSR_TRY(rec.dispatch_pixels(Variant::disocc, b, &g, format.width, format.height));
    rec.barrier();
    return {};
}

Result<void> Session::Impl::record_field(uint32_t slice, const gpu::GenParams& g) {
    FGSR_TRY(record_refine(slice, g));
    if (params.fill_holes) FGSR_TRY(record_disocc(slice, g));
    return {};
}

Variant Session::Impl::splat_variant(const gpu::GenParams& g, size_t count, bool tiled) {
    static_assert(FGSR_SPLAT_ALPHAS == 4);
    const bool lookup = g.quadratic != 0u && g.frame0_has_mv != 0u;
    if (tiled) return lookup ? Variant::splat_tiled : Variant::splat_tiled_linear;
    switch (count) {
    case 1:
        return lookup ? Variant::splat : Variant::splat_linear;
    case 2:
        return lookup ? Variant::splat_x2 : Variant::splat_x2_linear;
    case 3:
        return lookup ? Variant::splat_x3 : Variant::splat_x3_linear;
    default:
        return lookup ? Variant::splat_x4 : Variant::splat_x4_linear;
    }
}

Result<void> Session::Impl::check_generate(std::span<const float> alphas, bool extrapolate) const {
    if (submitted < 2)
        return make_error(Errc::empty_input, std::string(extrapolate ? "extrapolation" : "interpolation") +
                                                 " needs two submitted frames, the session has " +
                                                 std::to_string(submitted));
    if (alphas.empty()) return make_error(Errc::invalid_argument, "no alpha requested");
    if (alphas.size() > kMaxAlphas)
        return make_error(Errc::invalid_argument, std::to_string(alphas.size()) +
                                                      " alphas requested, at most " +
                                                      std::to_string(kMaxAlphas) + " per call");
    for (float a : alphas) {
        bool ok = extrapolate ? (a > 0.f && a <= 1.f) : (a > 0.f && a < 1.f);
        if (!std::isfinite(a) || !ok)
            return make_error(Errc::invalid_argument,
                              "alpha " + std::to_string(a) + " is outside " +
                                  (extrapolate ? "(0, 1] for extrapolation" : "(0, 1) for interpolation"));
    }
    return {};
}

Result<std::vector<GeneratedFrame>> Session::Impl::generate(std::span<const float> alphas, bool extrapolate) {
    FGSR_TRY(check_generate(alphas, extrapolate));
    last_agreed = false;
    // Extrapolation, and interpolation with super resolution (generate_sr makes no warped frames at
    // the input's size for stage 1 to compare), mix by the fields' residuals at the newest input.
    if (agreeing() && (extrapolate || sr())) return agree_by_residual(alphas, extrapolate);
    if (agreeing()) return generate_agreed(alphas);
    return generate_frames(alphas, extrapolate);
}

// After check_generate.
Result<std::vector<GeneratedFrame>> Session::Impl::generate_frames(std::span<const float> alphas,
                                                                   bool extrapolate) {
    FGSR_TRY(ensure_outputs(alphas.size()));
    const GenTiles tiling = classify_generate();
    const bool tiled = tiling == GenTiles::tiled;
    if (tiling != GenTiles::none) FGSR_TRY(ensure_tile_sets(tiled ? alphas.size() : 1));
    // Without tiles, one splat dispatch serves up to FGSR_SPLAT_ALPHAS frames (splat.h): frame k
    // reads slice k % FGSR_SPLAT_ALPHAS, and its chunk's first frame times the splat.
    const uint32_t chunk = tiled ? 1u : uint32_t(std::min<size_t>(alphas.size(), FGSR_SPLAT_ALPHAS));
    FGSR_TRY(ensure_splat_slices(chunk));
    const GpuFrame& f1 = frames[size_t(newest)];
    const GpuFrame& f0 = frames[size_t(1 - newest)];

    std::vector<std::vector<PassId>> timings(alphas.size()); // passes timed per generated frame, in order
    FGSR_TRY(rec.begin());
    for (size_t k = 0; k < alphas.size(); ++k) {
        gpu::GenParams g =
            params::gen_params(format, params, alphas[k], extrapolate, f0.has_mv, f1.has_mv, input_measure());
        if (sr()) g.fill_holes &= ~FGSR_FILL_HOLES_COVER; // generate_sr has no edge cover (disocc.h)
        const uint32_t q0 = uint32_t(k) * kQueriesPerFrame;
        uint32_t q = q0;
        const vk::Buffer& out = outputs[k];
        rec.timestamp(q++);
        if (tiled) {
            last_slice = 0;
            FGSR_TRY(record_tiled(k, g, extrapolate, q));
            timings[k] = {PassId::classify, PassId::splat, sr() ? PassId::generate_sr : PassId::generate};
            continue;
        }
        const uint32_t slice = uint32_t(k) % chunk;
        std::vector<PassId> splat_timing;
        if (k == 0 && tiling == GenTiles::probe) {
            FGSR_TRY(record_probe(g, q));
            splat_timing.push_back(PassId::classify);
        }
        if (slice == 0) {
            const size_t count = std::min<size_t>(chunk, alphas.size() - k);
            vkCmdFillBuffer(rec.cmd(), keys.handle(), 0, VkDeviceSize(splat_stride) * count * 8, 0xffffffffu);
            rec.barrier();
            const gpu::SplatParams sp = splat_params(g, alphas.subspan(k, count));
            const auto sb = make_slots<PassId::splat>(generated_frames(kAllSlices));
            FGSR_TRY(
                rec.dispatch_pixels(splat_variant(g, count, false), sb, &sp, format.width, format.height));
            rec.barrier();
            rec.timestamp(q++);
            splat_timing.push_back(PassId::splat);
        }
        last_slice = slice;
        auto with_splat = [&](std::initializer_list<PassId> after) {
            std::vector<PassId> t = splat_timing;
            t.insert(t.end(), after);
            return t;
        };
        if (sr()) { // joint ISR / ESR at output resolution
            const GenSrPush push = gen_sr_push(g);
            const auto gen = At<GENSR_COLOR0, GENSR_COLOR1, GENSR_SRC, GENSR_LUT, GENSR_OUTPUT>{
                {f0.color, f1.color, gen_sr_source(extrapolate), sr_history.lut, out}};
            if (rec.group() == 32) {
                // CPU devices: the field once per input pixel (refine, disocc), which generate_sr
                // then reads (shaders/generate_sr.comp, FGSR_SR_FIELD); the same frame.
                FGSR_TRY(record_field(slice, g));
                constexpr uint32_t base = GENSR_COUNT;
                using FieldSlots = At<base + TILED_LIST, base + TILED_FLAGS, base + TILED_APPEND>;
                FGSR_TRY(rec.dispatch_pixels(
                    extrapolate ? Variant::generate_sr_field_extrap : Variant::generate_sr_field,
                    make_slots<PassId::generate_sr, Layout::TILED>(
                        generated_frames(slice), gen, FieldSlots{{field, field_state, unused(field_depth)}}),
                    &push, out_w, out_h));
            } else {
                FGSR_TRY(rec.dispatch_pixels(Variant::generate_sr,
                                             make_slots<PassId::generate_sr>(generated_frames(slice), gen),
                                             &push, out_w, out_h));
            }
            rec.barrier();
            rec.timestamp(q++);
            timings[k] = with_splat({PassId::generate_sr});
            continue;
        }
        if (!separate() && rec.group() == 32) {
            // CPU devices: the split form (shaders/generate.h, generate_splatted), the splatted
            // pixels, then the list of the empty ones.
            FGSR_TRY(reset_gap_list(0));
            const auto gen_frames = generated_frames(slice);
            const auto colors = At<GENERATE_COLOR0, GENERATE_COLOR1, GENERATE_OUTPUT>{{f0.color, f1.color, out}};
            constexpr uint32_t base = GENERATE_COUNT;
            using ListSlots = At<base + TILED_LIST, base + TILED_FLAGS, base + TILED_APPEND>;
            FGSR_TRY(rec.dispatch_pixels(
                extrapolate ? Variant::generate_split_extrap : Variant::generate_split,
                make_slots<PassId::generate, Layout::TILED>(
                    gen_frames, colors, ListSlots{{unused(gap_list), unused(gap_list), gap_list}}),
                &g, format.width, format.height));
            rec.barrier();
            FGSR_TRY(rec.dispatch_indirect(
                extrapolate ? Variant::generate_rest_extrap : Variant::generate_rest,
                make_slots<PassId::generate, Layout::TILED>(
                    gen_frames, colors, ListSlots{{gap_list, unused(gap_list), unused(gap_list)}}),
                &g, gap_list));
            rec.barrier();
            rec.timestamp(q++);
            timings[k] = with_splat({PassId::generate});
            continue;
        }
        if (!separate()) {
            const auto b =
                make_slots<PassId::generate>(generated_frames(slice), at<GENERATE_COLOR0>(f0.color),
                                             at<GENERATE_COLOR1>(f1.color), at<GENERATE_OUTPUT>(out));
            FGSR_TRY(rec.dispatch_pixels(Variant::generate, b, &g, format.width, format.height));
            rec.barrier();
            rec.timestamp(q++);
            timings[k] = with_splat({PassId::generate});
            continue;
        }
        FGSR_TRY(record_refine(slice, g));
        rec.timestamp(q++);
        timings[k] = with_splat({PassId::refine});
        if (params.fill_holes) {
            FGSR_TRY(record_disocc(slice, g));
            rec.timestamp(q++);
            timings[k].push_back(PassId::disocc);
        }
        const auto wb = make_slots<PassId::warp>(
            at<WARP_FIELD>(field), at<WARP_COLOR0>(f0.color), at<WARP_COLOR1>(f1.color),
            at<WARP_DEPTH0>(f0.depth), at<WARP_DEPTH1>(f1.depth), at<WARP_OUT_COLOR0>(warped_color0),
            at<WARP_OUT_DEPTH0>(warped_depth0), at<WARP_OUT_COLOR1>(extrapolate ? out : warped_color1),
            at<WARP_OUT_DEPTH1>(warped_depth1), at<WARP_FIELD_STATE>(field_state));
        FGSR_TRY(rec.dispatch_pixels(Variant::warp, wb, &g, format.width, format.height));
        rec.barrier();
        rec.timestamp(q++);
        timings[k].push_back(PassId::warp);
        if (!extrapolate) {
            const auto bb = make_slots<PassId::blend>(
                at<BLEND_COLOR0>(warped_color0), at<BLEND_DEPTH0>(warped_depth0),
                at<BLEND_COLOR1>(warped_color1), at<BLEND_DEPTH1>(warped_depth1),
                at<BLEND_FIELD_STATE>(field_state), at<BLEND_OUTPUT>(out), at<BLEND_FIELD>(field),
                at<BLEND_MV1>(f1.mv), at<BLEND_FRAME_DEPTH1>(f1.depth));
            FGSR_TRY(rec.dispatch_pixels(Variant::blend, bb, &g, format.width, format.height));
            rec.barrier();
            rec.timestamp(q++);
            timings[k].push_back(PassId::blend);
        }
    }
    FGSR_TRY(rec.finish(true));

    std::vector<GeneratedFrame> result(alphas.size());
    bool worth_skipping = true; // every classified frame of the call skipped enough tiles
    for (size_t k = 0; k < alphas.size(); ++k) {
        GeneratedFrame& gf = result[k];
        gf.time = extrapolate ? 1.f + alphas[k] : alphas[k];
        auto t = rec.read_times(uint32_t(k) * kQueriesPerFrame, uint32_t(timings[k].size()));
        if (!t) return t.error();
        for (size_t p = 0; p < timings[k].size(); ++p) {
            PassTiming pt = timing_of(timings[k][p], (*t)[p]);
            gf.gpu_ms += pt.ms;
            gf.passes.push_back(std::move(pt));
        }
        if (tiled) {
            count_generate_tiles(k, gf);
            worth_skipping = worth_skipping && generate_worth_skipping(gf.passes[2].tiles_skipped);
        }
        if (k == 0 && tiling == GenTiles::probe) {
            gf.passes[0].tiles_total = tiles_total();
            worth_skipping = generate_worth_skipping(probe_skippable());
        }
        const size_t out_n = size_t(out_w) * out_h;
        gf.color.width = out_w;
        gf.color.height = out_h;
        // One pass over the frame: resize() would zero-fill it (a memset of 15 MB at 720p) before
        // the copy overwrites it.
        const float* src = static_cast<const float*>(outputs[k].mapped());
        gf.color.rgba.assign(src, src + out_n * 4);
    }
    if (tiling != GenTiles::none) tiles.gen_backoff.classified(worth_skipping);
    last_extrapolate = extrapolate;
    last_separate = separate() && !sr();
    tiles.last_tiled = tiled;
    tiles.last_side = tile_side();
    last_output = alphas.size() - 1;
    return result;
}

// Params::colour_agree: one alpha at a time, since the agree pass reads the warped frames that the
// separate passes of the given field and of the twin keep for the last frame of a call.
Result<std::vector<GeneratedFrame>> Session::Impl::generate_agreed(std::span<const float> alphas) {
    std::vector<GeneratedFrame> result;
    result.reserve(alphas.size());
    Impl& colour = *colour_twin->impl_;
    for (const float& alpha : alphas) {
        last_agreed = false;
        force_separate = true;
        auto given = generate_frames(std::span<const float>(&alpha, 1), false);
        force_separate = false;
        if (!given) return given.error();
        GeneratedFrame gf = std::move(given->front());
        // The twin restarted at a cut of its own (or has not two frames since): the given frame.
        if (colour.submitted < 2) {
            result.push_back(std::move(gf));
            continue;
        }
        colour.force_separate = true;
        auto from_colour = colour.generate_frames(std::span<const float>(&alpha, 1), false);
        colour.force_separate = false;
        if (!from_colour) return from_colour.error();
        const gpu::GenParams g =
            params::gen_params(format, params, alpha, false, frames[size_t(1 - newest)].has_mv,
                               frames[size_t(newest)].has_mv, input_measure());
        auto timing = record_agree(g, colour);
        if (!timing) return timing.error();
        last_agreed = true;
        for (PassTiming& t : from_colour->front().passes) {
            gf.gpu_ms += t.ms;
            gf.passes.push_back(std::move(t));
        }
        gf.gpu_ms += timing->ms;
        gf.passes.push_back(std::move(*timing));
        const float* src = static_cast<const float*>(outputs[0].mapped());
        gf.color.rgba.assign(src, src + size_t(out_w) * out_h * 4);
        result.push_back(std::move(gf));
    }
    return result;
}

// Params::colour_agree in extrapolation, and with super resolution in interpolation too: both fields
// generate every alpha (fused passes as configured); the fields' residuals at the newest input
// (agree_residual) and their box means are the same for every alpha, so they run once, then
// agree_mix once per frame. With super resolution (ISR, ESR: both fields' frames at the output's
// size) the means are stored at the input's size (agree_means) and agree_mix_upscaled mixes each
// frame per output pixel.
Result<std::vector<GeneratedFrame>> Session::Impl::agree_by_residual(std::span<const float> alphas,
                                                                     bool extrapolate) {
    auto given = generate_frames(alphas, extrapolate);
    if (!given) return given.error();
    Impl& colour = *colour_twin->impl_;
    // The twin restarted at a cut of its own (or has not two frames since), or either field has no
    // vectors for the newest frame: the given frames.
    if (colour.submitted < 2 || !colour.frames[size_t(colour.newest)].has_mv ||
        !frames[size_t(newest)].has_mv)
        return given;
    auto from_colour = colour.generate_frames(alphas, extrapolate);
    if (!from_colour) return from_colour.error();
    const GpuFrame& f1 = frames[size_t(newest)];
    const GpuFrame& f0 = frames[size_t(1 - newest)];
    FGSR_TRY(ensure_agree_buffers(false));
    // The residual spans a whole frame step whichever way the frames are generated: extrapolation's
    // parameters (its depth band, no gain).
    gpu::AgreeParams p = params::agree_params(
        params::gen_params(format, params, alphas.front(), true, f0.has_mv, f1.has_mv, input_measure()));
    if (sr()) {
        p.out_width = out_w;
        p.out_height = out_h;
    }
    const BufRef colour_mv = colour.frames[size_t(colour.newest)].mv;
    FGSR_TRY(rec.begin());
    rec.timestamp(0);
    // Stage 4 reads the inputs in the slots of the given field's warped frames (bindings.h); the
    // slots of the colour-only field's are unused there. Frame k's mix reads outputs k.
    auto slots = [&](size_t k) {
        return make_slots<PassId::agree>(
            at<AGREE_FRAME_COLOR0>(f0.color), at<AGREE_FRAME_DEPTH0>(f0.depth),
            at<AGREE_FRAME_COLOR1>(f1.color), at<AGREE_FRAME_DEPTH1>(f1.depth), at<AGREE_GIVEN_MV>(f1.mv),
            at<AGREE_COLOUR_MV>(colour_mv), at<AGREE_COLOUR_D0>(unused(colour_mv)),
            at<AGREE_COLOUR_W1>(unused(colour_mv)), at<AGREE_COLOUR_D1>(unused(colour_mv)),
            at<AGREE_COLOUR_STATE>(unused(colour_mv)), at<AGREE_GIVEN>(outputs[k]),
            at<AGREE_COLOUR>(colour.outputs[k]), at<AGREE_E>(agree_e), at<AGREE_ROWS>(agree_rows),
            at<AGREE_GIVEN_FIELD>(unused(colour_mv)), at<AGREE_LIGHT>(unused(colour_mv)),
            at<AGREE_LIGHT_ROWS>(unused(colour_mv)));
    };
    FGSR_TRY(rec.dispatch_pixels(Variant::agree_residual, slots(0), &p, format.width, format.height));
    rec.barrier();
    FGSR_TRY(
        rec.dispatch_pixels(Variant::agree_rows, slots(0), &p, agree_segments(format.width), format.height));
    rec.barrier();
    if (sr()) {
        FGSR_TRY(rec.dispatch_pixels(Variant::agree_means, slots(0), &p, format.width,
                                     agree_segments(format.height)));
        rec.barrier();
    }
    rec.timestamp(1);
    for (size_t k = 0; k < alphas.size(); ++k) {
        if (sr())
            FGSR_TRY(rec.dispatch_pixels(Variant::agree_mix_upscaled, slots(k), &p, out_w, out_h));
        else
            FGSR_TRY(rec.dispatch_pixels(Variant::agree_mix, slots(k), &p, format.width,
                                         agree_segments(format.height)));
        rec.barrier();
        rec.timestamp(uint32_t(k) + 2);
    }
    FGSR_TRY(rec.finish(true));
    auto t = rec.read_times(0, uint32_t(alphas.size()) + 1);
    if (!t) return t.error();
    last_agreed = true;
    for (size_t k = 0; k < alphas.size(); ++k) {
        GeneratedFrame& gf = (*given)[k];
        for (PassTiming& c : (*from_colour)[k].passes) {
            gf.gpu_ms += c.ms;
            gf.passes.push_back(std::move(c));
        }
        // The first frame carries the shared stages, every frame its own mix.
        PassTiming a = timing_of(PassId::agree, (*t)[k + 1]);
        if (k == 0) {
            a.ms += (*t)[0].ms;
            a.begin_ns = (*t)[0].begin_ns;
        }
        gf.gpu_ms += a.ms;
        gf.passes.push_back(std::move(a));
        const float* src = static_cast<const float*>(outputs[k].mapped());
        gf.color.rgba.assign(src, src + size_t(out_w) * out_h * 4);
    }
    return given;
}

Result<void> Session::Impl::ensure_agree_buffers(bool light) {
    auto make = [&](vk::Buffer& b, VkDeviceSize bytes_per_pixel) -> Result<void> {
        if (b.handle()) return {};
        auto r = vk::Buffer::create(*ctx, VkDeviceSize(n) * bytes_per_pixel, false);
        if (!r) return r.error();
        b = std::move(*r);
        return {};
    };
    FGSR_TRY(make(agree_e, 8));
    FGSR_TRY(make(agree_rows, 8));
    if (!light) return {}; // extrapolation has no gain stages
    FGSR_TRY(make(agree_light, 16));
    return make(agree_light_rows, 16);
}

// The agree pass's three stages over the given field's warped frames and output (this session's,
// from a call with separate passes) and the twin's.
Result<PassTiming> Session::Impl::record_agree(const gpu::GenParams& g, Impl& colour) {
    FGSR_TRY(ensure_agree_buffers(true));
    const gpu::AgreeParams p = params::agree_params(g);
    const auto b = make_slots<PassId::agree>(
        at<AGREE_GIVEN_W0>(warped_color0), at<AGREE_GIVEN_D0>(warped_depth0),
        at<AGREE_GIVEN_W1>(warped_color1), at<AGREE_GIVEN_D1>(warped_depth1),
        at<AGREE_GIVEN_STATE>(field_state), at<AGREE_COLOUR_W0>(colour.warped_color0),
        at<AGREE_COLOUR_D0>(colour.warped_depth0), at<AGREE_COLOUR_W1>(colour.warped_color1),
        at<AGREE_COLOUR_D1>(colour.warped_depth1), at<AGREE_COLOUR_STATE>(colour.field_state),
        at<AGREE_GIVEN>(outputs[0]), at<AGREE_COLOUR>(colour.outputs[0]), at<AGREE_E>(agree_e),
        at<AGREE_ROWS>(agree_rows), at<AGREE_GIVEN_FIELD>(field), at<AGREE_LIGHT>(agree_light),
        at<AGREE_LIGHT_ROWS>(agree_light_rows));
    FGSR_TRY(rec.begin());
    rec.timestamp(0);
    if (p.gain > 1.f) { // each field's brightness gain over its box (agree.h stages 5-7)
        FGSR_TRY(rec.dispatch_pixels(Variant::agree_light, b, &p, format.width, format.height));
        rec.barrier();
        FGSR_TRY(rec.dispatch_pixels(Variant::agree_light_rows, b, &p, agree_segments(format.width),
                                     format.height));
        rec.barrier();
        FGSR_TRY(rec.dispatch_pixels(Variant::agree_light_sums, b, &p, format.width,
                                     agree_segments(format.height)));
        rec.barrier();
    }
    FGSR_TRY(rec.dispatch_pixels(Variant::agree_error, b, &p, format.width, format.height));
    rec.barrier();
    FGSR_TRY(rec.dispatch_pixels(Variant::agree_rows, b, &p, agree_segments(format.width), format.height));
    rec.barrier();
    FGSR_TRY(rec.dispatch_pixels(Variant::agree_mix, b, &p, format.width, agree_segments(format.height)));
    rec.barrier();
    rec.timestamp(1);
    FGSR_TRY(rec.finish(true));
    auto t = rec.read_times(0, 1);
    if (!t) return t.error();
    return timing_of(PassId::agree, t->front());
}

Result<std::vector<GeneratedFrame>> Session::interpolate(std::span<const float> alphas) {
    return impl_->generate(alphas, false);
}

Result<std::vector<GeneratedFrame>> Session::extrapolate(std::span<const float> alphas) {
    return impl_->generate(alphas, true);
}

Result<Session::Intermediates> Session::read_intermediates() const {
    Impl& s = *impl_;
    Intermediates out;
    const size_t at = size_t(s.last_slice) * s.splat_stride;
    auto keys = s.rec.download<uint64_t>(s.keys, s.n, at);
    if (!keys) return keys.error();
    out.keys = std::move(*keys);
    auto motion = s.rec.download<float>(s.motion, s.n * 4);
    if (!motion) return motion.error();
    out.motion = std::move(*motion);
    if (s.tiles.last_tiled && s.last_output < s.tiles.sets.size()) {
        const uint32_t* flags = static_cast<const uint32_t*>(s.tiles.sets[s.last_output].flags.mapped());
        out.tile_flags.assign(flags, flags + s.tiles_total());
        out.tile_side = s.tiles.last_side;
    }
    if (!s.last_separate) return out; // the fused pass keeps no other intermediates
    auto get_f = [&](const vk::Buffer& b, size_t count, std::vector<float>& dst) -> Result<void> {
        auto r = s.rec.download<float>(b, count);
        if (!r) return r.error();
        dst = std::move(*r);
        return {};
    };
    FGSR_TRY(get_f(s.field, s.n * 4, out.field));
    FGSR_TRY(get_f(s.field_depth, s.n, out.field_depth));
    auto st = s.rec.download<uint32_t>(s.field_state, s.n);
    if (!st) return st.error();
    out.field_state = std::move(*st);
    FGSR_TRY(get_f(s.warped_color0, s.n * 4, out.warped_color0));
    FGSR_TRY(get_f(s.warped_depth0, s.n, out.warped_depth0));
    FGSR_TRY(
        get_f(s.last_extrapolate ? s.outputs[s.last_output] : s.warped_color1, s.n * 4, out.warped_color1));
    FGSR_TRY(get_f(s.warped_depth1, s.n, out.warped_depth1));
    if (s.last_agreed) {
        auto colour = s.colour_twin->read_intermediates();
        if (!colour) return colour.error();
        out.colour = std::make_shared<Intermediates>(std::move(*colour));
    }
    return out;
}

} // namespace fgsr
