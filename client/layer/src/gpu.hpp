// The layer's own Vulkan objects, each owned by one move-only handle that destroys it through the
// device's next-layer dispatch: host-visible staging buffers, fences, semaphores, command pools.
// Also the two transfers the layer records: swapchain image -> buffer (the presented frame) and
// buffer -> swapchain image (a generated frame). Errors are VkResults.
#pragma once

#include "dispatch.hpp"

#include <cstdint>
#include <utility>

namespace fgsr::layer {

class StagingBuffer {
  public:
    StagingBuffer() = default;
    // A host-visible buffer of `size` bytes with TRANSFER_SRC|DST usage, mapped (host-cached memory
    // preferred: the layer reads it back).
    static VkResult create(DeviceData& dev, VkDeviceSize size, StagingBuffer& out);
    StagingBuffer(StagingBuffer&& o) noexcept { *this = std::move(o); }
    StagingBuffer& operator=(StagingBuffer&& o) noexcept;
    ~StagingBuffer() { reset(); }

    VkBuffer buffer() const { return buffer_; }
    void* data() const { return mapped_; }
    VkDeviceSize size() const { return size_; }
    // Make device writes visible to the host / host writes visible to the device (no-ops on
    // coherent memory).
    void invalidate() const;
    void flush() const;

  private:
    void reset();
    DeviceData* dev_ = nullptr;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
    VkDeviceSize size_ = 0;
    bool coherent_ = true;
};

// A fence or semaphore (T) with its destroy call.
class Fence {
  public:
    Fence() = default;
    static VkResult create(DeviceData& dev, bool signaled, Fence& out);
    Fence(Fence&& o) noexcept
        : dev_(std::exchange(o.dev_, nullptr)), h_(std::exchange(o.h_, VK_NULL_HANDLE)) {}
    Fence& operator=(Fence&& o) noexcept {
        std::swap(dev_, o.dev_);
        std::swap(h_, o.h_);
        return *this;
    }
    ~Fence() {
        if (h_) dev_->vk.DestroyFence(dev_->device, h_, nullptr);
    }
    VkFence get() const { return h_; }
    VkResult wait(uint64_t timeout_ns = UINT64_MAX) const {
        return dev_->vk.WaitForFences(dev_->device, 1, &h_, VK_TRUE, timeout_ns);
    }
    VkResult reset() const { return dev_->vk.ResetFences(dev_->device, 1, &h_); }

  private:
    DeviceData* dev_ = nullptr;
    VkFence h_ = VK_NULL_HANDLE;
};

class Semaphore {
  public:
    Semaphore() = default;
    static VkResult create(DeviceData& dev, Semaphore& out);
    Semaphore(Semaphore&& o) noexcept
        : dev_(std::exchange(o.dev_, nullptr)), h_(std::exchange(o.h_, VK_NULL_HANDLE)) {}
    Semaphore& operator=(Semaphore&& o) noexcept {
        std::swap(dev_, o.dev_);
        std::swap(h_, o.h_);
        return *this;
    }
    ~Semaphore() {
        if (h_) dev_->vk.DestroySemaphore(dev_->device, h_, nullptr);
    }
    VkSemaphore get() const { return h_; }

  private:
    DeviceData* dev_ = nullptr;
    VkSemaphore h_ = VK_NULL_HANDLE;
};

// A command pool (resettable buffers) on one queue family; its command buffers are freed with it.
// Externally synchronised: one thread records from one pool.
class CommandPool {
  public:
    CommandPool() = default;
    static VkResult create(DeviceData& dev, uint32_t family, CommandPool& out);
    CommandPool(CommandPool&& o) noexcept
        : dev_(std::exchange(o.dev_, nullptr)), h_(std::exchange(o.h_, VK_NULL_HANDLE)) {}
    CommandPool& operator=(CommandPool&& o) noexcept {
        std::swap(dev_, o.dev_);
        std::swap(h_, o.h_);
        return *this;
    }
    ~CommandPool() {
        if (h_) dev_->vk.DestroyCommandPool(dev_->device, h_, nullptr);
    }
    // A primary command buffer, with the loader's dispatch set on it.
    VkResult allocate(VkCommandBuffer& out) const;

  private:
    DeviceData* dev_ = nullptr;
    VkCommandPool h_ = VK_NULL_HANDLE;
};

// Records into `cmd` (reset and begun here, ended here): the presented `image` (PRESENT_SRC, left
// PRESENT_SRC) copied to `buffer`, made visible to host reads.
VkResult record_readback(DeviceData& dev, VkCommandBuffer cmd, VkImage image, VkExtent2D extent,
                         VkBuffer buffer);
// Records `buffer` uploaded into the acquired `image` (contents discarded), left in PRESENT_SRC.
VkResult record_upload(DeviceData& dev, VkCommandBuffer cmd, VkBuffer buffer, VkImage image,
                       VkExtent2D extent);

} // namespace fgsr::layer
