// VK_LAYER_FGSR_test_present_wait: a test-only explicit layer that gives a driver without them
// (lavapipe) VK_KHR_present_id and VK_KHR_present_wait, so that the fgsr layer's use of them runs
// end to end. Placed below the fgsr layer (the loader puts implicit layers nearest the
// application, explicit ones after), it
//   - adds both extensions to vkEnumerateDeviceExtensionProperties and sets presentId and
//     presentWait in vkGetPhysicalDeviceFeatures2;
//   - removes them (and their feature structs, which lead the chain as the fgsr layer puts them)
//     from vkCreateDevice before the driver sees them;
//   - notes the id of every present (VkPresentIdKHR), and declares it displayed
//     FGSR_TEST_DISPLAY_DELAY_MS (default 12) after the present call returned;
//   - answers vkWaitForPresentKHR from those notes (VK_SUCCESS once an id at or beyond the one
//     asked for is displayed, VK_TIMEOUT otherwise).
// A delay the test chooses is what lets the test tell display times from present-call times.
#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#define EMU_EXPORT extern "C" __attribute__((visibility("default")))

namespace {

uint64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

void* key(const void* handle) {
    return *static_cast<void* const*>(handle);
}

struct Instance {
    PFN_vkGetInstanceProcAddr gipa;
    PFN_vkEnumerateDeviceExtensionProperties enumerate_extensions;
    PFN_vkGetPhysicalDeviceFeatures2 features2;
    PFN_vkGetPhysicalDeviceFeatures2KHR features2_khr;
    VkInstance instance;
};

struct Device {
    PFN_vkGetDeviceProcAddr gdpa;
    PFN_vkQueuePresentKHR present;
    PFN_vkDestroyDevice destroy;
};

struct State {
    std::mutex m;
    std::unordered_map<void*, Instance> instances;
    std::unordered_map<void*, Device> devices;
    std::map<VkSwapchainKHR, std::map<uint64_t, uint64_t>> displayed; // id -> display time
    uint64_t delay_ns = 12'000'000;

