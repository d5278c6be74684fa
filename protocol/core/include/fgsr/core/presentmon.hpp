// Per-frame telemetry as CSV in PresentMon's column names, so that the tools people already use
// for frame pacing (PresentMon's own viewers, CapFrameX, spreadsheets) read fgsr's records:
// `fgsr replay --telemetry`, the layer's FGSR_LAYER_PRESENTS, and `fgsr report`, which reads both
// (and PresentMon's own files, by column name).
//
// One row per displayed frame, in display order. Columns with a PresentMon meaning come first,
// under PresentMon's names; fgsr's own columns follow, prefixed "fgsr_". A value that is unknown
// is written "NA". FrameType is "Application" for the application's own frames and fgsr's types
// for the frames it made: "fgsr-interpolated", "fgsr-extrapolated", "fgsr-upscaled".
// Times: TimeInSeconds is CLOCK_MONOTONIC seconds of the present (PresentMon: QPC seconds since
// its start); every Ms* column is milliseconds:
//   MsBetweenPresents       this present minus the previous present of the same session
//   MsBetweenDisplayChange  this frame on screen minus the previous one (NA without a display time)
//   MsInPresentAPI          time spent in the present call
//   MsUntilRenderComplete   from the frame's submit (application present, or fgsr submit) until its
//                           pixels were ready (daemon: output written)
//   MsUntilDisplayed        from the frame's submit until it was displayed
//   MsGPUTime               GPU time fgsr spent on the frame (sum of its passes)
//   MsClickToPhotonLatency  a hardware probe's click-to-photon figure (fgsr probe), else NA
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/passes.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr {

inline constexpr size_t kPresentMonPasses = 0
#define FGSR_PM_COUNT_(ID, name, value) +1
    FGSR_PASSES(FGSR_PM_COUNT_)
#undef FGSR_PM_COUNT_
    ;

struct PresentRow {
    // PresentMon's columns
    std::string application; // executable name
    uint32_t process_id = 0;
    uint64_t swapchain = 0;          // SwapChainAddress (fgsr: the session id where there is none)
    std::string runtime = "Vulkan";  // PresentRuntime
    std::string present_mode = "NA"; // PresentMode (Vulkan: FIFO, MAILBOX, IMMEDIATE, ...)
    std::string frame_type = "Application";
    double time_s = 0; // TimeInSeconds
    double ms_between_presents = 0, ms_between_display_change = 0, ms_in_present_api = 0,
           ms_until_render_complete = 0, ms_until_displayed = 0, ms_gpu_time = 0, ms_click_to_photon = 0;
    // fgsr's columns
    uint64_t sequence = 0;     // fgsr_sequence: the submit (the application's frame) it belongs to
    uint32_t output_index = 0; // fgsr_output_index within the submit (NA for Application frames)
    std::string status = "OK";
    double target_time = 0; // fgsr_target_time: alpha, 1 + alpha, 1 (upscaled); NA for Application
    double daemon_latency_ms = 0, client_latency_ms = 0, queue_wait_ms = 0, daemon_cpu_ms = 0;
    double intended_s = 0; // fgsr_intended_s: when the pacing meant it to be presented
    double call_s = 0;     // fgsr_call_s: when the present call returned (TimeInSeconds may be later:
                           // the display time, where the driver tells it)
    uint32_t skipped_passes = 0, tiles_total = 0, tiles_skipped = 0;
    std::array<double, kPresentMonPasses> pass_ms{}; // fgsr_<pass>_ms
    PresentRow();                                    // every number NA (NaN) except the ids
};

// The header line (no newline at the end) and one row (idem).
std::string presentmon_header();
std::string presentmon_row(const PresentRow& row);

// Reads a CSV in these columns (fgsr's own files) or PresentMon's (columns it lacks stay NA,
// columns fgsr does not know are ignored). Needs TimeInSeconds and FrameType or
// MsBetweenPresents; errors name the line.
Result<std::vector<PresentRow>> parse_presentmon_csv(std::string_view text);

// "fgsr-interpolated" etc. for fgsr_frame_type values; "Application" for FGSR_FRAME_NONE.
const char* presentmon_frame_type(uint32_t fgsr_frame_type);

} // namespace fgsr
