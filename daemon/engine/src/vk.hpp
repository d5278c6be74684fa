// Thin RAII layer over the Vulkan objects the engine uses (internal to the engine library).
#pragma once

#include <fgsr/engine/engine.hpp>
#include <fgsr/core/result.hpp>

#include <vulkan/vulkan.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr::vk {

std::string result_string(VkResult r);
inline Error vk_error(const char* what, VkResult r) {
    return make_error(Errc::vulkan, std::string(what) + " failed: " + result_string(r));
}
#define FGSR_VK(call, what)                                                                                  \
    do {                                                                                                     \
        VkResult fgsr_vk_r_ = (call);                                                                        \
        if (fgsr_vk_r_ != VK_SUCCESS) return ::fgsr::vk::vk_error(what, fgsr_vk_r_);                         \
    } while (0)

struct Context {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    // Held around every use of `queue` (vkQueueSubmit, vkDeviceWaitIdle), which Vulkan requires the
    // application to synchronise: sessions of one engine may run on several threads.
    std::mutex queue_mutex;
    uint32_t queue_family = 0;
    VkPhysicalDeviceProperties props{};
    VkPhysicalDeviceMemoryProperties memory{};
    uint32_t timestamp_valid_bits = 0;
    std::atomic<uint64_t> validation_errors{0};
    // VK_EXT_external_memory_host enabled: host allocations can be imported (alignment in bytes).
    bool host_import = false;
    VkDeviceSize host_import_alignment = 0;
    PFN_vkGetMemoryHostPointerPropertiesEXT get_host_pointer_properties = nullptr;
    // VK_EXT_calibrated_timestamps enabled with both the device and the CLOCK_MONOTONIC domain.
    PFN_vkGetCalibratedTimestampsEXT get_calibrated_timestamps = nullptr;

    Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    ~Context();
};

Result<std::unique_ptr<Context>> create_context(const DeviceOptions& options);
Result<std::vector<std::string>> enumerate_devices();

// A buffer with its own memory. host: mapped for the whole lifetime (HOST_VISIBLE|HOST_COHERENT),
// else DEVICE_LOCAL (which on CPU devices is host-visible too, but is not mapped here).
class Buffer {
  public:
    Buffer() = default;
    Buffer(Buffer&& o) noexcept { *this = std::move(o); }
    Buffer& operator=(Buffer&& o) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    ~Buffer() { release(); }

    static Result<Buffer> create(Context& ctx, VkDeviceSize size, bool host);
    // A storage buffer over `size` bytes of host memory at `data` (VK_EXT_external_memory_host;
    // data and size multiples of Context::host_import_alignment). The memory must outlive the
    // buffer; mapped() returns data.
    static Result<Buffer> import_host(Context& ctx, void* data, VkDeviceSize size);
    VkBuffer handle() const { return buffer_; }
    VkDeviceSize size() const { return size_; }
    void* mapped() const { return mapped_; }
    // A view of the whole buffer as texels of `format` (R32_SFLOAT, R32G32_SFLOAT, R32G32B32A32_SFLOAT), for
    // passes that read it as a uniform texel buffer (texelFetch): on llvmpipe a texel fetch is a
    // vector gather, while a storage-buffer load at a per-invocation index is a loop over the SIMD
    // lanes. Created once; lives as long as the buffer. VK_NULL_HANDLE until make_texel_view().
    Result<void> make_texel_view(VkFormat format = VK_FORMAT_R32_SFLOAT);
    VkBufferView texel_view() const { return view_; }

  private:
    void release();
    Context* ctx_ = nullptr;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkBufferView view_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;
    bool imported_ = false;
};

// One compute pipeline: a pass's SPIR-V, `bindings` storage buffers at set 0, `push_size` bytes of
// push constants.
class Pipeline {
  public:
    Pipeline() = default;
    Pipeline(Pipeline&& o) noexcept { *this = std::move(o); }
    Pipeline& operator=(Pipeline&& o) noexcept;
    Pipeline(const Pipeline&) = delete;
    Pipeline& operator=(const Pipeline&) = delete;
    ~Pipeline() { release(); }

    // `shader` names an embedded SPIR-V module ("<pass>_g<group>").
    // Bindings whose bit is set in `texels` are uniform texel buffers, the others storage buffers.
    static Result<Pipeline> create(Context& ctx, std::string_view shader, uint32_t bindings,
                                   uint32_t push_size, uint32_t texels = 0);
    VkPipeline handle() const { return pipeline_; }
    VkPipelineLayout layout() const { return layout_; }
    VkDescriptorSetLayout set_layout() const { return set_layout_; }
    uint32_t bindings() const { return bindings_; }
    uint32_t push_size() const { return push_size_; }

  private:
    void release();
    Context* ctx_ = nullptr;
    VkShaderModule module_ = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    uint32_t bindings_ = 0;
    uint32_t push_size_ = 0;
};

} // namespace fgsr::vk

namespace fgsr::shaders {
std::span<const uint32_t> spirv(std::string_view name);
}
