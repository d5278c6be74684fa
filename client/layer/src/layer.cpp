// VK_LAYER_FGSR_frame_generation: the loader-facing side of the layer. Negotiation, instance and
// device creation (dispatch tables from the next layer), the calls it intercepts and the
// process-wide state: configuration, swapchains, the exit hook that writes the stats.
//
// Intercepted: vkCreateInstance/vkDestroyInstance, vkCreateDevice/vkDestroyDevice,
// vkGetDeviceQueue(2) (queue families), vkCreateSwapchainKHR (extra images, transfer usage),
// vkDestroySwapchainKHR, vkAcquireNextImage(2)KHR (the layer acquires too), vkQueuePresentKHR,
// and every queue operation (vkQueueSubmit(2), vkQueueWaitIdle, vkQueueBindSparse,
// vkDeviceWaitIdle), which take the device's queue mutex because the layer's present threads use
// the application's queue.
#include "config.hpp"
#include "dispatch.hpp"
#include "lazy.hpp"
#include "report.hpp"
#include "swapchain.hpp"

#include <fgsr/core/clock.hpp>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#define FGSR_LAYER_EXPORT extern "C" __attribute__((visibility("default")))

namespace fgsr::layer {
namespace {

struct Globals {
    std::mutex mutex;
    std::unordered_map<void*, InstanceData*> instances; // by dispatch key
    std::unordered_map<void*, DeviceData*> devices;     // by dispatch key
    std::unordered_map<VkSwapchainKHR, Swapchain*> swapchains;
    std::unordered_map<VkSwapchainKHR, DeviceData*> swapchain_device;
    std::mutex config_mutex;
    std::unique_ptr<ConfigWatcher> config;
};

// The process-wide state (lazy.hpp): freed by the exit hook once the application has destroyed
// everything it made (release_globals).
Lazy<Globals> globals;

Globals& g() {
    return globals.get();
}

// Frees the process-wide state (Globals and the Report) when no instance, device or swapchain of
// the application's is left: then no layer thread runs and no call can reach them. Otherwise (the
// process exits with its Vulkan objects alive) they stay, reachable, for the threads still stopping.
void release_globals() {
    bool freed = false;
    globals.reset_if([&](Globals& s) {
        std::lock_guard l(s.mutex);
        freed = s.instances.empty() && s.devices.empty() && s.swapchains.empty();
        return freed;
    });
    if (freed) Report::release();
}

void log_config(const Result<LayerConfig>& c, const std::string& path, bool reload) {
    if (!c) {
        log_line("configuration error, passing frames through: " + c.error().message);
        return;
    }
    log_line(std::string(reload ? "configuration reloaded" : "configuration") + " (" +
             (path.empty() ? "no file" : path) + "): " + (c->enabled ? "enabled" : "disabled") +
             ", multiplier " + std::to_string(c->multiplier) + ", " + mode_name(c->mode) + ", pacing " +
             (c->pacing == Pacing::even ? "even" : "none") + ", motion " + motion_name(c->motion) +
             (c->fps_limit > 0 ? ", fps limit " + std::to_string(c->fps_limit) : "") +
             (c->profile.empty() ? "" : ", profile " + c->profile));
}

// The configuration now (re-read at most every 0.5 s); a configuration error disables the layer.
LayerConfig current_config() {
    Globals& s = g();
    std::lock_guard l(s.config_mutex);
    if (!s.config) {
        s.config = std::make_unique<ConfigWatcher>(config_path_from_process(), executable_name(),
                                                   config_env_from_process());
        log_config(s.config->current(), s.config->path(), false);
    } else if (s.config->poll(monotonic_ns())) {
        log_config(s.config->current(), s.config->path(), true);
    }
    LayerConfig c = s.config->current() ? *s.config->current() : LayerConfig{};
    if (!s.config->current()) c.enabled = false;
    Report::get().set_config(c);
    return c;
}

void at_exit() {
    Globals& s = g();
    {
        std::lock_guard l(s.mutex);
        for (auto& [handle, sc] : s.swapchains) sc->stop(); // no Vulkan calls: the driver may be gone
    }
    Report::get().write_files();
}

// Runs at_exit, then release_globals, at the process's exit, or when the loader unloads the layer
// (dlclose, at the last vkDestroyInstance) if that comes first. A static's destructor is
// registered with the layer's own DSO handle (__cxa_atexit), as glibc registers atexit() called
// from a shared library; std::atexit under ThreadSanitizer lost the handle, and the process's exit
// then called into the unloaded layer.
struct ExitHook {
    ~ExitHook() {
        at_exit();
        release_globals();
    }
};

template <class T> T* find_chain(const void* pnext, VkStructureType type, VkLayerFunction function) {
    for (auto* p = static_cast<const VkBaseInStructure*>(pnext); p; p = p->pNext) {
        if (p->sType != type) continue;
        auto* info = reinterpret_cast<T*>(const_cast<VkBaseInStructure*>(p));
        if (info->function == function) return info;
    }
    return nullptr;
}

InstanceData* instance_of(const void* handle) {
    std::lock_guard l(g().mutex);
    auto it = g().instances.find(dispatch_key(handle));
    return it == g().instances.end() ? nullptr : it->second;
}

DeviceData* device_of(const void* handle) {
    std::lock_guard l(g().mutex);
    auto it = g().devices.find(dispatch_key(handle));
    return it == g().devices.end() ? nullptr : it->second;
}

Swapchain* swapchain_of(VkSwapchainKHR h) {
    std::lock_guard l(g().mutex);
    auto it = g().swapchains.find(h);
    return it == g().swapchains.end() ? nullptr : it->second;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* ci,
                                              const VkAllocationCallbacks* alloc, VkInstance* out) {
    auto* link = find_chain<VkLayerInstanceCreateInfo>(
        ci->pNext, VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO, VK_LAYER_LINK_INFO);
    if (!link || !link->u.pLayerInfo) return VK_ERROR_INITIALIZATION_FAILED;
    PFN_vkGetInstanceProcAddr gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
    link->u.pLayerInfo = link->u.pLayerInfo->pNext;
    auto create = reinterpret_cast<PFN_vkCreateInstance>(gipa(VK_NULL_HANDLE, "vkCreateInstance"));
    if (!create) return VK_ERROR_INITIALIZATION_FAILED;
    const VkResult r = create(ci, alloc, out);
    if (r != VK_SUCCESS) return r;
    auto* d = new InstanceData{};
    d->instance = *out;
#define FGSR_INSTANCE_FN(name) d->vk.name = reinterpret_cast<PFN_vk##name>(gipa(*out, "vk" #name))
    d->vk.GetInstanceProcAddr = gipa;
    FGSR_INSTANCE_FN(DestroyInstance);
    FGSR_INSTANCE_FN(EnumerateDeviceExtensionProperties);
    FGSR_INSTANCE_FN(GetPhysicalDeviceMemoryProperties);
    FGSR_INSTANCE_FN(GetPhysicalDeviceSurfaceCapabilitiesKHR);
    FGSR_INSTANCE_FN(GetPhysicalDeviceProperties);
    d->api_version = ci->pApplicationInfo && ci->pApplicationInfo->apiVersion ? ci->pApplicationInfo->apiVersion
                                                                              : VK_API_VERSION_1_0;
    if (d->api_version >= VK_API_VERSION_1_1) FGSR_INSTANCE_FN(GetPhysicalDeviceFeatures2);
#undef FGSR_INSTANCE_FN
    current_config(); // loads and logs the configuration once per process
    std::lock_guard l(g().mutex);
    g().instances[dispatch_key(*out)] = d;
    static ExitHook exit_hook; // once per process
    (void)exit_hook;
    return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance instance, const VkAllocationCallbacks* alloc) {
    InstanceData* d = instance_of(instance);
    if (!d) return;
    {
        std::lock_guard l(g().mutex);
        g().instances.erase(dispatch_key(instance));
    }
    d->vk.DestroyInstance(instance, alloc);
    delete d;
    Report::get().write_files();
}

// Whether the layer can enable VK_KHR_present_id and VK_KHR_present_wait for itself: the driver
// offers both extensions and both features (queried with Vulkan 1.1's vkGetPhysicalDeviceFeatures2,
// so the application's instance and the device must be 1.1 or later), and the application does
// not use either (its present ids and the layer's would mix on the same swapchains).
struct PresentWaitSupport {
    bool offered = false, usable = false;
    std::string why; // when offered but not usable
};

PresentWaitSupport present_wait_support(const InstanceData& inst, VkPhysicalDevice physical,
                                        const VkDeviceCreateInfo& ci) {
    PresentWaitSupport s;
    uint32_t n = 0;
    inst.vk.EnumerateDeviceExtensionProperties(physical, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    inst.vk.EnumerateDeviceExtensionProperties(physical, nullptr, &n, exts.data());
    exts.resize(n);
    bool id = false, wait = false;
    for (const VkExtensionProperties& e : exts) {
        id |= std::strcmp(e.extensionName, VK_KHR_PRESENT_ID_EXTENSION_NAME) == 0;
        wait |= std::strcmp(e.extensionName, VK_KHR_PRESENT_WAIT_EXTENSION_NAME) == 0;
    }
    s.offered = id && wait;
    if (!s.offered) return s;
    for (uint32_t i = 0; i < ci.enabledExtensionCount; ++i)
        if (std::strcmp(ci.ppEnabledExtensionNames[i], VK_KHR_PRESENT_ID_EXTENSION_NAME) == 0 ||
            std::strcmp(ci.ppEnabledExtensionNames[i], VK_KHR_PRESENT_WAIT_EXTENSION_NAME) == 0) {
            s.why = "the application uses it itself";
            return s;
        }
    for (auto* p = static_cast<const VkBaseInStructure*>(ci.pNext); p; p = p->pNext)
        if (p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_ID_FEATURES_KHR ||
            p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_WAIT_FEATURES_KHR) {
            s.why = "the application uses it itself";
            return s;
        }
    VkPhysicalDeviceProperties props{};
    inst.vk.GetPhysicalDeviceProperties(physical, &props);
    if (!inst.vk.GetPhysicalDeviceFeatures2 || props.apiVersion < VK_API_VERSION_1_1) {
        s.why = "needs Vulkan 1.1 (application and device) to query its features";
        return s;
    }
    VkPhysicalDevicePresentWaitFeaturesKHR wf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_WAIT_FEATURES_KHR};
    VkPhysicalDevicePresentIdFeaturesKHR idf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_ID_FEATURES_KHR, &wf};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &idf};
    inst.vk.GetPhysicalDeviceFeatures2(physical, &f2);
    s.usable = idf.presentId && wf.presentWait;
    if (!s.usable) s.why = "the device does not offer its features";
    return s;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice physical, const VkDeviceCreateInfo* ci,
                                            const VkAllocationCallbacks* alloc, VkDevice* out) {
    InstanceData* inst = instance_of(physical);
    auto* link = find_chain<VkLayerDeviceCreateInfo>(ci->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO,
                                                     VK_LAYER_LINK_INFO);
    auto* loader_data = find_chain<VkLayerDeviceCreateInfo>(
        ci->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO, VK_LOADER_DATA_CALLBACK);
    if (!inst || !link || !link->u.pLayerInfo || !loader_data) return VK_ERROR_INITIALIZATION_FAILED;
    PFN_vkGetInstanceProcAddr gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
    PFN_vkGetDeviceProcAddr gdpa = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
    link->u.pLayerInfo = link->u.pLayerInfo->pNext;
    auto create = reinterpret_cast<PFN_vkCreateDevice>(gipa(inst->instance, "vkCreateDevice"));
    if (!create) return VK_ERROR_INITIALIZATION_FAILED;
    // The layer needs nothing beyond Vulkan 1.0 and the application's swapchain extension, and
    // uses VK_KHR_present_id + VK_KHR_present_wait where it can (present_wait.hpp).
    PresentWaitSupport pw = present_wait_support(*inst, physical, *ci);
    VkDeviceCreateInfo mine = *ci;
    std::vector<const char*> extensions(ci->ppEnabledExtensionNames,
                                        ci->ppEnabledExtensionNames + ci->enabledExtensionCount);
    VkPhysicalDevicePresentIdFeaturesKHR id_features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_ID_FEATURES_KHR};
    VkPhysicalDevicePresentWaitFeaturesKHR wait_features{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_WAIT_FEATURES_KHR};
    if (pw.usable) {
        extensions.push_back(VK_KHR_PRESENT_ID_EXTENSION_NAME);
        extensions.push_back(VK_KHR_PRESENT_WAIT_EXTENSION_NAME);
        mine.enabledExtensionCount = uint32_t(extensions.size());
        mine.ppEnabledExtensionNames = extensions.data();
        id_features.presentId = VK_TRUE;
        id_features.pNext = const_cast<void*>(ci->pNext);
        wait_features.presentWait = VK_TRUE;
        wait_features.pNext = &id_features;
        mine.pNext = &wait_features;
    }
    const VkResult r = create(physical, &mine, alloc, out);
    if (r != VK_SUCCESS) return r;
    auto* d = new DeviceData{};
    d->device = *out;
    d->physical_device = physical;
    d->instance = inst;
    d->set_loader_data = loader_data->u.pfnSetDeviceLoaderData;
