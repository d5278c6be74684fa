// One application swapchain under the layer: capture on the application's thread, generation and
// paced presents on the swapchain's present thread (swapchain.hpp).
#include "swapchain.hpp"

#include "report.hpp"

#include <fgsr/core/clock.hpp>

#include <algorithm>
#include <cstring>
#include <ctime>

namespace fgsr::layer {
namespace {

uint64_t thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

bool is_error_to_report(VkResult r) {
    return r == VK_SUBOPTIMAL_KHR || r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_ERROR_SURFACE_LOST_KHR ||
           r == VK_ERROR_DEVICE_LOST || r == VK_ERROR_FULL_SCREEN_EXCLUSIVE_MODE_LOST_EXT;
}

} // namespace

Swapchain::Swapchain(DeviceData& dev, VkSwapchainKHR handle, VkFormat format, VkExtent2D extent, bool managed)
    : dev_(dev), handle_(handle), format_(format), extent_(extent), kind_(pixel_kind(format)),
      managed_(managed && kind_ != PixelKind::unsupported) {
    if (managed_ && !init_images()) {
        log_line("could not set up the swapchain's copies; passing its frames through");
        managed_ = false;
    }
    if (managed_) thread_ = std::thread([this] { thread_main(); });
}

Swapchain::~Swapchain() {
    drain();
    stop();
    if (!managed_) return;
    if (last_queue_) { // the layer's presents wait on its semaphores: let them retire first
        std::lock_guard l(dev_.queue_mutex);
        dev_.vk.QueueWaitIdle(last_queue_);
    }
    for (Slot& s : slots_)
        if (s.fence.get()) s.fence.wait();
    for (uint32_t i = 0; i < kMaxMultiplier - 1; ++i)
        if (upload_pending_[i]) uploads_[i].fence.wait();
}

bool Swapchain::init_images() {
    uint32_t n = 0;
    if (dev_.vk.GetSwapchainImagesKHR(dev_.device, handle_, &n, nullptr) != VK_SUCCESS || n == 0)
        return false;
    images_.resize(n);
    if (dev_.vk.GetSwapchainImagesKHR(dev_.device, handle_, &n, images_.data()) != VK_SUCCESS) return false;
    images_.resize(n);
    image_ready_.resize(n);
    for (Semaphore& s : image_ready_)
        if (Semaphore::create(dev_, s) != VK_SUCCESS) return false;
    const VkDeviceSize bytes =
        VkDeviceSize(extent_.width) * extent_.height * swapchain_bytes_per_pixel(kind_);
    for (Slot& s : slots_) // signalled: the destructor waits on every slot, used or not
        if (StagingBuffer::create(dev_, bytes, s.staging) != VK_SUCCESS || Fence::create(dev_, true, s.fence))
            return false;
    for (Slot& s : uploads_)
        if (StagingBuffer::create(dev_, bytes, s.staging) != VK_SUCCESS ||
            Fence::create(dev_, false, s.fence))
            return false;
    return Fence::create(dev_, false, acquire_fence_) == VK_SUCCESS;
}

bool Swapchain::init_pools(uint32_t family) {
    if (CommandPool::create(dev_, family, app_pool_) != VK_SUCCESS ||
        CommandPool::create(dev_, family, thread_pool_) != VK_SUCCESS)
        return false;
    for (Slot& s : slots_)
        if (app_pool_.allocate(s.cmd) != VK_SUCCESS) return false;
    for (Slot& s : uploads_)
        if (thread_pool_.allocate(s.cmd) != VK_SUCCESS) return false;
    family_ = family;
    return true;
}

void Swapchain::drain() {
    std::unique_lock l(mutex_);
    cv_.wait(l, [&] { return (queue_.empty() && !busy_) || !thread_.joinable() || stop_; });
}

void Swapchain::stop() {
    {
        std::lock_guard l(mutex_);
        stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void Swapchain::note_result(VkResult r) {
    if (!is_error_to_report(r)) return;
    VkResult expected = VK_SUCCESS;
    // An error outranks SUBOPTIMAL.
    if (!pending_result_.compare_exchange_strong(expected, r) && expected == VK_SUBOPTIMAL_KHR && r < 0)
        pending_result_.store(r);
}

VkResult Swapchain::acquire(uint64_t timeout_ns, VkSemaphore semaphore, VkFence fence, uint32_t device_mask,
                            uint32_t* index) {
    auto call = [&](uint64_t t) {
        std::lock_guard l(acquire_mutex_);
        if (device_mask == 0)
            return dev_.vk.AcquireNextImageKHR(dev_.device, handle_, t, semaphore, fence, index);
        VkAcquireNextImageInfoKHR ai{VK_STRUCTURE_TYPE_ACQUIRE_NEXT_IMAGE_INFO_KHR};
        ai.swapchain = handle_;
        ai.timeout = t;
        ai.semaphore = semaphore;
        ai.fence = fence;
        ai.deviceMask = device_mask;
        return dev_.vk.AcquireNextImage2KHR(dev_.device, &ai, index);
    };
    if (!managed_ || timeout_ns == 0) return call(timeout_ns);
    // Short slices, so that the present thread can acquire (and present, freeing images) between.
    constexpr uint64_t kSliceNs = 2'000'000;
    const uint64_t start = monotonic_ns();
    for (;;) {
        const uint64_t elapsed = monotonic_ns() - start;
        const uint64_t left = timeout_ns == UINT64_MAX ? UINT64_MAX
                              : timeout_ns > elapsed   ? timeout_ns - elapsed
                                                       : 0;
        const VkResult r = call(std::min(left, kSliceNs));
        if (r != VK_TIMEOUT && r != VK_NOT_READY) return r;
        if (left <= kSliceNs) return r;
    }
}

VkResult Swapchain::call_present(VkQueue queue, uint32_t index, VkSemaphore wait, uint64_t* id) {
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = wait ? 1 : 0;
    pi.pWaitSemaphores = &wait;
    pi.swapchainCount = 1;
    pi.pSwapchains = &handle_;
    pi.pImageIndices = &index;
    const uint64_t present_id = display_.next_id();
    VkPresentIdKHR pid{VK_STRUCTURE_TYPE_PRESENT_ID_KHR};
    if (present_id != 0) { // VK_KHR_present_id: the display time comes from VK_KHR_present_wait
        pid.swapchainCount = 1;
        pid.pPresentIds = &present_id;
        pi.pNext = &pid;
    }
    if (id) *id = present_id;
    std::lock_guard l(dev_.queue_mutex);
    return dev_.vk.QueuePresentKHR(queue, &pi);
}

VkResult Swapchain::pass_through(VkQueue queue, const VkPresentInfoKHR& info, uint32_t index,
                                 uint64_t app_present) {
    drain(); // keep the order of frames already handed to the present thread
    VkPresentInfoKHR pi = info;
    pi.swapchainCount = 1;
    pi.pSwapchains = &handle_;
    pi.pImageIndices = &index;
    pi.pResults = nullptr;
    VkResult r;
    {
        std::lock_guard l(dev_.queue_mutex);
        r = dev_.vk.QueuePresentKHR(queue, &pi);
    }
    const uint64_t t = monotonic_ns();
    Report::get().present(PresentKind::real, app_present, last_entry_ns_, t, t, t, uint64_t(handle_));
    const VkResult pending = pending_result_.exchange(VK_SUCCESS);
    return r == VK_SUCCESS ? pending : r;
}

VkResult Swapchain::present(VkQueue queue, const VkPresentInfoKHR& info, uint32_t index,
                            const LayerConfig& cfg, uint64_t entry_ns) {
    if (cfg.enabled && cfg.fps_limit > 0 && last_entry_ns_ != 0) { // the base frame-rate cap
        const uint64_t next = last_entry_ns_ + uint64_t(1e9 / cfg.fps_limit);
        for (uint64_t now = monotonic_ns(); now < next; now = monotonic_ns()) {
            const uint64_t left = next - now;
            timespec ts{time_t(left / 1'000'000'000), long(left % 1'000'000'000)};
            nanosleep(&ts, nullptr);
        }
        entry_ns = monotonic_ns();
    }
    const uint64_t cpu0 = thread_cpu_ns();
    const uint64_t app_present = app_presents_++;
    if (last_entry_ns_ != 0) {
        const uint64_t dt = std::clamp<uint64_t>(entry_ns - last_entry_ns_, 1'000'000, 1'000'000'000);
        interval_ns_ = interval_ns_ == 0 ? dt : (interval_ns_ * 7 + dt) / 8;
    }
    last_entry_ns_ = entry_ns;
    if (!managed_ || !cfg.enabled || index >= images_.size())
        return pass_through(queue, info, index, app_present);
    if (family_ == UINT32_MAX) {
        uint32_t family = 0;
        {
            std::lock_guard l(dev_.families_mutex);
            if (auto it = dev_.queue_family.find(queue); it != dev_.queue_family.end()) family = it->second;
        }
        if (!init_pools(family)) {
            log_line("could not create command pools; passing this swapchain's frames through");
            managed_ = false;
            return pass_through(queue, info, index, app_present);
        }
    }
    uint32_t slot = 0;
    {
        std::unique_lock l(mutex_);
        // The present thread frees a slot within about one interval (it drops generated frames
        // when it falls behind).
        cv_.wait(l, [&] { return free_slots_ != 0 || stop_; });
        if (stop_) {
            l.unlock();
            return pass_through(queue, info, index, app_present);
        }
        slot = uint32_t(__builtin_ctz(free_slots_));
        free_slots_ &= ~(1u << slot);
    }
    last_queue_ = queue;
    Slot& s = slots_[slot];
    VkResult r = record_readback(dev_, s.cmd, images_[index], extent_, s.staging.buffer());
    if (r == VK_SUCCESS) r = s.fence.reset();
    if (r == VK_SUCCESS) {
        std::vector<VkPipelineStageFlags> stages(info.waitSemaphoreCount, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
        VkSemaphore ready = image_ready_[index].get();
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.waitSemaphoreCount = info.waitSemaphoreCount;
        si.pWaitSemaphores = info.pWaitSemaphores;
        si.pWaitDstStageMask = stages.data();
        si.commandBufferCount = 1;
        si.pCommandBuffers = &s.cmd;
        si.signalSemaphoreCount = 1;
        si.pSignalSemaphores = &ready;
        std::lock_guard l(dev_.queue_mutex);
        r = dev_.vk.QueueSubmit(queue, 1, &si, s.fence.get());
    }
    if (r != VK_SUCCESS) {
        log_line("copy of a presented frame failed (VkResult " + std::to_string(int(r)) +
                 "); passing it through");
        {
            std::lock_guard l(mutex_);
            free_slots_ |= 1u << slot;
        }
        return pass_through(queue, info, index, app_present);
    }
    {
        std::lock_guard l(mutex_);
        queue_.push_back(Item{slot, index, queue, entry_ns, app_present, interval_ns_, cfg});
    }
    cv_.notify_all();
    Report::get().layer_cpu(thread_cpu_ns() - cpu0);
    return pending_result_.exchange(VK_SUCCESS);
}

void Swapchain::thread_main() {
    for (;;) {
        Item item;
        {
            std::unique_lock l(mutex_);
            while (display_.pending() && queue_.empty() && !stop_) { // display times still to come
                cv_.wait_for(l, std::chrono::milliseconds(1));
                l.unlock();
                display_.poll();
                l.lock();
            }
            cv_.wait(l, [&] { return !queue_.empty() || stop_; });
            if (stop_) {
                l.unlock();
                display_.poll(true); // the swapchain may be going: no more Vulkan calls
                return;
            }
            item = queue_.front();
            queue_.pop_front();
            busy_ = true;
        }
        const uint64_t cpu0 = thread_cpu_ns();
        process(item);
        Report::get().layer_cpu(thread_cpu_ns() - cpu0);
        {
            std::lock_guard l(mutex_);
            free_slots_ |= 1u << item.slot;
            busy_ = false;
        }
        cv_.notify_all();
    }
}

bool Swapchain::sleep_until(uint64_t t_ns, size_t max_waiting) {
    std::unique_lock l(mutex_);
    for (;;) {
        if (queue_.size() > max_waiting || stop_) return false;
        const uint64_t now = monotonic_ns();
        if (now >= t_ns) return true;
        if (!display_.pending()) {
            cv_.wait_for(l, std::chrono::nanoseconds(t_ns - now));
            continue;
        }
        // Presents waiting for their display time: look every millisecond.
        cv_.wait_for(l, std::chrono::nanoseconds(std::min<uint64_t>(t_ns - now, 1'000'000)));
        l.unlock();
        display_.poll();
        l.lock();
    }
}

void Swapchain::process(Item& item) {
    Slot& s = slots_[item.slot];
    s.fence.wait();
    s.staging.invalidate();
    const uint32_t m = item.cfg.multiplier;
    const uint64_t P = item.interval_ns;
    const bool even = item.cfg.pacing == Pacing::even && P != 0;
    // Interpolation runs about one interval behind the application, so one newer frame waiting is
    // normal there; extrapolation presents every real frame at once, so any newer frame means it
    // is late.
    const size_t max_waiting = item.cfg.mode == Mode::interpolate ? 1 : 0;
    bool behind;
    {
        std::lock_guard l(mutex_);
        behind = queue_.size() > max_waiting;
    }
    // How long the daemon may take: two intervals after the application's present (the present
    // thread holds at most kSlots frames, so the application does not wait); no time at all when
    // the present thread is behind (the frame is still sent: it is the next one's previous frame).
    const uint64_t budget = behind ? 0 : std::clamp<uint64_t>(2 * P, 20'000'000, 500'000'000);
    if (item.cfg.mode == Mode::interpolate) {
        // Generated frames between the previous real frame and this one, then this one.
        const uint64_t deadline = item.entry_ns + budget;
        std::vector<Generated> gens = generate(item, deadline);
        // The schedule starts at the previous real present R, or later when the generated frames
        // came after R + P / m: then everything moves later by as much (the real frame too), which
        // raises the latency to what the daemon needs and keeps the intervals even. It may also
        // start up to half a step before R, so that the latency comes back down once the daemon is
        // fast again (one gap of the sequence is then shorter by at most P / 2m).
        const uint64_t R = last_real_ns_;
        const uint64_t ready = monotonic_ns();
        const uint64_t step = P / m, catch_up = P / (2 * m);
        const uint64_t base =
            R == 0 ? 0 : std::max(R > catch_up ? R - catch_up : 0, ready > step ? ready - step : 0);
        bool on_time = true;
        uint32_t shown = 0;
        for (const Generated& g : gens) {
            const uint64_t intended = even && R ? base + g.index * P / m : monotonic_ns();
            if (on_time && even && R)
                on_time = sleep_until(std::min(intended, monotonic_ns() + P), max_waiting);
            if (!on_time) { // a newer frame waits: drop the rest
                report_present(g.sequence, g.output_index, g.frame_type, g.submit_ns, g.received_ns, intended, 0,
                               true);
                release(g);
                continue;
            }
            shown += present_generated(item, g, intended) ? 1 : 0;
        }
        Report::get().dropped(m - 1 - shown);
        const uint64_t now = monotonic_ns();
        uint64_t intended = even && R && shown ? std::max(base + P, now) : now;
        if (on_time && intended > now) on_time = sleep_until(std::min(intended, now + P), max_waiting);
        present_real(item, intended);
    } else {
        // This frame at once, then the frames after it.
        present_real(item, monotonic_ns());
        const uint64_t R = last_real_ns_;
        std::vector<Generated> gens = generate(item, item.entry_ns + budget);
        bool on_time = true;
        uint32_t shown = 0;
        for (const Generated& g : gens) {
            const uint64_t intended = even ? R + g.index * P / m : monotonic_ns();
            if (on_time && even) on_time = sleep_until(std::min(intended, monotonic_ns() + P), max_waiting);
            if (!on_time) {
                report_present(g.sequence, g.output_index, g.frame_type, g.submit_ns, g.received_ns, intended, 0,
                               true);
                release(g);
                continue;
            }
            shown += present_generated(item, g, intended) ? 1 : 0;
        }
        Report::get().dropped(m - 1 - shown);
    }
}

void Swapchain::present_real(const Item& item, uint64_t intended_ns) {
    uint64_t id = 0;
    const VkResult r = call_present(item.queue, item.image_index, image_ready_[item.image_index].get(), &id);
    note_result(r);
    last_real_ns_ = monotonic_ns(); // the pacing follows the present calls
    // Interpolation submitted this frame before presenting it; extrapolation submits it after.
    const uint64_t sequence = item.cfg.mode == Mode::interpolate ? last_sequence_ : 0;
    const uint64_t call = last_real_ns_;
    display_.add(id, call, [this, item, intended_ns, call, sequence](uint64_t shown) {
        Report::get().present(PresentKind::real, item.app_present, item.entry_ns, intended_ns, shown, call,
                              uint64_t(handle_));
        report_present(sequence, FGSR_REPORT_APPLICATION, FGSR_FRAME_NONE, item.entry_ns, 0, intended_ns, shown,
                       false);
    });
}

std::vector<Swapchain::Generated> Swapchain::generate(const Item& item, uint64_t deadline_ns) {
    std::vector<Generated> out;
    SessionShape shape{extent_.width,       extent_.height,       fgsr_format_for(kind_), item.cfg.mode,
                       item.cfg.multiplier, item.cfg.socket_path, item.cfg.motion};
    const uint64_t now = monotonic_ns();
    if (!link_.ensure(shape, now)) return out;
    fgsr_session* session = link_.session();
    fgsr_input_slot in{};
    fgsr_status st = fgsr_acquire_input(session, 0, &in);
    if (st == FGSR_STATUS_NO_SLOT) return out; // the daemon is behind: this frame gets none
    if (st != FGSR_STATUS_OK) {
        link_.fail(st, "went away", now);
        return out;
    }
    const fgsr_pool_layout& layout = link_.layout();
    const uint32_t bpp = swapchain_bytes_per_pixel(kind_);
    to_fgsr(kind_, {slots_[item.slot].staging.data(), extent_.width * bpp},
            {in.color, layout.color.row_pitch}, extent_.width, extent_.height);
#if !(defined(FGSR_SESSION_NO_MVS) && defined(FGSR_SESSION_NO_DEPTH))
    // Before colour-only sessions: a depth plane of zeros (one plane, no vectors flagged).
    std::vector<bool>& cleared = link_.depth_cleared();
    if (in.index < cleared.size() && !cleared[in.index] && in.depth) {
        std::memset(in.depth, 0, layout.depth.size);
        cleared[in.index] = true;
    }
#endif
    const uint32_t m = item.cfg.multiplier;
    float alphas[kMaxMultiplier - 1];
    for (uint32_t j = 1; j < m; ++j) alphas[j - 1] = float(j) / float(m);
    fgsr_submit_info si{};
    si.struct_size = sizeof(si);
    si.input_slot = in.index;
    if (item.cfg.mode == Mode::interpolate) {
        si.interp_count = m - 1;
        si.interp_alphas = alphas;
    } else {
        si.extrap_count = m - 1;
        si.extrap_alphas = alphas;
    }
    si.present_time_ns = item.entry_ns;
    si.user_data = item.app_present;
    uint64_t sequence = 0;
    st = fgsr_submit(session, &si, &sequence);
    if (st != FGSR_STATUS_OK) {
        if (st == FGSR_STATUS_DISCONNECTED) link_.fail(st, "went away", now);
        return out;
    }
    last_sequence_ = sequence;
    if (!collect(sequence, m - 1, deadline_ns, out)) {
        for (const Generated& g : out) release(g);
        out.clear();
    }
    std::sort(out.begin(), out.end(),
              [](const Generated& a, const Generated& b) { return a.index < b.index; });
    return out;
}

bool Swapchain::collect(uint64_t sequence, uint32_t wanted, uint64_t deadline_ns,
                        std::vector<Generated>& out) {
    fgsr_session* session = link_.session();
    uint32_t seen = 0;
    while (seen < wanted) {
        const uint64_t now = monotonic_ns();
        const uint32_t timeout_ms =
            deadline_ns > now ? uint32_t((deadline_ns - now + 999'999) / 1'000'000) : 0;
        fgsr_output o{};
        const fgsr_status st = fgsr_wait(session, timeout_ms, &o);
        if (st == FGSR_STATUS_TIMEOUT) return true; // late: what arrives later is released as stale
        if (st != FGSR_STATUS_OK) {
            link_.fail(st, "went away", now);
            out.clear(); // the session's memory is gone
            return true;
        }
        if (o.sequence != sequence) { // a late output of an earlier frame
            if (o.output_slot != FGSR_NO_SLOT) fgsr_release_output(session, o.output_slot);
            continue;
        }
        ++seen;
        const bool usable = o.status == FGSR_STATUS_OK && o.output_slot != FGSR_NO_SLOT &&
                            o.width == extent_.width && o.height == extent_.height &&
                            o.format == uint32_t(link_.shape().format) &&
                            o.row_pitch >= extent_.width * FGSR_COLOR_FORMAT_BYTES(o.format) &&
                            o.output_index < wanted && o.pixels;
        if (usable) {
            out.push_back(Generated{o.output_slot, o.output_index + 1, o.telemetry.target_time, o.pixels,
                                    o.row_pitch, o.sequence, o.output_index, o.telemetry.frame_type,
                                    o.telemetry.submit_ns, monotonic_ns()});
        } else if (o.output_slot != FGSR_NO_SLOT) {
            fgsr_release_output(session, o.output_slot);
        }
        if (o.flags & FGSR_COMPLETION_LAST) break;
    }
    return true;
}

void Swapchain::release(const Generated& g) {
    if (link_.session()) fgsr_release_output(link_.session(), g.output_slot);
}

bool Swapchain::present_generated(const Item& item, const Generated& g, uint64_t intended_ns) {
    const uint32_t u = next_upload_;
    next_upload_ = (next_upload_ + 1) % (kMaxMultiplier - 1);
    Slot& up = uploads_[u];
    if (upload_pending_[u]) up.fence.wait();
    upload_pending_[u] = false;
    const uint32_t bpp = swapchain_bytes_per_pixel(kind_);
    from_fgsr(kind_, {g.pixels, g.row_pitch}, {up.staging.data(), extent_.width * bpp}, extent_.width,
              extent_.height);
    up.staging.flush();
    if (Report::get().dumping()) {
        std::vector<uint8_t> rgba(size_t(extent_.width) * extent_.height * 4);
        fgsr_to_rgba8(link_.shape().format, {g.pixels, g.row_pitch}, {rgba.data(), extent_.width * 4},
                      extent_.width, extent_.height);
        const float alpha = float(g.index) / float(item.cfg.multiplier);
        Report::get().dump(DumpInfo{extent_.width, extent_.height, item.app_present, g.index, alpha,
                                    item.cfg.mode, item.cfg.multiplier},
                           rgba.data());
    }
    release(g);
    // An image of our own: at most one interval of waiting, else this frame is dropped.
    uint32_t index = 0;
    const uint64_t deadline = monotonic_ns() + std::max<uint64_t>(item.interval_ns, 20'000'000);
    VkResult r;
    for (;;) {
        {
            std::lock_guard l(acquire_mutex_);
            r = dev_.vk.AcquireNextImageKHR(dev_.device, handle_, 2'000'000, VK_NULL_HANDLE,
                                            acquire_fence_.get(), &index);
        }
        if ((r != VK_TIMEOUT && r != VK_NOT_READY) || monotonic_ns() >= deadline) break;
    }
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) {
        note_result(r);
        return false;
    }
    acquire_fence_.wait();
    acquire_fence_.reset();
    if (index >= images_.size()) return false;
    r = record_upload(dev_, up.cmd, up.staging.buffer(), images_[index], extent_);
    if (r == VK_SUCCESS) r = up.fence.reset();
    VkSemaphore ready = image_ready_[index].get();
    if (r == VK_SUCCESS) {
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.commandBufferCount = 1;
        si.pCommandBuffers = &up.cmd;
        si.signalSemaphoreCount = 1;
        si.pSignalSemaphores = &ready;
        std::lock_guard l(dev_.queue_mutex);
        r = dev_.vk.QueueSubmit(item.queue, 1, &si, up.fence.get());
    }
    if (r != VK_SUCCESS) {
        // The image is ours and must go back: present it unchanged is not possible without a
        // signalled semaphore, so present with none (its contents are the previous frame's).
        note_result(call_present(item.queue, index, VK_NULL_HANDLE));
        return false;
    }
    upload_pending_[u] = true;
    uint64_t id = 0;
    note_result(call_present(item.queue, index, ready, &id));
    const uint64_t call = monotonic_ns();
    display_.add(id, call, [this, item, g, intended_ns, call](uint64_t shown) {
        Report::get().present(PresentKind::generated, item.app_present, item.entry_ns, intended_ns, shown, call,
                              uint64_t(handle_));
        report_present(g.sequence, g.output_index, g.frame_type, g.submit_ns, g.received_ns, intended_ns, shown,
                       false);
    });
    return true;
}

void Swapchain::report_present(uint64_t sequence, uint32_t output_index, uint32_t frame_type, uint64_t submit_ns,
                               uint64_t received_ns, uint64_t intended_ns, uint64_t presented_ns, bool dropped) {
    fgsr_session* session = link_.session();
    if (!session) return;
    fgsr_present_report r{};
    r.sequence = sequence;
    r.output_index = output_index;
    r.frame_type = frame_type;
    r.flags = dropped ? FGSR_REPORT_DROPPED : 0u;
    r.submit_ns = submit_ns;
    r.received_ns = received_ns;
    r.intended_ns = intended_ns;
    r.presented_ns = presented_ns;
    // UNSUPPORTED (an older daemon) and a full socket only lose the report.
    (void)fgsr_report_presents(session, &r, 1);
}

} // namespace fgsr::layer
