// One application swapchain under the layer. The application's thread (present()) copies each
// presented image into a staging buffer (a submit that waits on the application's semaphores) and
// hands it to the swapchain's present thread; that thread sends the frame to fgsrd, gets the
// generated frames back, uploads each into an image it acquires itself and presents them, paced,
// before (interpolate) or after (extrapolate) the real frame, which it presents too.
//
// Pacing (LayerConfig::pacing even): with P the application's present interval (moving average of
// the times between its vkQueuePresentKHR calls) and R the time the previous real frame was
// presented, generated frame j of m - 1 is presented at R + j P / m (interpolate: then the real
// frame at R + P; extrapolate: the real frame at once, R = now); when the generated frames come
// after R + P / m the whole schedule moves later (interpolation latency: what the daemon needs plus
// (m - 1) / m intervals). When the present thread falls behind (interpolate: two newer frames
// waiting; extrapolate: one), nothing waits: late frames are dropped, so the application's present
// never waits for the daemon. Present modes: FIFO queues every present behind
// vblank (the generated frames count against the display's rate, as they should); MAILBOX may
// replace a generated frame by the next present when they fall into the same vblank; IMMEDIATE
// shows each at its paced time (tearing as the application asked for).
//
// The swapchain is created with kExtraImages more images than asked for (the present thread holds
// up to three real frames and one generated frame) and TRANSFER_SRC|TRANSFER_DST usage. Errors of the
// presents the layer makes (OUT_OF_DATE, SUBOPTIMAL, SURFACE_LOST) are returned by the
// application's next vkQueuePresentKHR.
//
// Thread safety: present(), acquire() and drain() are called by the application (which
// synchronises them per swapchain, as Vulkan requires); the present thread is private.
#pragma once

#include "config.hpp"
#include "daemon_link.hpp"
#include "dispatch.hpp"
#include "gpu.hpp"
#include "pixels.hpp"
#include "present_wait.hpp"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <thread>
#include <vector>

namespace fgsr::layer {

constexpr uint32_t kSlots = 4;       // frames between the application and the present thread
constexpr uint32_t kExtraImages = 4; // held there at most: 3 waiting or in work, 1 generated
constexpr uint32_t kMaxMultiplier = 4;

class Swapchain {
  public:
    // Takes over `handle` (already created with the layer's additions when `managed`).
    Swapchain(DeviceData& dev, VkSwapchainKHR handle, VkFormat format, VkExtent2D extent, bool managed);
    ~Swapchain(); // drains, stops the present thread, waits for the layer's work, frees its objects
    Swapchain(const Swapchain&) = delete;
    Swapchain& operator=(const Swapchain&) = delete;

    VkSwapchainKHR handle() const { return handle_; }
    bool managed() const { return managed_; }

    // The application's present of image `index` on `queue` (one swapchain of its present info).
    VkResult present(VkQueue queue, const VkPresentInfoKHR& info, uint32_t index, const LayerConfig& cfg,
                     uint64_t entry_ns);
    // The application's acquire: the driver's, in short slices under the swapchain's acquire lock
    // (the present thread acquires too). timeout as vkAcquireNextImageKHR's.
    VkResult acquire(uint64_t timeout_ns, VkSemaphore semaphore, VkFence fence, uint32_t device_mask,
                     uint32_t* index);
    // Returns once the present thread has presented (or dropped) everything handed to it.
    void drain();
    // Stops the present thread after its current frame (process exit: no Vulkan calls after).
    void stop();

  private:
    struct Slot {
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        Fence fence;
        StagingBuffer staging;
    };
    struct Item {
        uint32_t slot, image_index;
        VkQueue queue;
        uint64_t entry_ns, app_present, interval_ns;
        LayerConfig cfg;
    };
    struct Generated {
        uint32_t output_slot, index;
        float alpha;
        const void* pixels;
        uint32_t row_pitch;
        uint64_t sequence = 0;       // the submit it came from
        uint32_t output_index = 0;   // within that submit
        uint32_t frame_type = 0;     // fgsr_frame_type
        uint64_t submit_ns = 0, received_ns = 0;
    };
    // Tells fgsrd what became of a frame (its dashboard's frame times and latencies); nothing when
    // no session is up.
    void report_present(uint64_t sequence, uint32_t output_index, uint32_t frame_type, uint64_t submit_ns,
                        uint64_t received_ns, uint64_t intended_ns, uint64_t presented_ns, bool dropped);

    bool init_images();
    bool init_pools(uint32_t family);
    VkResult pass_through(VkQueue queue, const VkPresentInfoKHR& info, uint32_t index, uint64_t app_present);
    // A present of the layer's own; *id (when given) gets its present id (0: present wait unused).
    VkResult call_present(VkQueue queue, uint32_t index, VkSemaphore wait, uint64_t* id = nullptr);
    void thread_main();
    void process(Item& item);
    // Sends the item's frame to fgsrd and collects the generated frames (within the deadline).
    std::vector<Generated> generate(const Item& item, uint64_t deadline_ns);
    bool collect(uint64_t sequence, uint32_t wanted, uint64_t deadline_ns, std::vector<Generated>& out);
    void release(const Generated& g);
    bool present_generated(const Item& item, const Generated& g, uint64_t intended_ns);
    void present_real(const Item& item, uint64_t intended_ns);
    // Sleeps until t (monotonic ns) unless more than `max_waiting` newer frames wait first; false
    // when they do.
    bool sleep_until(uint64_t t_ns, size_t max_waiting);
    void note_result(VkResult r);

    DeviceData& dev_;
    VkSwapchainKHR handle_;
    VkFormat format_;
    VkExtent2D extent_;
    PixelKind kind_;
    bool managed_;

    std::vector<VkImage> images_;
    std::vector<Semaphore> image_ready_; // per image: signalled by the layer's copy, waited by present
    uint32_t family_ = UINT32_MAX;
    CommandPool app_pool_;    // recorded on the application's thread
    CommandPool thread_pool_; // recorded on the present thread
    Slot slots_[kSlots];
    Slot uploads_[kMaxMultiplier - 1];
    bool upload_pending_[kMaxMultiplier - 1] = {};
    uint32_t next_upload_ = 0;
    Fence acquire_fence_;
    std::mutex acquire_mutex_; // the driver's acquire, from either thread

    // Application thread only.
    uint64_t last_entry_ns_ = 0;
    uint64_t interval_ns_ = 0;
    uint64_t app_presents_ = 0;
    VkQueue last_queue_ = VK_NULL_HANDLE;

    // Shared with the present thread (mutex_).
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<Item> queue_;
    uint32_t free_slots_ = (1u << kSlots) - 1; // bit per slot
    bool busy_ = false, stop_ = false;
    std::atomic<VkResult> pending_result_{VK_SUCCESS};
    std::thread thread_;

    // Present thread only.
    DaemonLink link_;
    DisplayClock display_{dev_, handle_, acquire_mutex_};
    uint64_t last_real_ns_ = 0;
    uint64_t last_sequence_ = 0;
};

} // namespace fgsr::layer