#define FGSR_DEVICE_FN(name) d->vk.name = reinterpret_cast<PFN_vk##name>(gdpa(*out, "vk" #name))
    d->vk.GetDeviceProcAddr = gdpa;
    FGSR_DEVICE_FN(DestroyDevice);
    FGSR_DEVICE_FN(GetDeviceQueue);
    FGSR_DEVICE_FN(GetDeviceQueue2);
    FGSR_DEVICE_FN(CreateSwapchainKHR);
    FGSR_DEVICE_FN(DestroySwapchainKHR);
    FGSR_DEVICE_FN(GetSwapchainImagesKHR);
    FGSR_DEVICE_FN(AcquireNextImageKHR);
    FGSR_DEVICE_FN(AcquireNextImage2KHR);
    FGSR_DEVICE_FN(QueuePresentKHR);
    FGSR_DEVICE_FN(QueueSubmit);
    FGSR_DEVICE_FN(QueueSubmit2);
    FGSR_DEVICE_FN(QueueSubmit2KHR);
    FGSR_DEVICE_FN(QueueWaitIdle);
    FGSR_DEVICE_FN(QueueBindSparse);
    FGSR_DEVICE_FN(DeviceWaitIdle);
    FGSR_DEVICE_FN(CreateCommandPool);
    FGSR_DEVICE_FN(DestroyCommandPool);
    FGSR_DEVICE_FN(AllocateCommandBuffers);
    FGSR_DEVICE_FN(BeginCommandBuffer);
    FGSR_DEVICE_FN(EndCommandBuffer);
    FGSR_DEVICE_FN(ResetCommandBuffer);
    FGSR_DEVICE_FN(CmdPipelineBarrier);
    FGSR_DEVICE_FN(CmdCopyImageToBuffer);
    FGSR_DEVICE_FN(CmdCopyBufferToImage);
    FGSR_DEVICE_FN(CreateBuffer);
    FGSR_DEVICE_FN(DestroyBuffer);
    FGSR_DEVICE_FN(GetBufferMemoryRequirements);
    FGSR_DEVICE_FN(AllocateMemory);
    FGSR_DEVICE_FN(FreeMemory);
    FGSR_DEVICE_FN(BindBufferMemory);
    FGSR_DEVICE_FN(MapMemory);
    FGSR_DEVICE_FN(InvalidateMappedMemoryRanges);
    FGSR_DEVICE_FN(FlushMappedMemoryRanges);
    FGSR_DEVICE_FN(CreateFence);
    FGSR_DEVICE_FN(DestroyFence);
    FGSR_DEVICE_FN(WaitForFences);
    FGSR_DEVICE_FN(ResetFences);
    FGSR_DEVICE_FN(CreateSemaphore);
    FGSR_DEVICE_FN(DestroySemaphore);
