// When the layer has enabled VK_KHR_present_id + VK_KHR_present_wait (layer.cpp: the driver offers
// them and the application does not use them), the time each of the layer's presents reached the
// display. Each present the layer makes carries the next present id of its swapchain; the present
// thread polls vkWaitForPresentKHR with a zero timeout between its presents (about every
// millisecond while it sleeps: the swapchain's host access is externally synchronized with
// presents and acquires, so the layer never blocks in the wait while holding it). A present's
// records complete with the time its id was seen displayed, or, when the driver does not say within
// kMaxWaitNs or reports an error for the swapchain, with the time the present call returned
// (counted as a fallback).
//
// Without present wait, records complete at once with the present call's return time.
//
// Thread safety: the present thread only (the swapchain's acquire and queue locks are taken for the
// wait calls).
#pragma once

#include "dispatch.hpp"

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>

namespace fgsr::layer {

class DisplayClock {
  public:
    static constexpr uint64_t kMaxWaitNs = 500'000'000;

    DisplayClock(DeviceData& dev, VkSwapchainKHR swapchain, std::mutex& acquire_mutex)
        : dev_(dev), swapchain_(swapchain), acquire_mutex_(acquire_mutex) {}

    bool enabled() const { return dev_.use_present_wait; }
    // The id to chain (VkPresentIdKHR) to the next present; 0 when present wait is not used.
    uint64_t next_id() { return enabled() ? ++last_id_ : 0; }
    // `done(displayed_ns)` once present `id` (0: none) reached the display; the call returned at
    // call_ns.
    void add(uint64_t id, uint64_t call_ns, std::function<void(uint64_t)> done);
    // Completes the records whose presents were displayed. final: completes every record, those
    // not yet displayed with their call time, without calling Vulkan (the swapchain may be going).
    void poll(bool final = false);
    bool pending() const { return !pending_.empty(); }

  private:
    struct Pending {
        uint64_t id, call_ns;
        std::function<void(uint64_t)> done;
    };
    DeviceData& dev_;
    VkSwapchainKHR swapchain_;
    std::mutex& acquire_mutex_;
    uint64_t last_id_ = 0;
    std::deque<Pending> pending_;
};

} // namespace fgsr::layer
