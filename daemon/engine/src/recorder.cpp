// Command recording (recorder.hpp): the session's command buffer, fence, descriptor and query
// pools; submission and waiting; barriers; timestamps and their CLOCK_MONOTONIC pairing; binding
// a variant's pipeline with its slots.
#include <fgsr/core/clock.hpp>

#include "recorder.hpp"

#include <cmath>
#include <string>

namespace fgsr {

Recorder::~Recorder() {
    if (!ctx_) return;
    if (queries_) vkDestroyQueryPool(ctx_->device, queries_, nullptr);
    if (desc_pool_) vkDestroyDescriptorPool(ctx_->device, desc_pool_, nullptr);
    if (fence_) vkDestroyFence(ctx_->device, fence_, nullptr);
    if (cmd_pool_) vkDestroyCommandPool(ctx_->device, cmd_pool_, nullptr);
}

Result<void> Recorder::init(vk::Context& ctx, Pipelines& pipelines, uint32_t group, uint32_t max_sets,
                            uint32_t query_count) {
    ctx_ = &ctx;
    pipelines_ = &pipelines;
    group_ = group;
    query_count_ = query_count;
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = ctx.queue_family;
    FGSR_VK(vkCreateCommandPool(ctx.device, &pi, nullptr, &cmd_pool_), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = cmd_pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    FGSR_VK(vkAllocateCommandBuffers(ctx.device, &ai, &cmd_), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    FGSR_VK(vkCreateFence(ctx.device, &fi, nullptr, &fence_), "vkCreateFence");
    const std::array<VkDescriptorPoolSize, 2> ps{{{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, max_sets * kMaxBindings},
                                                  {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, max_sets * kMaxBindings}}};
    VkDescriptorPoolCreateInfo di{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    di.maxSets = max_sets;
    di.poolSizeCount = uint32_t(ps.size());
    di.pPoolSizes = ps.data();
    FGSR_VK(vkCreateDescriptorPool(ctx.device, &di, nullptr, &desc_pool_), "vkCreateDescriptorPool");
    VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = query_count;
    FGSR_VK(vkCreateQueryPool(ctx.device, &qi, nullptr, &queries_), "vkCreateQueryPool");
    return {};
}

Result<void> Recorder::begin() {
    FGSR_VK(vkResetDescriptorPool(ctx_->device, desc_pool_, 0), "vkResetDescriptorPool");
    FGSR_VK(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    FGSR_VK(vkBeginCommandBuffer(cmd_, &bi), "vkBeginCommandBuffer");
    vkCmdResetQueryPool(cmd_, queries_, 0, query_count_);
    return {};
}

Result<void> Recorder::finish(bool timed) {
    FGSR_VK(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd_;
    FGSR_VK(vkResetFences(ctx_->device, 1, &fence_), "vkResetFences");
    const uint64_t submit_ns = monotonic_ns();
    {
        std::lock_guard lock(ctx_->queue_mutex);
        FGSR_VK(vkQueueSubmit(ctx_->queue, 1, &si, fence_), "vkQueueSubmit");
    }
    FGSR_VK(vkWaitForFences(ctx_->device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    if (!timed) return {};
    if (ctx_->get_calibrated_timestamps) {
        std::array<VkCalibratedTimestampInfoEXT, 2> info{};
        info[0] = {VK_STRUCTURE_TYPE_CALIBRATED_TIMESTAMP_INFO_EXT, nullptr, VK_TIME_DOMAIN_DEVICE_EXT};
        info[1] = {VK_STRUCTURE_TYPE_CALIBRATED_TIMESTAMP_INFO_EXT, nullptr,
                   VK_TIME_DOMAIN_CLOCK_MONOTONIC_EXT};
        std::array<uint64_t, 2> ts{};
        uint64_t deviation = 0;
        FGSR_VK(ctx_->get_calibrated_timestamps(ctx_->device, 2, info.data(), ts.data(), &deviation),
                "vkGetCalibratedTimestampsEXT");
        calib_tick_ = ts[0];
        calib_ns_ = ts[1];
        return {};
    }
    uint64_t first = 0;
    FGSR_VK(vkGetQueryPoolResults(ctx_->device, queries_, 0, 1, 8, &first, 8,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    calib_tick_ = first;
    calib_ns_ = submit_ns;
    return {};
}

uint64_t Recorder::tick_ns(uint64_t tick) const {
    const uint64_t mask =
        ctx_->timestamp_valid_bits >= 64 ? ~0ull : ((1ull << ctx_->timestamp_valid_bits) - 1);
    uint64_t diff = (tick - calib_tick_) & mask;
    int64_t signed_diff = int64_t(diff);
    if (mask != ~0ull && diff > mask / 2) signed_diff = int64_t(diff) - int64_t(mask) - 1;
    const double ns = double(signed_diff) * double(ctx_->props.limits.timestampPeriod);
    return uint64_t(int64_t(calib_ns_) + int64_t(std::llround(ns)));
}

void Recorder::barrier() {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                       VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT |
                       VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                         0, 1, &mb, 0, nullptr, 0, nullptr);
}

void Recorder::timestamp(uint32_t query) {
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, queries_, query);
}

Result<void> Recorder::bind_slots(Variant v, PassId pass, Layout layout, std::span<const BufRef> slots,
                                  const void* push) {
    const VariantInfo& info = variant_info(v);
    if (info.pass != pass || info.layout != layout || slots.size() != variant_bindings(v))
        return make_error(Errc::invalid_argument, "internal: " + std::string(info.shader) +
                                                      " dispatched with the bindings of another pass");
    const uint32_t texels = variant_texels(v);
    for (size_t i = 0; i < slots.size(); ++i) {
        const bool texel = (texels >> i) & 1u;
        if (slots[i].buffer == VK_NULL_HANDLE || (texel && slots[i].view == VK_NULL_HANDLE))
            return make_error(Errc::invalid_argument, "internal: " + std::string(info.shader) + " binding " +
                                                          std::to_string(i) + " is unbound" +
                                                          (texel ? " (or has no texel view)" : ""));
        if (texel && (slots[i].offset != 0 || slots[i].range != VK_WHOLE_SIZE))
            return make_error(Errc::invalid_argument, "internal: " + std::string(info.shader) + " binding " +
                                                          std::to_string(i) + ": a texel binding is a whole buffer");
    }
    auto pipe = pipelines_->get(v);
    if (!pipe) return pipe.error();
    const vk::Pipeline& p = **pipe;
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = desc_pool_;
    ai.descriptorSetCount = 1;
    VkDescriptorSetLayout set_layout = p.set_layout();
    ai.pSetLayouts = &set_layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    FGSR_VK(vkAllocateDescriptorSets(ctx_->device, &ai, &set), "vkAllocateDescriptorSets");
    std::array<VkDescriptorBufferInfo, kMaxBindings> infos{};
    std::array<VkWriteDescriptorSet, kMaxBindings> writes{};
    uint32_t i = 0;
    for (const BufRef& b : slots) {
        infos[i] = VkDescriptorBufferInfo{b.buffer, b.offset, b.range};
        writes[i] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        if ((texels >> i) & 1u) {
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
            writes[i].pTexelBufferView = &b.view;
        } else {
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        ++i;
    }
    vkUpdateDescriptorSets(ctx_->device, i, writes.data(), 0, nullptr);
    vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, p.handle());
    vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd_, p.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, p.push_size(), push);
    return {};
}

Result<std::vector<PassTiming>> Recorder::read_times(uint32_t first, uint32_t count) {
    std::vector<uint64_t> ticks(count + 1);
    FGSR_VK(vkGetQueryPoolResults(ctx_->device, queries_, first, count + 1, ticks.size() * 8, ticks.data(), 8,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    const uint64_t mask =
        ctx_->timestamp_valid_bits >= 64 ? ~0ull : ((1ull << ctx_->timestamp_valid_bits) - 1);
    std::vector<PassTiming> t(count);
    for (uint32_t i = 0; i < count; ++i) {
        t[i].ms =
            double((ticks[i + 1] - ticks[i]) & mask) * double(ctx_->props.limits.timestampPeriod) * 1e-6;
        t[i].begin_ns = tick_ns(ticks[i]);
        t[i].end_ns = tick_ns(ticks[i + 1]);
    }
    return t;
}

} // namespace fgsr
