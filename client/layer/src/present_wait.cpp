// Display times of the layer's presents through VK_KHR_present_wait (present_wait.hpp).
#include "present_wait.hpp"

#include "report.hpp"

#include <fgsr/core/clock.hpp>

namespace fgsr::layer {

void DisplayClock::add(uint64_t id, uint64_t call_ns, std::function<void(uint64_t)> done) {
    if (id == 0 || !enabled()) {
        done(call_ns);
        return;
    }
    pending_.push_back({id, call_ns, std::move(done)});
    poll();
}

void DisplayClock::poll(bool final) {
    while (!pending_.empty()) {
        Pending& p = pending_.front();
        const uint64_t now = monotonic_ns();
        bool displayed = false;
        if (!final) {
            VkResult r;
            {
                std::scoped_lock l(acquire_mutex_, dev_.queue_mutex);
                r = dev_.vk.WaitForPresentKHR(dev_.device, swapchain_, p.id, 0);
            }
            if (r == VK_TIMEOUT && now - p.call_ns < kMaxWaitNs) return; // not yet: later ids neither
            displayed = r == VK_SUCCESS || r == VK_SUBOPTIMAL_KHR;
        }
        Report::get().display_time(displayed);
        auto done = std::move(p.done);
        const uint64_t t = displayed ? now : p.call_ns;
        pending_.pop_front();
        done(t);
    }
}

} // namespace fgsr::layer