    State() {
        if (const char* d = std::getenv("FGSR_TEST_DISPLAY_DELAY_MS"))
            delay_ns = uint64_t(std::atof(d) * 1e6);
    }
};

// Destroyed when the loader unloads this layer, or at exit (an ASan build's leak check sees no
// unreachable state). Made inside the fgsr layer's vkCreateInstance, before the fgsr layer's exit
// hook, so destroyed after it: the fgsr layer's present threads, which call down into this layer,
// are stopped first.
State& st() {
    static State s;
    return s;
}

template <class T> T* chain_info(const void* pnext, VkStructureType type, VkLayerFunction f) {
    for (auto* p = static_cast<const VkBaseInStructure*>(pnext); p; p = p->pNext)
        if (p->sType == type && reinterpret_cast<const T*>(p)->function == f)
            return reinterpret_cast<T*>(const_cast<VkBaseInStructure*>(p));
    return nullptr;
}

bool is_ours(const char* name) {
    return std::strcmp(name, VK_KHR_PRESENT_ID_EXTENSION_NAME) == 0 ||
           std::strcmp(name, VK_KHR_PRESENT_WAIT_EXTENSION_NAME) == 0;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* ci, const VkAllocationCallbacks* a,
                                              VkInstance* out) {
    auto* link = chain_info<VkLayerInstanceCreateInfo>(ci->pNext, VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO,
                                                       VK_LAYER_LINK_INFO);
    if (!link) return VK_ERROR_INITIALIZATION_FAILED;
    PFN_vkGetInstanceProcAddr gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
    link->u.pLayerInfo = link->u.pLayerInfo->pNext;
    auto create = reinterpret_cast<PFN_vkCreateInstance>(gipa(VK_NULL_HANDLE, "vkCreateInstance"));
    const VkResult r = create(ci, a, out);
    if (r != VK_SUCCESS) return r;
    Instance i{gipa,
               reinterpret_cast<PFN_vkEnumerateDeviceExtensionProperties>(
                   gipa(*out, "vkEnumerateDeviceExtensionProperties")),
               reinterpret_cast<PFN_vkGetPhysicalDeviceFeatures2>(gipa(*out, "vkGetPhysicalDeviceFeatures2")),
               reinterpret_cast<PFN_vkGetPhysicalDeviceFeatures2KHR>(gipa(*out, "vkGetPhysicalDeviceFeatures2KHR")),
               *out};
    std::lock_guard l(st().m);
    st().instances[key(*out)] = i;
    return VK_SUCCESS;
}

Instance instance_of(const void* h) {
    std::lock_guard l(st().m);
    return st().instances.at(key(h));
}

VKAPI_ATTR VkResult VKAPI_CALL EnumerateDeviceExtensionProperties(VkPhysicalDevice pd, const char* layer,
                                                                  uint32_t* count, VkExtensionProperties* props) {
    const Instance i = instance_of(pd);
    if (layer) return i.enumerate_extensions(pd, layer, count, props);
    uint32_t n = 0;
    VkResult r = i.enumerate_extensions(pd, nullptr, &n, nullptr);
    if (r != VK_SUCCESS) return r;
    std::vector<VkExtensionProperties> all(n);
    r = i.enumerate_extensions(pd, nullptr, &n, all.data());
    if (r != VK_SUCCESS) return r;
    all.resize(n);
    for (const char* name : {VK_KHR_PRESENT_ID_EXTENSION_NAME, VK_KHR_PRESENT_WAIT_EXTENSION_NAME}) {
        VkExtensionProperties e{};
        std::strncpy(e.extensionName, name, VK_MAX_EXTENSION_NAME_SIZE - 1);
        e.specVersion = 1;
        all.push_back(e);
    }
    if (!props) {
        *count = uint32_t(all.size());
        return VK_SUCCESS;
    }
    const uint32_t k = std::min<uint32_t>(*count, uint32_t(all.size()));
    std::memcpy(props, all.data(), k * sizeof(VkExtensionProperties));
    *count = k;
    return k < all.size() ? VK_INCOMPLETE : VK_SUCCESS;
}

void set_features(VkPhysicalDeviceFeatures2* f) {
    for (auto* p = static_cast<VkBaseOutStructure*>(f->pNext); p; p = p->pNext) {
        if (p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_ID_FEATURES_KHR)
            reinterpret_cast<VkPhysicalDevicePresentIdFeaturesKHR*>(p)->presentId = VK_TRUE;
        if (p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_WAIT_FEATURES_KHR)
            reinterpret_cast<VkPhysicalDevicePresentWaitFeaturesKHR*>(p)->presentWait = VK_TRUE;
    }
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceFeatures2(VkPhysicalDevice pd, VkPhysicalDeviceFeatures2* f) {
    instance_of(pd).features2(pd, f);
    set_features(f);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceFeatures2KHR(VkPhysicalDevice pd, VkPhysicalDeviceFeatures2* f) {
    instance_of(pd).features2_khr(pd, f);
    set_features(f);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice pd, const VkDeviceCreateInfo* ci,
                                            const VkAllocationCallbacks* a, VkDevice* out) {
    const Instance i = instance_of(pd);
    auto* link = chain_info<VkLayerDeviceCreateInfo>(ci->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO,
                                                     VK_LAYER_LINK_INFO);
    if (!link) return VK_ERROR_INITIALIZATION_FAILED;
    PFN_vkGetDeviceProcAddr gdpa = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
    link->u.pLayerInfo = link->u.pLayerInfo->pNext;
    auto create = reinterpret_cast<PFN_vkCreateDevice>(i.gipa(i.instance, "vkCreateDevice"));
    VkDeviceCreateInfo mine = *ci;
    std::vector<const char*> ext;
    for (uint32_t k = 0; k < ci->enabledExtensionCount; ++k)
        if (!is_ours(ci->ppEnabledExtensionNames[k])) ext.push_back(ci->ppEnabledExtensionNames[k]);
    mine.enabledExtensionCount = uint32_t(ext.size());
    mine.ppEnabledExtensionNames = ext.data();
    auto* p = static_cast<const VkBaseInStructure*>(ci->pNext);
    while (p && (p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_ID_FEATURES_KHR ||
                 p->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PRESENT_WAIT_FEATURES_KHR))
        p = p->pNext;
    mine.pNext = p;
    const VkResult r = create(pd, &mine, a, out);
    if (r != VK_SUCCESS) return r;
    Device d{gdpa, reinterpret_cast<PFN_vkQueuePresentKHR>(gdpa(*out, "vkQueuePresentKHR")),
             reinterpret_cast<PFN_vkDestroyDevice>(gdpa(*out, "vkDestroyDevice"))};
    std::lock_guard l(st().m);
    st().devices[key(*out)] = d;
    return VK_SUCCESS;
}

Device device_of(const void* h) {
    std::lock_guard l(st().m);
    return st().devices.at(key(h));
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice device, const VkAllocationCallbacks* a) {
    const Device d = device_of(device);
    {
        std::lock_guard l(st().m);
        st().devices.erase(key(device));
    }
    d.destroy(device, a);
}

VKAPI_ATTR VkResult VKAPI_CALL QueuePresentKHR(VkQueue queue, const VkPresentInfoKHR* info) {
    const VkPresentIdKHR* ids = nullptr;
    for (auto* p = static_cast<const VkBaseInStructure*>(info->pNext); p; p = p->pNext)
        if (p->sType == VK_STRUCTURE_TYPE_PRESENT_ID_KHR) ids = reinterpret_cast<const VkPresentIdKHR*>(p);
    VkPresentInfoKHR mine = *info;
    if (ids && mine.pNext == ids) mine.pNext = ids->pNext; // the driver does not know the struct
    const VkResult r = device_of(queue).present(queue, &mine);
    if (ids && (r == VK_SUCCESS || r == VK_SUBOPTIMAL_KHR)) {
        const uint64_t shown = now_ns() + st().delay_ns;
        std::lock_guard l(st().m);
        for (uint32_t k = 0; k < ids->swapchainCount && k < info->swapchainCount; ++k)
            if (ids->pPresentIds && ids->pPresentIds[k] != 0)
                st().displayed[info->pSwapchains[k]][ids->pPresentIds[k]] = shown;
    }
    return r;
}

VKAPI_ATTR VkResult VKAPI_CALL WaitForPresentKHR(VkDevice, VkSwapchainKHR swapchain, uint64_t id, uint64_t timeout) {
    const uint64_t start = now_ns();
    for (;;) {
        {
            std::lock_guard l(st().m);
            auto& ids = st().displayed[swapchain];
            auto it = ids.lower_bound(id);
            if (it != ids.end() && now_ns() >= it->second) {
                ids.erase(ids.begin(), it); // older ids are displayed too
                return VK_SUCCESS;
            }
        }
        if (now_ns() - start >= timeout) return VK_TIMEOUT;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* name);

PFN_vkVoidFunction device_hook(const char* name) {
    if (std::strcmp(name, "vkDestroyDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&DestroyDevice);
    if (std::strcmp(name, "vkQueuePresentKHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&QueuePresentKHR);
    if (std::strcmp(name, "vkWaitForPresentKHR") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&WaitForPresentKHR);
    if (std::strcmp(name, "vkGetDeviceProcAddr") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
    return nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* name) {
    if (PFN_vkVoidFunction f = device_hook(name)) return f;
    return device_of(device).gdpa(device, name);
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* name) {
    if (std::strcmp(name, "vkGetInstanceProcAddr") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr);
    if (std::strcmp(name, "vkCreateInstance") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateInstance);
    if (!instance) return nullptr;
    if (std::strcmp(name, "vkCreateDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&CreateDevice);
    if (std::strcmp(name, "vkEnumerateDeviceExtensionProperties") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&EnumerateDeviceExtensionProperties);
    if (std::strcmp(name, "vkGetPhysicalDeviceFeatures2") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceFeatures2);
    if (std::strcmp(name, "vkGetPhysicalDeviceFeatures2KHR") == 0)
        return reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceFeatures2KHR);
    if (PFN_vkVoidFunction f = device_hook(name)) return f;
    return instance_of(instance).gipa(instance, name);
}

} // namespace

EMU_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* v) {
    if (!v || v->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT) return VK_ERROR_INITIALIZATION_FAILED;
    if (v->loaderLayerInterfaceVersion >= 2) {
        v->pfnGetInstanceProcAddr = GetInstanceProcAddr;
        v->pfnGetDeviceProcAddr = GetDeviceProcAddr;
        v->pfnGetPhysicalDeviceProcAddr = nullptr;
        v->loaderLayerInterfaceVersion = 2;
    }
    return VK_SUCCESS;
}
