// Per-instance and per-device state of the layer: the next layer's entry points (filled with
// GetInstanceProcAddr / GetDeviceProcAddr at creation), and the maps from dispatchable handles to
// that state. Maps are keyed by the loader's dispatch key (the first pointer of a dispatchable
// object), which every child of an instance or device shares.
//
// Thread safety: the maps are guarded by a global mutex; an InstanceData/DeviceData is immutable
// after creation except for the members marked otherwise. DeviceData::queue_mutex serialises every
// call that touches a queue of the device (the application's and the layer's present threads).
#pragma once

#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <cstdint>
#include <mutex>
#include <unordered_map>

namespace fgsr::layer {

struct InstanceDispatch {
    PFN_vkGetInstanceProcAddr GetInstanceProcAddr;
    PFN_vkDestroyInstance DestroyInstance;
    PFN_vkEnumerateDeviceExtensionProperties EnumerateDeviceExtensionProperties;
    PFN_vkGetPhysicalDeviceMemoryProperties GetPhysicalDeviceMemoryProperties;
    PFN_vkGetPhysicalDeviceSurfaceCapabilitiesKHR GetPhysicalDeviceSurfaceCapabilitiesKHR;
    PFN_vkGetPhysicalDeviceProperties GetPhysicalDeviceProperties;
    PFN_vkGetPhysicalDeviceFeatures2 GetPhysicalDeviceFeatures2; // null before Vulkan 1.1
};

struct InstanceData {
    VkInstance instance;
    uint32_t api_version; // the application's VkApplicationInfo::apiVersion (1.0 when absent)
    InstanceDispatch vk;
};

struct DeviceDispatch {
    PFN_vkGetDeviceProcAddr GetDeviceProcAddr;
    PFN_vkDestroyDevice DestroyDevice;
    PFN_vkGetDeviceQueue GetDeviceQueue;
    PFN_vkGetDeviceQueue2 GetDeviceQueue2;
    PFN_vkCreateSwapchainKHR CreateSwapchainKHR;
    PFN_vkDestroySwapchainKHR DestroySwapchainKHR;
    PFN_vkGetSwapchainImagesKHR GetSwapchainImagesKHR;
    PFN_vkAcquireNextImageKHR AcquireNextImageKHR;
    PFN_vkAcquireNextImage2KHR AcquireNextImage2KHR;
    PFN_vkQueuePresentKHR QueuePresentKHR;
    PFN_vkQueueSubmit QueueSubmit;
    PFN_vkQueueSubmit2 QueueSubmit2;
    PFN_vkQueueSubmit2KHR QueueSubmit2KHR;
    PFN_vkQueueWaitIdle QueueWaitIdle;
    PFN_vkQueueBindSparse QueueBindSparse;
    PFN_vkDeviceWaitIdle DeviceWaitIdle;
    PFN_vkCreateCommandPool CreateCommandPool;
    PFN_vkDestroyCommandPool DestroyCommandPool;
    PFN_vkAllocateCommandBuffers AllocateCommandBuffers;
    PFN_vkBeginCommandBuffer BeginCommandBuffer;
    PFN_vkEndCommandBuffer EndCommandBuffer;
    PFN_vkResetCommandBuffer ResetCommandBuffer;
    PFN_vkCmdPipelineBarrier CmdPipelineBarrier;
    PFN_vkCmdCopyImageToBuffer CmdCopyImageToBuffer;
    PFN_vkCmdCopyBufferToImage CmdCopyBufferToImage;
    PFN_vkCreateBuffer CreateBuffer;
    PFN_vkDestroyBuffer DestroyBuffer;
    PFN_vkGetBufferMemoryRequirements GetBufferMemoryRequirements;
    PFN_vkAllocateMemory AllocateMemory;
    PFN_vkFreeMemory FreeMemory;
    PFN_vkBindBufferMemory BindBufferMemory;
    PFN_vkMapMemory MapMemory;
    PFN_vkInvalidateMappedMemoryRanges InvalidateMappedMemoryRanges;
    PFN_vkFlushMappedMemoryRanges FlushMappedMemoryRanges;
    PFN_vkCreateFence CreateFence;
    PFN_vkDestroyFence DestroyFence;
    PFN_vkWaitForFences WaitForFences;
    PFN_vkResetFences ResetFences;
    PFN_vkCreateSemaphore CreateSemaphore;
    PFN_vkDestroySemaphore DestroySemaphore;
    PFN_vkWaitForPresentKHR WaitForPresentKHR; // null unless use_present_wait
};

struct DeviceData {
    VkDevice device;
    VkPhysicalDevice physical_device;
    InstanceData* instance;
    DeviceDispatch vk;
    PFN_vkSetDeviceLoaderData set_loader_data;
    VkPhysicalDeviceMemoryProperties memory;
    bool has_present_wait;  // VK_KHR_present_id + VK_KHR_present_wait offered by the driver
    bool use_present_wait;  // and enabled by the layer (its presents carry ids; display times)
    std::mutex queue_mutex; // every queue operation of this device, from any thread
    std::mutex families_mutex;
    std::unordered_map<VkQueue, uint32_t> queue_family; // guarded by families_mutex
};

inline void* dispatch_key(const void* handle) {
    return *static_cast<void* const*>(handle);
}

// Memory type index with `required` properties among `type_bits`, or UINT32_MAX.
inline uint32_t find_memory_type(const VkPhysicalDeviceMemoryProperties& m, uint32_t type_bits,
                                 VkMemoryPropertyFlags required) {
    for (uint32_t i = 0; i < m.memoryTypeCount; ++i)
        if ((type_bits & (1u << i)) && (m.memoryTypes[i].propertyFlags & required) == required) return i;
    return UINT32_MAX;
}

} // namespace fgsr::layer