#undef FGSR_DEVICE_FN
    inst->vk.GetPhysicalDeviceMemoryProperties(physical, &d->memory);
    d->has_present_wait = pw.offered;
    d->use_present_wait = pw.usable;
    if (pw.usable) d->vk.WaitForPresentKHR = reinterpret_cast<PFN_vkWaitForPresentKHR>(gdpa(*out, "vkWaitForPresentKHR"));
    if (!d->vk.WaitForPresentKHR) d->use_present_wait = false;
    if (pw.offered && !pw.usable) log_line("VK_KHR_present_wait: " + pw.why + "; present times are when the "
                                           "present call returned");
    Report::get().set_present_wait(d->use_present_wait);
    std::lock_guard l(g().mutex);
    g().devices[dispatch_key(*out)] = d;
    return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice device, const VkAllocationCallbacks* alloc) {
    DeviceData* d = device_of(device);
    if (!d) return;
    std::vector<Swapchain*> owned;
    {
        std::lock_guard l(g().mutex);
        for (auto it = g().swapchain_device.begin(); it != g().swapchain_device.end();) {
            if (it->second == d) {
                owned.push_back(g().swapchains[it->first]);
                g().swapchains.erase(it->first);
                it = g().swapchain_device.erase(it);
            } else {
                ++it;
            }
        }
        g().devices.erase(dispatch_key(device));
    }
    for (Swapchain* sc : owned) delete sc; // the application leaked them; the driver frees the images
    d->vk.DestroyDevice(device, alloc);
    delete d;
}

