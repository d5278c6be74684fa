#include "vk.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace fgsr::vk {

std::string result_string(VkResult r) {
    switch (r) {
    case VK_SUCCESS:
        return "VK_SUCCESS";
    case VK_NOT_READY:
        return "VK_NOT_READY";
    case VK_TIMEOUT:
        return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
        return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
        return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
        return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
        return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT:
        return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
        return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
        return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
        return "VK_ERROR_INCOMPATIBLE_DRIVER";
    default:
        return "VkResult " + std::to_string(int(r));
    }
}

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        static_cast<Context*>(user)->validation_errors.fetch_add(1);
        std::fprintf(stderr, "fgsr: vulkan validation error: %s\n", data->pMessage);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        std::fprintf(stderr, "fgsr: vulkan validation warning: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

bool has_layer(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> layers(n);
    vkEnumerateInstanceLayerProperties(&n, layers.data());
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool has_instance_extension(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> ext(n);
    vkEnumerateInstanceExtensionProperties(nullptr, &n, ext.data());
    return std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

const char* type_name(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return "CPU";
    default:
        return "other";
    }
}

Result<VkInstance> make_instance(bool validation) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "fgsr";
    app.pEngineName = "fgsr";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> layers, extensions;
    if (validation) {
        if (!has_layer("VK_LAYER_KHRONOS_validation"))
            return make_error(Errc::unsupported,
                              "validation requested but VK_LAYER_KHRONOS_validation is not installed "
                              "(Debian package vulkan-validationlayers)");
        layers.push_back("VK_LAYER_KHRONOS_validation");
        if (has_instance_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME))
            extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    FGSR_VK(vkCreateInstance(&ci, nullptr, &instance),
            "vkCreateInstance (is a Vulkan driver such as mesa-vulkan-drivers installed?)");
    return instance;
}

} // namespace

Context::~Context() {
    if (device) {
        vkDeviceWaitIdle(device);
        vkDestroyDevice(device, nullptr);
    }
    if (messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
}

Result<std::vector<std::string>> enumerate_devices() {
    auto inst = make_instance(false);
    if (!inst) return inst.error();
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(*inst, &n, nullptr);
    std::vector<VkPhysicalDevice> devs(n);
    vkEnumeratePhysicalDevices(*inst, &n, devs.data());
    std::vector<std::string> out;
    for (uint32_t i = 0; i < n; ++i) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devs[i], &p);
        out.push_back(std::to_string(i) + ": " + p.deviceName + " (" + type_name(p.deviceType) + ")");
    }
    vkDestroyInstance(*inst, nullptr);
    return out;
}

