// Command recording of one session: the command buffer and its fence, descriptor sets, barriers,
// timestamp queries and their clock pairing, dispatches of the engine's pipelines with their
// bindings by name (Slots), and synchronous downloads.
#pragma once

#include <fgsr/engine/engine.hpp>

#include "variants.hpp"
#include "vk.hpp"

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <span>
#include <vector>

namespace fgsr {

// The engine's pipelines, one per variant, each created at its first use. lavapipe translates the
// SPIR-V when a pipeline is created, 50-280 ms a variant: creating all 81 with the engine took 3-5 s
// on 2 cores, before fgsrd listened and in every process that made an engine, though a session
// uses a fraction of them. Safe to call from several threads: a variant is created once, a caller
// asking for it meanwhile waits for that creation.
class Pipelines {
  public:
    // ctx outlives this; group: the workgroup side the variants are built for.
    void init(vk::Context& ctx, uint32_t group) {
        ctx_ = &ctx;
        group_ = group;
    }
    Result<const vk::Pipeline*> get(Variant v);
    // Creates every variant not created yet, on up to `threads` threads at once. Returns the first
    // error.
    Result<void> create_all(uint32_t threads);
    // How many variants have been created so far.
    uint32_t created() const;

  private:
    vk::Context* ctx_ = nullptr;
    uint32_t group_ = 8;
    std::array<vk::Pipeline, kVariantCount> pipes_;
    std::array<std::atomic<bool>, kVariantCount> ready_{};
    std::array<std::mutex, kVariantCount> creating_;
};

constexpr uint32_t groups(uint32_t n, uint32_t size) {
    return (n + size - 1) / size;
}

class Recorder {
  public:
    Recorder() = default;
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;
    ~Recorder();

    // pipelines: the engine's, one per variant, built for workgroups of group x group.
    Result<void> init(vk::Context& ctx, Pipelines& pipelines, uint32_t group, uint32_t max_sets,
                      uint32_t query_count);

    VkCommandBuffer cmd() const { return cmd_; }
    uint32_t group() const { return group_; }

    // Resets the descriptor pool, begins the command buffer and resets every query.
    Result<void> begin();
    // Ends, submits and waits. timed: the command buffer wrote timestamp query 0 first; pairs the
    // GPU clock with CLOCK_MONOTONIC for tick_ns() (calibrated timestamps when the device has
    // them, else query 0 is taken to be the CPU time just before vkQueueSubmit).
    Result<void> finish(bool timed = false);

    void barrier();
    void timestamp(uint32_t query);

    // Binds variant v's pipeline, a fresh descriptor set of the slots and the push constants.
    template <PassId P, Layout L> Result<void> bind(Variant v, const Slots<P, L>& s, const void* push) {
        return bind_slots(v, P, L, s.slot, push);
    }
    // ... and dispatches groups_x x groups_y workgroups.
    template <PassId P, Layout L>
    Result<void> dispatch(Variant v, const Slots<P, L>& s, const void* push, uint32_t groups_x,
                          uint32_t groups_y) {
        FGSR_TRY(bind(v, s, push));
        vkCmdDispatch(cmd_, groups_x, groups_y, 1);
        return {};
    }
    // ... one invocation per pixel of a width x height image.
    template <PassId P, Layout L>
    Result<void> dispatch_pixels(Variant v, const Slots<P, L>& s, const void* push, uint32_t width,
                                 uint32_t height) {
        return dispatch(v, s, push, groups(width, group_), groups(height, group_));
    }
    // ... an indirect dispatch whose arguments are at `offset` in `args` (a tile list's header, or
    // the denoise pass's dispatch words).
    template <PassId P, Layout L>
    Result<void> dispatch_indirect(Variant v, const Slots<P, L>& s, const void* push, const vk::Buffer& args,
                                   VkDeviceSize offset = 0) {
        FGSR_TRY(bind(v, s, push));
        vkCmdDispatchIndirect(cmd_, args.handle(), offset);
        return {};
    }

    // Timings between consecutive timestamps [first, first + count] (names and ids left unset).
    Result<std::vector<PassTiming>> read_times(uint32_t first, uint32_t count);

    // Copies a buffer to the host (through a staging buffer when it is not mapped).
    // `count` elements from element `first` on.
    template <class T> Result<std::vector<T>> download(const vk::Buffer& b, size_t count, size_t first = 0) {
        auto staging = vk::Buffer::create(*ctx_, count * sizeof(T), true);
        if (!staging) return staging.error();
        FGSR_TRY(begin());
        VkBufferCopy region{first * sizeof(T), 0, count * sizeof(T)};
        vkCmdCopyBuffer(cmd_, b.handle(), staging->handle(), 1, &region);
        barrier();
        FGSR_TRY(finish());
        std::vector<T> out(count);
        std::memcpy(out.data(), staging->mapped(), count * sizeof(T));
        return out;
    }

  private:
    Result<void> bind_slots(Variant v, PassId pass, Layout layout, std::span<const BufRef> slots,
                            const void* push);
    // CLOCK_MONOTONIC ns of a GPU timestamp of the last timed submission.
    uint64_t tick_ns(uint64_t tick) const;

    vk::Context* ctx_ = nullptr;
    Pipelines* pipelines_ = nullptr;
    uint32_t group_ = 8;
    uint32_t query_count_ = 0;
    VkCommandPool cmd_pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkDescriptorPool desc_pool_ = VK_NULL_HANDLE;
    VkQueryPool queries_ = VK_NULL_HANDLE;
    // Clock pairing of the last timed submission: GPU tick calib_tick is CLOCK_MONOTONIC calib_ns.
    uint64_t calib_tick_ = 0, calib_ns_ = 0;
};

} // namespace fgsr
