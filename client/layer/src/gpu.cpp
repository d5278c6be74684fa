// The layer's own Vulkan objects and transfers (gpu.hpp).
#include "gpu.hpp"

namespace fgsr::layer {

VkResult StagingBuffer::create(DeviceData& dev, VkDeviceSize size, StagingBuffer& out) {
    StagingBuffer b;
    b.dev_ = &dev;
    b.size_ = size;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (VkResult r = dev.vk.CreateBuffer(dev.device, &bi, nullptr, &b.buffer_); r != VK_SUCCESS) return r;
    VkMemoryRequirements req{};
    dev.vk.GetBufferMemoryRequirements(dev.device, b.buffer_, &req);
    const VkMemoryPropertyFlags visible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
    const VkMemoryPropertyFlags coherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags cached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    uint32_t type = find_memory_type(dev.memory, req.memoryTypeBits, visible | coherent | cached);
    if (type == UINT32_MAX) type = find_memory_type(dev.memory, req.memoryTypeBits, visible | cached);
    if (type == UINT32_MAX) type = find_memory_type(dev.memory, req.memoryTypeBits, visible | coherent);
    if (type == UINT32_MAX) type = find_memory_type(dev.memory, req.memoryTypeBits, visible);
    if (type == UINT32_MAX) return VK_ERROR_FEATURE_NOT_PRESENT;
    b.coherent_ = (dev.memory.memoryTypes[type].propertyFlags & coherent) != 0;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    if (VkResult r = dev.vk.AllocateMemory(dev.device, &ai, nullptr, &b.memory_); r != VK_SUCCESS) return r;
    if (VkResult r = dev.vk.BindBufferMemory(dev.device, b.buffer_, b.memory_, 0); r != VK_SUCCESS) return r;
    if (VkResult r = dev.vk.MapMemory(dev.device, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_);
        r != VK_SUCCESS)
        return r;
    out = std::move(b);
    return VK_SUCCESS;
}

StagingBuffer& StagingBuffer::operator=(StagingBuffer&& o) noexcept {
    std::swap(dev_, o.dev_);
    std::swap(buffer_, o.buffer_);
    std::swap(memory_, o.memory_);
    std::swap(mapped_, o.mapped_);
    std::swap(size_, o.size_);
    std::swap(coherent_, o.coherent_);
    return *this;
}

void StagingBuffer::reset() {
    if (!dev_) return;
    if (buffer_) dev_->vk.DestroyBuffer(dev_->device, buffer_, nullptr);
    if (memory_) dev_->vk.FreeMemory(dev_->device, memory_, nullptr); // unmaps
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    mapped_ = nullptr;
}

void StagingBuffer::invalidate() const {
    if (coherent_) return;
    VkMappedMemoryRange r{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_, 0, VK_WHOLE_SIZE};
    dev_->vk.InvalidateMappedMemoryRanges(dev_->device, 1, &r);
}

void StagingBuffer::flush() const {
    if (coherent_) return;
    VkMappedMemoryRange r{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_, 0, VK_WHOLE_SIZE};
    dev_->vk.FlushMappedMemoryRanges(dev_->device, 1, &r);
}

VkResult Fence::create(DeviceData& dev, bool signaled, Fence& out) {
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fi.flags = signaled ? VK_FENCE_CREATE_SIGNALED_BIT : 0;
    Fence f;
    f.dev_ = &dev;
    const VkResult r = dev.vk.CreateFence(dev.device, &fi, nullptr, &f.h_);
    if (r == VK_SUCCESS) out = std::move(f);
    return r;
}

VkResult Semaphore::create(DeviceData& dev, Semaphore& out) {
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    Semaphore s;
    s.dev_ = &dev;
    const VkResult r = dev.vk.CreateSemaphore(dev.device, &si, nullptr, &s.h_);
    if (r == VK_SUCCESS) out = std::move(s);
    return r;
}

VkResult CommandPool::create(DeviceData& dev, uint32_t family, CommandPool& out) {
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    ci.queueFamilyIndex = family;
    CommandPool p;
    p.dev_ = &dev;
    const VkResult r = dev.vk.CreateCommandPool(dev.device, &ci, nullptr, &p.h_);
    if (r == VK_SUCCESS) out = std::move(p);
    return r;
}

VkResult CommandPool::allocate(VkCommandBuffer& out) const {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = h_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if (VkResult r = dev_->vk.AllocateCommandBuffers(dev_->device, &ai, &out); r != VK_SUCCESS) return r;
    // Command buffers the layer makes need the loader's dispatch pointer, as the loader would set it.
    return dev_->set_loader_data(dev_->device, out);
}

namespace {

VkImageMemoryBarrier image_barrier(VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                                   VkAccessFlags dst) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    return b;
}

VkBufferImageCopy whole_image(VkExtent2D extent) {
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    c.imageExtent = {extent.width, extent.height, 1};
    return c;
}

VkResult begin(DeviceData& dev, VkCommandBuffer cmd) {
    if (VkResult r = dev.vk.ResetCommandBuffer(cmd, 0); r != VK_SUCCESS) return r;
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    return dev.vk.BeginCommandBuffer(cmd, &bi);
}

} // namespace

VkResult record_readback(DeviceData& dev, VkCommandBuffer cmd, VkImage image, VkExtent2D extent,
                         VkBuffer buffer) {
    if (VkResult r = begin(dev, cmd); r != VK_SUCCESS) return r;
    const VkImageMemoryBarrier to_src =
        image_barrier(image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    dev.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                              nullptr, 0, nullptr, 1, &to_src);
    const VkBufferImageCopy region = whole_image(extent);
    dev.vk.CmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    const VkImageMemoryBarrier back =
        image_barrier(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                      VK_ACCESS_TRANSFER_READ_BIT, 0);
    VkBufferMemoryBarrier host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    host.buffer = buffer;
    host.size = VK_WHOLE_SIZE;
    dev.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                              nullptr, 1, &host, 1, &back);
    return dev.vk.EndCommandBuffer(cmd);
}

VkResult record_upload(DeviceData& dev, VkCommandBuffer cmd, VkBuffer buffer, VkImage image,
                       VkExtent2D extent) {
    if (VkResult r = begin(dev, cmd); r != VK_SUCCESS) return r;
    const VkImageMemoryBarrier to_dst =
        image_barrier(image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                      VK_ACCESS_TRANSFER_WRITE_BIT);
    dev.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                              VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &to_dst);
    const VkBufferImageCopy region = whole_image(extent);
    dev.vk.CmdCopyBufferToImage(cmd, buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    const VkImageMemoryBarrier to_present =
        image_barrier(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                      VK_ACCESS_TRANSFER_WRITE_BIT, 0);
    dev.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0,
                              nullptr, 0, nullptr, 1, &to_present);
    return dev.vk.EndCommandBuffer(cmd);
}

} // namespace fgsr::layer