Result<std::unique_ptr<Context>> create_context(const DeviceOptions& options) {
    auto ctx = std::make_unique<Context>();
    const char* env_validation = std::getenv("FGSR_VALIDATION");
    bool validation = options.validation || (env_validation && std::strcmp(env_validation, "1") == 0);
    auto inst = make_instance(validation);
    if (!inst) return inst.error();
    ctx->instance = *inst;
    if (validation && has_instance_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME)) {
        VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        mi.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
        mi.messageType =
            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
        mi.pfnUserCallback = on_validation;
        mi.pUserData = ctx.get();
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(ctx->instance, "vkCreateDebugUtilsMessengerEXT"));
        if (create)
            FGSR_VK(create(ctx->instance, &mi, nullptr, &ctx->messenger), "vkCreateDebugUtilsMessengerEXT");
    }

    uint32_t n = 0;
    vkEnumeratePhysicalDevices(ctx->instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devs(n);
    vkEnumeratePhysicalDevices(ctx->instance, &n, devs.data());
    if (n == 0)
        return make_error(Errc::no_device,
                          "no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");

    std::string want = options.device;
    if (want.empty())
        if (const char* env = std::getenv("FGSR_DEVICE")) want = env;
    int chosen = -1;
    std::vector<VkPhysicalDeviceProperties> props(n);
    for (uint32_t i = 0; i < n; ++i) vkGetPhysicalDeviceProperties(devs[i], &props[i]);
    if (!want.empty()) {
        bool numeric = std::all_of(want.begin(), want.end(), [](unsigned char c) { return std::isdigit(c); });
        if (numeric) {
            unsigned long idx = std::strtoul(want.c_str(), nullptr, 10);
            if (idx < n) chosen = int(idx);
        } else {
            for (uint32_t i = 0; i < n && chosen < 0; ++i)
                if (lower(props[i].deviceName).find(lower(want)) != std::string::npos) chosen = int(i);
        }
        if (chosen < 0) {
            std::string names;
            for (uint32_t i = 0; i < n; ++i)
                names += (i ? ", " : "") + std::to_string(i) + ": " + props[i].deviceName;
            return make_error(Errc::no_device,
                              "no Vulkan device matches '" + want + "' (devices: " + names + ")");
        }
    } else {
        for (uint32_t i = 0; i < n && chosen < 0; ++i)
            if (props[i].deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) chosen = int(i);
        if (chosen < 0) chosen = 0;
    }
    ctx->physical = devs[size_t(chosen)];
    ctx->props = props[size_t(chosen)];
    vkGetPhysicalDeviceMemoryProperties(ctx->physical, &ctx->memory);

    uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical, &qn, nullptr);
    std::vector<VkQueueFamilyProperties> qf(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical, &qn, qf.data());
    bool found = false;
    for (uint32_t i = 0; i < qn && !found; ++i)
        if (qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
            ctx->queue_family = i;
            ctx->timestamp_valid_bits = qf[i].timestampValidBits;
            found = true;
        }
    if (!found)
        return make_error(Errc::unsupported, std::string(ctx->props.deviceName) + " has no compute queue");

    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    f2.pNext = &f12;
    vkGetPhysicalDeviceFeatures2(ctx->physical, &f2);
    if (!f2.features.shaderInt64 || !f12.shaderBufferInt64Atomics)
        return make_error(
            Errc::unsupported,
            std::string(ctx->props.deviceName) +
                " lacks shaderInt64 / shaderBufferInt64Atomics (needed by depth-aware splatting)");
    VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    e12.shaderBufferInt64Atomics = VK_TRUE;
    VkPhysicalDeviceFeatures2 e2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    e2.features.shaderInt64 = VK_TRUE;
    e2.pNext = &e12;

    // Optional extensions: host-pointer import (zero-copy input) and calibrated timestamps.
    uint32_t en = 0;
    vkEnumerateDeviceExtensionProperties(ctx->physical, nullptr, &en, nullptr);
    std::vector<VkExtensionProperties> dev_ext(en);
    vkEnumerateDeviceExtensionProperties(ctx->physical, nullptr, &en, dev_ext.data());
    auto has_dev_ext = [&](const char* name) {
        return std::any_of(dev_ext.begin(), dev_ext.end(), [&](const VkExtensionProperties& e) {
            return std::strcmp(e.extensionName, name) == 0;
        });
    };
    std::vector<const char*> enabled;
    if (has_dev_ext(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME)) {
        enabled.push_back(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
        VkPhysicalDeviceExternalMemoryHostPropertiesEXT hp{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT};
        VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
        p2.pNext = &hp;
        vkGetPhysicalDeviceProperties2(ctx->physical, &p2);
        ctx->host_import_alignment = hp.minImportedHostPointerAlignment;
        ctx->host_import = hp.minImportedHostPointerAlignment > 0;
    }
    bool calibrated = false;
    if (has_dev_ext(VK_EXT_CALIBRATED_TIMESTAMPS_EXTENSION_NAME)) {
        auto domains_fn = reinterpret_cast<PFN_vkGetPhysicalDeviceCalibrateableTimeDomainsEXT>(
            vkGetInstanceProcAddr(ctx->instance, "vkGetPhysicalDeviceCalibrateableTimeDomainsEXT"));
        uint32_t dn = 0;
        if (domains_fn && domains_fn(ctx->physical, &dn, nullptr) == VK_SUCCESS) {
            std::vector<VkTimeDomainEXT> domains(dn);
            domains_fn(ctx->physical, &dn, domains.data());
            const bool dev =
                std::find(domains.begin(), domains.end(), VK_TIME_DOMAIN_DEVICE_EXT) != domains.end();
            const bool mono = std::find(domains.begin(), domains.end(), VK_TIME_DOMAIN_CLOCK_MONOTONIC_EXT) !=
                              domains.end();
            calibrated = dev && mono;
        }
        if (calibrated) enabled.push_back(VK_EXT_CALIBRATED_TIMESTAMPS_EXTENSION_NAME);
    }

    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = ctx->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &e2;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = uint32_t(enabled.size());
    dci.ppEnabledExtensionNames = enabled.data();
    FGSR_VK(vkCreateDevice(ctx->physical, &dci, nullptr, &ctx->device), "vkCreateDevice");
    if (ctx->host_import) {
        ctx->get_host_pointer_properties = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
            vkGetDeviceProcAddr(ctx->device, "vkGetMemoryHostPointerPropertiesEXT"));
        ctx->host_import = ctx->get_host_pointer_properties != nullptr;
    }
    if (calibrated)
        ctx->get_calibrated_timestamps = reinterpret_cast<PFN_vkGetCalibratedTimestampsEXT>(
            vkGetDeviceProcAddr(ctx->device, "vkGetCalibratedTimestampsEXT"));
    vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);
    return ctx;
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    if (this != &o) {
        release();
        ctx_ = std::exchange(o.ctx_, nullptr);
        buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
        view_ = std::exchange(o.view_, VK_NULL_HANDLE);
        size_ = std::exchange(o.size_, 0);
        mapped_ = std::exchange(o.mapped_, nullptr);
        imported_ = std::exchange(o.imported_, false);
    }
    return *this;
}