void note_queue(DeviceData* d, VkQueue queue, uint32_t family) {
    std::lock_guard l(d->families_mutex);
    d->queue_family[queue] = family;
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue(VkDevice device, uint32_t family, uint32_t index, VkQueue* out) {
    DeviceData* d = device_of(device);
    d->vk.GetDeviceQueue(device, family, index, out);
    if (*out) note_queue(d, *out, family);
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue2(VkDevice device, const VkDeviceQueueInfo2* info, VkQueue* out) {
    DeviceData* d = device_of(device);
    d->vk.GetDeviceQueue2(device, info, out);
    if (*out) note_queue(d, *out, info->queueFamilyIndex);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateSwapchainKHR(VkDevice device, const VkSwapchainCreateInfoKHR* ci,
                                                  const VkAllocationCallbacks* alloc, VkSwapchainKHR* out) {
    DeviceData* d = device_of(device);
    if (Swapchain* old = ci->oldSwapchain ? swapchain_of(ci->oldSwapchain) : nullptr) old->drain();
    VkSurfaceCapabilitiesKHR caps{};
    const VkImageUsageFlags need = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    bool managed = pixel_kind(ci->imageFormat) != PixelKind::unsupported && ci->imageArrayLayers == 1 &&
                   d->instance->vk.GetPhysicalDeviceSurfaceCapabilitiesKHR(d->physical_device, ci->surface,
                                                                           &caps) == VK_SUCCESS &&
                   (caps.supportedUsageFlags & need) == need;
    if (!managed)
        log_line("swapchain format " + std::to_string(int(ci->imageFormat)) +
                 " or usage not supported by the layer; its frames pass through");
    VkSwapchainCreateInfoKHR mine = *ci;
    if (managed) {
        mine.imageUsage |= need;
        mine.minImageCount += kExtraImages;
        if (caps.maxImageCount != 0 && mine.minImageCount > caps.maxImageCount)
            mine.minImageCount = caps.maxImageCount;
    }
    VkResult r = d->vk.CreateSwapchainKHR(device, &mine, alloc, out);
    if (r != VK_SUCCESS && managed) { // the driver refused the additions: pass this one through
        managed = false;
        r = d->vk.CreateSwapchainKHR(device, ci, alloc, out);
    }
    if (r != VK_SUCCESS) return r;
    auto* sc = new Swapchain(*d, *out, ci->imageFormat, ci->imageExtent, managed);
    std::lock_guard l(g().mutex);
    g().swapchains[*out] = sc;
    g().swapchain_device[*out] = d;
    return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroySwapchainKHR(VkDevice device, VkSwapchainKHR swapchain,
                                               const VkAllocationCallbacks* alloc) {
    DeviceData* d = device_of(device);
    Swapchain* sc = nullptr;
    {
        std::lock_guard l(g().mutex);
        if (auto it = g().swapchains.find(swapchain); it != g().swapchains.end()) {
            sc = it->second;
            g().swapchains.erase(it);
            g().swapchain_device.erase(swapchain);
        }
    }
    delete sc; // presents what it holds, then frees the layer's objects
    d->vk.DestroySwapchainKHR(device, swapchain, alloc);
}

VKAPI_ATTR VkResult VKAPI_CALL AcquireNextImageKHR(VkDevice device, VkSwapchainKHR swapchain,
                                                   uint64_t timeout, VkSemaphore semaphore, VkFence fence,
                                                   uint32_t* index) {
    if (Swapchain* sc = swapchain_of(swapchain)) return sc->acquire(timeout, semaphore, fence, 0, index);
    return device_of(device)->vk.AcquireNextImageKHR(device, swapchain, timeout, semaphore, fence, index);
}

VKAPI_ATTR VkResult VKAPI_CALL AcquireNextImage2KHR(VkDevice device, const VkAcquireNextImageInfoKHR* info,
                                                    uint32_t* index) {
    if (Swapchain* sc = swapchain_of(info->swapchain); sc && info->pNext == nullptr)
        return sc->acquire(info->timeout, info->semaphore, info->fence, info->deviceMask, index);
    return device_of(device)->vk.AcquireNextImage2KHR(device, info, index);
}

VKAPI_ATTR VkResult VKAPI_CALL QueuePresentKHR(VkQueue queue, const VkPresentInfoKHR* info) {
    const uint64_t entry = monotonic_ns();
    DeviceData* d = device_of(queue);
    for (uint32_t i = 0; i < info->swapchainCount; ++i) Report::get().app_present();
    const LayerConfig cfg = current_config();
    if (info->swapchainCount == 1) {
        if (Swapchain* sc = swapchain_of(info->pSwapchains[0])) {
            const VkResult r = sc->present(queue, *info, info->pImageIndices[0], cfg, entry);
            if (info->pResults) info->pResults[0] = r;
            return r;
        }
    }
    // Several swapchains in one call (their semaphores are waited once): as the application asked,
    // after what the layer still holds of each.
    for (uint32_t i = 0; i < info->swapchainCount; ++i)
        if (Swapchain* sc = swapchain_of(info->pSwapchains[i])) sc->drain();
    VkResult r;
    {
        std::lock_guard l(d->queue_mutex);
        r = d->vk.QueuePresentKHR(queue, info);
    }
    const uint64_t t = monotonic_ns();
    for (uint32_t i = 0; i < info->swapchainCount; ++i)
        Report::get().present(PresentKind::real, 0, entry, t, t, t, uint64_t(info->pSwapchains[i]));
    return r;
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t n, const VkSubmitInfo* s, VkFence fence) {
    DeviceData* d = device_of(queue);
    std::lock_guard l(d->queue_mutex);
    return d->vk.QueueSubmit(queue, n, s, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t n, const VkSubmitInfo2* s,
                                            VkFence fence) {
    DeviceData* d = device_of(queue);
    std::lock_guard l(d->queue_mutex);
    return d->vk.QueueSubmit2(queue, n, s, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2KHR(VkQueue queue, uint32_t n, const VkSubmitInfo2* s,
                                               VkFence fence) {
    DeviceData* d = device_of(queue);
    std::lock_guard l(d->queue_mutex);
    return d->vk.QueueSubmit2KHR(queue, n, s, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueWaitIdle(VkQueue queue) {
    DeviceData* d = device_of(queue);
    std::lock_guard l(d->queue_mutex);
    return d->vk.QueueWaitIdle(queue);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueBindSparse(VkQueue queue, uint32_t n, const VkBindSparseInfo* b,
                                               VkFence fence) {
    DeviceData* d = device_of(queue);
    std::lock_guard l(d->queue_mutex);
    return d->vk.QueueBindSparse(queue, n, b, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL DeviceWaitIdle(VkDevice device) {
    DeviceData* d = device_of(device);
    std::lock_guard l(d->queue_mutex);
    return d->vk.DeviceWaitIdle(device);
}

// Device-level entry points the layer replaces; null when the next layer lacks the function.
PFN_vkVoidFunction device_intercept(const char* name, DeviceData* d) {
#define FGSR_HOOK(fn)                                                                                        \
    if (std::strcmp(name, "vk" #fn) == 0)                                                                    \
        return (d && !d->vk.fn) ? nullptr : reinterpret_cast<PFN_vkVoidFunction>(&fn);
    FGSR_HOOK(DestroyDevice)
    FGSR_HOOK(GetDeviceQueue)
    FGSR_HOOK(GetDeviceQueue2)
    FGSR_HOOK(CreateSwapchainKHR)
    FGSR_HOOK(DestroySwapchainKHR)
    FGSR_HOOK(AcquireNextImageKHR)
    FGSR_HOOK(AcquireNextImage2KHR)
    FGSR_HOOK(QueuePresentKHR)
    FGSR_HOOK(QueueSubmit)
    FGSR_HOOK(QueueSubmit2)
    FGSR_HOOK(QueueSubmit2KHR)
    FGSR_HOOK(QueueWaitIdle)
    FGSR_HOOK(QueueBindSparse)
    FGSR_HOOK(DeviceWaitIdle)
#undef FGSR_HOOK
    return nullptr;
}

} // namespace

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* name);

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* name) {
    if (std::strcmp(name, "vkGetInstanceProcAddr") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr);
    if (std::strcmp(name, "vkCreateInstance") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&CreateInstance);
    if (!instance) return nullptr;
    if (std::strcmp(name, "vkDestroyInstance") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&DestroyInstance);
    if (std::strcmp(name, "vkCreateDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateDevice);
    if (std::strcmp(name, "vkGetDeviceProcAddr") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
    if (PFN_vkVoidFunction f = device_intercept(name, nullptr)) return f;
    InstanceData* d = instance_of(instance);
    return d ? d->vk.GetInstanceProcAddr(instance, name) : nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* name) {
    if (std::strcmp(name, "vkGetDeviceProcAddr") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
    DeviceData* d = device ? device_of(device) : nullptr;
    if (!d) return nullptr;
    if (PFN_vkVoidFunction f = device_intercept(name, d)) return f;
    return d->vk.GetDeviceProcAddr(device, name);
}

} // namespace fgsr::layer

FGSR_LAYER_EXPORT VKAPI_ATTR VkResult VKAPI_CALL
vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* v) {
    if (!v || v->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT) return VK_ERROR_INITIALIZATION_FAILED;
    if (v->loaderLayerInterfaceVersion >= 2) {
        v->pfnGetInstanceProcAddr = fgsr::layer::GetInstanceProcAddr;
        v->pfnGetDeviceProcAddr = fgsr::layer::GetDeviceProcAddr;
        v->pfnGetPhysicalDeviceProcAddr = nullptr;
        v->loaderLayerInterfaceVersion = 2;
    }
    return VK_SUCCESS;
}

FGSR_LAYER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance,
                                                                                 const char* name) {
    return fgsr::layer::GetInstanceProcAddr(instance, name);
}

FGSR_LAYER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetDeviceProcAddr(VkDevice device,
                                                                               const char* name) {
    return fgsr::layer::GetDeviceProcAddr(device, name);
}
