// Super resolution: the LUT upload, the sr pass of a submit over the ping-pong history (its tiled
// form is tiles.cpp's), the history swap, what generate_sr reads, and the super-resolved result.
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/params.hpp>

#include "session.hpp"

#include <cstring>

namespace fgsr {

Result<void> Session::Impl::upload_lut() {
    Lut l = params.lut.size() == kLutSize ? Lut{params.scale, params.lut} : default_lut(params.scale);
    force_identity_phase(l);
    const std::vector<float>& weights = l.weights;
    std::memcpy(sr_history.lut.mapped(), weights.data(), kLutSize * 4);
    return {};
}

Result<bool> Session::Impl::record_sr(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                      uint32_t& query) {
    const vk::Buffer& history = sr_history.hr[size_t(sr_history.newest)];
    const vk::Buffer& out = sr_history.hr[size_t(1 - sr_history.newest)];
    // Without history every pixel is a spatial upsample: nothing to classify.
    const bool tiled = classify_sr(sp.has_history != 0u);
    if (tiled) {
        FGSR_TRY(record_sr_tiled(sp, f, prev, history, out, query++));
    } else {
        FGSR_TRY(record_sr_noise(sp, f, prev, history, out));
        const auto b = make_slots<PassId::sr>(sr_inputs(f, prev, history, out));
        FGSR_TRY(rec.dispatch_pixels(Variant::sr, b, &sp, out_w, out_h));
    }
    rec.barrier();
    rec.timestamp(query++);
    return tiled;
}

// sr.h's (r, q) once per input pixel (variant sr_noise), for steps 3 and 7 of every output pixel
// that shares it; only where one of them is on and there is a history to measure against.
Result<void> Session::Impl::record_sr_noise(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                            const vk::Buffer& history, const vk::Buffer& out) {
    if (sp.has_history == 0u || (sp.flags & (SR_NOISE_KERNEL | SR_NOISE_AVERAGE)) == 0u) return {};
    const auto b = make_slots<PassId::sr>(sr_inputs(f, prev, history, out));
    FGSR_TRY(rec.dispatch_pixels(Variant::sr_noise, b, &sp, format.width, format.height));
    rec.barrier();
    return {};
}

Session::Impl::SrInputs Session::Impl::sr_inputs(const GpuFrame& f, const GpuFrame& prev,
                                                 const vk::Buffer& history, const vk::Buffer& out) const {
    return SrInputs{{f.color, f.depth, f.mv, prev.depth, history, sr_history.lut, out, sr_history.noise}};
}

void Session::Impl::finish_sr(const PassTiming& t) {
    sr_history.timing = timing_of(PassId::sr, t);
    sr_history.newest = 1 - sr_history.newest;
    sr_history.valid = true;
}

GenSrPush Session::Impl::gen_sr_push(const gpu::GenParams& g) const {
    return GenSrPush{g, params::generate_sr_params(format, params, out_w, out_h, jitter_x, jitter_y,
                                                   g.extrapolate != 0u, input_measure())};
}

const vk::Buffer& Session::Impl::gen_sr_source(bool extrapolate) const {
    return sr_history.hr[size_t(extrapolate ? sr_history.newest : 1 - sr_history.newest)];
}

Result<GeneratedFrame> Session::super_resolved() {
    Impl& s = *impl_;
    if (!s.sr())
        return make_error(Errc::invalid_argument, "the session does not upscale (Params::scale is 1)");
    if (!s.sr_history.valid) return make_error(Errc::empty_input, "no frame submitted yet");
    const size_t hpx = size_t(s.out_w) * s.out_h;
    auto px = s.rec.download<float>(s.sr_history.hr[size_t(s.sr_history.newest)], hpx * 4);
    if (!px) return px.error();
    GeneratedFrame gf;
    gf.time = 1.f;
    gf.color = ImageRGBA{s.out_w, s.out_h, std::move(*px)};
    PassTiming sr = s.sr_history.timing;
    if (s.denoise()) {
        gf.passes.push_back(s.denoiser.timing);
        gf.gpu_ms += s.denoiser.timing.ms;
    }
    if (s.tiles.last_sr_tiled) {
        PassTiming cl = s.tiles.classify_sr_timing;
        cl.tiles_total = s.tiles.sr_total;
        gf.passes.push_back(cl);
        gf.gpu_ms += cl.ms;
        sr.tiles_total = s.tiles.sr_total;
        sr.tiles_skipped = s.tiles.sr_skipped;
    }
    gf.passes.push_back(sr);
    gf.gpu_ms += sr.ms;
    return gf;
}

} // namespace fgsr
