// What the layer tells the outside: log lines (stderr, "fgsr layer: " prefix), the counters of
// FGSR_LAYER_STATS, the per-present records of FGSR_LAYER_PRESENTS and the generated-frame dumps of
// FGSR_LAYER_DUMP. One process-wide Report; every member function is thread-safe.
//
// FGSR_LAYER_STATS=FILE, written at exit (and when the last device is destroyed):
//   {"app_presents": N, "presents": M, "generated": K, "dropped": D, "mode": "...", "multiplier": m,
//    "present_wait": false, "displayed_by_present_wait": W, "present_wait_fallbacks": F,
//    "layer_cpu_ns_per_present": c}
// app_presents: vkQueuePresentKHR calls of the application; presents: presents the layer made
// (real + generated); generated: generated frames presented; dropped: generated frames requested
// but not presented (daemon late or gone, first frame of a session, no free image); present_wait:
// the layer uses VK_KHR_present_wait on this device (present_wait.hpp); W: presents whose time is
// their display time from it; F: presents it did not report in time (their time is the call's).
// FGSR_LAYER_PRESENTS=FILE: a CSV row per present in PresentMon's columns (fgsr/core/presentmon.hpp):
// FrameType Application (real) or fgsr-interpolated / fgsr-extrapolated, TimeInSeconds = when the
// frame reached the display (VK_KHR_present_wait) or else when the present call returned
// (CLOCK_MONOTONIC), MsUntilDisplayed = from the application's vkQueuePresentKHR of the real frame
// involved (so, on Application rows, the latency the layer adds), fgsr_sequence = the
// application's present counter, fgsr_intended_s = when the pacing meant it to be presented,
// fgsr_call_s = when the present call returned, SwapChainAddress = the VkSwapchainKHR. Each
// present also goes to fgsrd's telemetry (fgsr_report_presents).
// FGSR_LAYER_DUMP=DIR: each generated frame as DIR/gen_<app_present>_<j>.rgba (RGBA8 sRGB rows,
// tightly packed) + .json {"width","height","app_present","index","alpha","mode","multiplier"};
// interpolated frames lie between app presents app_present-1 and app_present at alpha, extrapolated
// ones after app_present at 1 + alpha.
#pragma once

#include "config.hpp"

#include <cstdint>
#include <string>

namespace fgsr::layer {

void log_line(const std::string& message);

enum class PresentKind { real, generated };

struct DumpInfo {
    uint32_t width, height;
    uint64_t app_present;
    uint32_t index; // 1..multiplier-1
    float alpha;
    Mode mode;
    uint32_t multiplier;
};

class Report {
  public:
    static Report& get();
    // Frees the Report (the next get() makes a fresh one). Only when nothing can use it any more:
    // the layer calls it as it unloads, with no instance, device or swapchain left.
    static void release();

    void app_present();
    // app_ns: when the application presented the real frame this present belongs to (generated
    // frames: the real frame they were made with).
    // actual_ns: displayed (present wait) or call_ns (when the present call returned).
    void present(PresentKind kind, uint64_t app_present, uint64_t app_ns, uint64_t intended_ns,
                 uint64_t actual_ns, uint64_t call_ns, uint64_t swapchain);
    void dropped(uint32_t n);
    void layer_cpu(uint64_t ns);
    void set_config(const LayerConfig& c);
    void set_present_wait(bool available);
    // A present's record completed: with its display time from VK_KHR_present_wait (true), or with
    // the present call's time because the driver did not say in time (false).
    void display_time(bool from_present_wait);
    // Writes `rgba8` (width * height * 4 bytes) when FGSR_LAYER_DUMP is set.
    bool dumping() const;
    void dump(const DumpInfo& info, const uint8_t* rgba8);
    // Writes the stats and present files (idempotent: rewrites them with the current figures).
    void write_files();

  private:
    template <class T> friend class Lazy; // makes and frees the one Report
    Report();
    ~Report();
    Report(const Report&) = delete;
    Report& operator=(const Report&) = delete;
    struct State;
    State* s_;
};

} // namespace fgsr::layer