void Buffer::release() {
    if (!ctx_) return;
    if (mapped_ && !imported_) vkUnmapMemory(ctx_->device, memory_);
    if (view_) vkDestroyBufferView(ctx_->device, view_, nullptr);
    if (buffer_) vkDestroyBuffer(ctx_->device, buffer_, nullptr);
    if (memory_) vkFreeMemory(ctx_->device, memory_, nullptr);
    ctx_ = nullptr;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    view_ = VK_NULL_HANDLE;
    mapped_ = nullptr;
    imported_ = false;
}

Result<void> Buffer::make_texel_view(VkFormat format) {
    if (view_) return {};
    if (!ctx_ || imported_)
        return make_error(Errc::invalid_argument, "internal: a texel view of an imported or empty buffer");
    const VkDeviceSize texel =
        format == VK_FORMAT_R32G32B32A32_SFLOAT ? 16 : (format == VK_FORMAT_R32G32_SFLOAT ? 8 : 4);
    if (format != VK_FORMAT_R32_SFLOAT && format != VK_FORMAT_R32G32_SFLOAT &&
        format != VK_FORMAT_R32G32B32A32_SFLOAT)
        return make_error(Errc::invalid_argument,
                          "internal: texel views are R32, R32G32 or R32G32B32A32 floats");
    if (size_ / texel > ctx_->props.limits.maxTexelBufferElements)
        return make_error(Errc::unsupported, "a texel buffer of " + std::to_string(size_ / texel) +
                                                 " texels exceeds maxTexelBufferElements (" +
                                                 std::to_string(ctx_->props.limits.maxTexelBufferElements) + ")");
    VkBufferViewCreateInfo vi{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    vi.buffer = buffer_;
    vi.format = format;
    vi.offset = 0;
    vi.range = VK_WHOLE_SIZE;
    FGSR_VK(vkCreateBufferView(ctx_->device, &vi, nullptr, &view_), "vkCreateBufferView");
    return {};
}

Result<Buffer> Buffer::import_host(Context& ctx, void* data, VkDeviceSize size) {
    if (!ctx.host_import || !ctx.get_host_pointer_properties)
        return make_error(Errc::unsupported, std::string(ctx.props.deviceName) +
                                                 " does not support VK_EXT_external_memory_host");
    const VkDeviceSize align = ctx.host_import_alignment;
    if (size == 0 || reinterpret_cast<uintptr_t>(data) % align != 0 || size % align != 0)
        return make_error(Errc::invalid_argument, "host memory of " + std::to_string(size) +
                                                      " bytes is not aligned to " + std::to_string(align) +
                                                      " (minImportedHostPointerAlignment)");
    Buffer b;
    b.ctx_ = &ctx;
    b.size_ = size;
    b.imported_ = true;
    VkExternalMemoryBufferCreateInfo ext{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
    ext.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.pNext = &ext;
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    FGSR_VK(vkCreateBuffer(ctx.device, &bi, nullptr, &b.buffer_), "vkCreateBuffer (host import)");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device, b.buffer_, &req);
    VkMemoryHostPointerPropertiesEXT hp{VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT};
    FGSR_VK(ctx.get_host_pointer_properties(
                ctx.device, VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT, data, &hp),
            "vkGetMemoryHostPointerPropertiesEXT");
    const uint32_t types = req.memoryTypeBits & hp.memoryTypeBits;
    int type = -1;
    for (uint32_t i = 0; i < ctx.memory.memoryTypeCount && type < 0; ++i)
        if (types & (1u << i)) type = int(i);
    if (type < 0 || req.size > size)
        return make_error(Errc::unsupported, "no memory type can import this host allocation");
    VkImportMemoryHostPointerInfoEXT imp{VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT};
    imp.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    imp.pHostPointer = data;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.pNext = &imp;
    ai.allocationSize = size;
    ai.memoryTypeIndex = uint32_t(type);
    FGSR_VK(vkAllocateMemory(ctx.device, &ai, nullptr, &b.memory_), "vkAllocateMemory (host import)");
    FGSR_VK(vkBindBufferMemory(ctx.device, b.buffer_, b.memory_, 0), "vkBindBufferMemory (host import)");
    b.mapped_ = data;
    return b;
}

Result<Buffer> Buffer::create(Context& ctx, VkDeviceSize size, bool host) {
    Buffer b;
    b.ctx_ = &ctx;
    b.size_ = size;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = std::max<VkDeviceSize>(size, 16);
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
               VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
               VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    FGSR_VK(vkCreateBuffer(ctx.device, &bi, nullptr, &b.buffer_), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device, b.buffer_, &req);
    const VkMemoryPropertyFlags host_flags =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    auto pick = [&](VkMemoryPropertyFlags want) -> int {
        for (uint32_t i = 0; i < ctx.memory.memoryTypeCount; ++i)
            if ((req.memoryTypeBits & (1u << i)) && (ctx.memory.memoryTypes[i].propertyFlags & want) == want)
                return int(i);
        return -1;
    };
    int type = host ? pick(host_flags | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                    : pick(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type < 0) type = host ? pick(host_flags) : pick(0);
    if (type < 0)
        return make_error(Errc::vulkan,
                          "no suitable memory type for a buffer of " + std::to_string(size) + " bytes");
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = uint32_t(type);
    FGSR_VK(vkAllocateMemory(ctx.device, &ai, nullptr, &b.memory_), "vkAllocateMemory");
    FGSR_VK(vkBindBufferMemory(ctx.device, b.buffer_, b.memory_, 0), "vkBindBufferMemory");
    if (host) FGSR_VK(vkMapMemory(ctx.device, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_), "vkMapMemory");
    return b;
}

Pipeline& Pipeline::operator=(Pipeline&& o) noexcept {
    if (this != &o) {
        release();
        ctx_ = std::exchange(o.ctx_, nullptr);
        module_ = std::exchange(o.module_, VK_NULL_HANDLE);
        set_layout_ = std::exchange(o.set_layout_, VK_NULL_HANDLE);
        layout_ = std::exchange(o.layout_, VK_NULL_HANDLE);
        pipeline_ = std::exchange(o.pipeline_, VK_NULL_HANDLE);
        bindings_ = o.bindings_;
        push_size_ = o.push_size_;
    }
    return *this;
}

void Pipeline::release() {
    if (!ctx_) return;
    if (pipeline_) vkDestroyPipeline(ctx_->device, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(ctx_->device, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(ctx_->device, set_layout_, nullptr);
    if (module_) vkDestroyShaderModule(ctx_->device, module_, nullptr);
    ctx_ = nullptr;
}

Result<Pipeline> Pipeline::create(Context& ctx, std::string_view shader, uint32_t bindings,
                                  uint32_t push_size, uint32_t texels) {
    std::span<const uint32_t> code = shaders::spirv(shader);
    if (code.empty())
        return make_error(Errc::unsupported, "no embedded SPIR-V for pass '" + std::string(shader) + "'");
    Pipeline p;
    p.ctx_ = &ctx;
    p.bindings_ = bindings;
    p.push_size_ = push_size;
    VkShaderModuleCreateInfo si{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    si.codeSize = code.size_bytes();
    si.pCode = code.data();
    FGSR_VK(vkCreateShaderModule(ctx.device, &si, nullptr, &p.module_), "vkCreateShaderModule");
    std::vector<VkDescriptorSetLayoutBinding> b(bindings);
    for (uint32_t i = 0; i < bindings; ++i) {
        b[i].binding = i;
        b[i].descriptorType = (texels >> i) & 1u ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                                 : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = bindings;
    dl.pBindings = b.data();
    FGSR_VK(vkCreateDescriptorSetLayout(ctx.device, &dl, nullptr, &p.set_layout_),
            "vkCreateDescriptorSetLayout");
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_size};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &p.set_layout_;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    FGSR_VK(vkCreatePipelineLayout(ctx.device, &pl, nullptr, &p.layout_), "vkCreatePipelineLayout");
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = p.module_;
    ci.stage.pName = "main";
    ci.layout = p.layout_;
    FGSR_VK(vkCreateComputePipelines(ctx.device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline_),
            "vkCreateComputePipelines");
    return p;
}

} // namespace fgsr::vk
