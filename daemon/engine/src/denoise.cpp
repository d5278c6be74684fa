// The denoise pass of super-resolution sessions (shaders/denoise.h): its four stages on a frame's
// ingested colour (histogram, noise level, filter into the scratch, copy back), and the estimate.
#include <fgsr/engine/params.hpp>

#include "session.hpp"

#include <cstring>

namespace fgsr {

// The frame's colour is filtered in place (through the scratch) when its estimate asks for it.
Result<void> Session::Impl::record_denoise(const vk::Buffer& color) {
    vkCmdFillBuffer(rec.cmd(), denoiser.noise.handle(), 0, VK_WHOLE_SIZE, 0u);
    rec.barrier();
    gpu::DenoiseParams d = params::denoise_params(format, params);
    // Stages 0-2 bind the frame's colour and the scratch (bindings.h, DENOISE_*); stage 3 copies
    // the scratch back into the colour.
    const auto b = make_slots<PassId::denoise>(
        at<DENOISE_COLOR_IN>(color), at<DENOISE_COLOR>(denoiser.scratch), at<DENOISE_NOISE>(denoiser.noise));
    d.stage = DENOISE_HISTOGRAM;
    FGSR_TRY(rec.dispatch_pixels(Variant::denoise, b, &d, (format.width + 1) / 2, (format.height + 1) / 2));
    rec.barrier();
    d.stage = DENOISE_LEVEL;
    FGSR_TRY(rec.dispatch_pixels(Variant::denoise, b, &d, 1, 1));
    rec.barrier();
    d.stage = DENOISE_FILTER;
    FGSR_TRY(
        rec.dispatch_indirect(Variant::denoise, b, &d, denoiser.noise, VkDeviceSize(DENOISE_DISPATCH) * 4));
    rec.barrier();
    d.stage = DENOISE_COPY;
    const auto copy = make_slots<PassId::denoise>(
        at<DENOISE_COLOR_IN>(denoiser.scratch), at<DENOISE_COLOR>(color), at<DENOISE_NOISE>(denoiser.noise));
    FGSR_TRY(rec.dispatch_indirect(Variant::denoise, copy, &d, denoiser.noise,
                                   VkDeviceSize(DENOISE_DISPATCH) * 4));
    return {};
}

void Session::Impl::read_noise_estimate() {
    const uint32_t* words = static_cast<const uint32_t*>(denoiser.noise.mapped());
    std::memcpy(&denoiser.estimate.sigma, &words[DENOISE_SIGMA], 4);
    std::memcpy(&denoiser.estimate.range, &words[DENOISE_RANGE], 4);
}

} // namespace fgsr
