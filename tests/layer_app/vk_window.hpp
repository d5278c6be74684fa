// The test application's Vulkan side (included once, by fgsr_layer_app.cpp): XCB windows, their
// swapchains, CPU-rendered frames uploaded with vkCmdCopyBufferToImage, swapchain recreation on
// resize and OUT_OF_DATE/SUBOPTIMAL.
#pragma once

namespace fgsr::layer_app {

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    uint8_t* mapped = nullptr;
};

struct Window {
    xcb_window_t xid = 0;
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    VkExtent2D extent{};
    std::vector<VkImage> images;
    std::vector<VkSemaphore> rendered; // per image
    VkCommandBuffer cmd[2]{};
    VkFence fence[2]{};
    VkSemaphore acquired[2]{};
    Buffer staging[2];
};

struct App {
    const Options& o;
    Format format;
    VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
    xcb_connection_t* xcb = nullptr;
    xcb_screen_t* screen = nullptr;
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t family = 0;
    VkCommandPool pool = VK_NULL_HANDLE;
    std::vector<Window> windows;
    Scene scene;
    uint32_t recreations = 0;

    explicit App(const Options& opt) : o(opt), format(parse_format(opt.format)) {}

    Buffer make_buffer(VkDeviceSize size) {
        Buffer b;
        VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bi.size = size;
        bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
        CHECK(vkCreateBuffer(device, &bi, nullptr, &b.buffer));
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(device, b.buffer, &req);
        VkPhysicalDeviceMemoryProperties mp;
        vkGetPhysicalDeviceMemoryProperties(physical, &mp);
        const VkMemoryPropertyFlags want =
            VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        uint32_t type = UINT32_MAX;
        for (uint32_t i = 0; i < mp.memoryTypeCount && type == UINT32_MAX; ++i)
            if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want)
                type = i;
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.allocationSize = req.size;
        ai.memoryTypeIndex = type;
        CHECK(vkAllocateMemory(device, &ai, nullptr, &b.memory));
        CHECK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
        void* p = nullptr;
        CHECK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &p));
        b.mapped = static_cast<uint8_t*>(p);
        return b;
    }

    int init() {
        xcb = xcb_connect(nullptr, nullptr);
        if (!xcb || xcb_connection_has_error(xcb)) {
            std::fprintf(stderr, "fgsr_layer_app: cannot connect to the X server ($DISPLAY)\n");
            return 1;
        }
        screen = xcb_setup_roots_iterator(xcb_get_setup(xcb)).data;
        const char* exts[] = {VK_KHR_SURFACE_EXTENSION_NAME, VK_KHR_XCB_SURFACE_EXTENSION_NAME};
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.pApplicationName = "fgsr_layer_app";
        app.apiVersion = VK_API_VERSION_1_1;
        VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        ici.pApplicationInfo = &app;
        ici.enabledExtensionCount = 2;
        ici.ppEnabledExtensionNames = exts;
        CHECK(vkCreateInstance(&ici, nullptr, &instance));
        uint32_t n = 1;
        VkPhysicalDevice pds[1];
        const VkResult er = vkEnumeratePhysicalDevices(instance, &n, pds);
        if ((er != VK_SUCCESS && er != VK_INCOMPLETE) || n == 0) return 1;
        physical = pds[0];
        windows.resize(o.windows);
        for (uint32_t i = 0; i < o.windows; ++i) {
            Window& w = windows[i];
            w.xid = xcb_generate_id(xcb);
            const uint32_t values[] = {screen->black_pixel};
            xcb_create_window(xcb, XCB_COPY_FROM_PARENT, w.xid, screen->root, int16_t(40 * i), 0,
                              uint16_t(o.width), uint16_t(o.height), 0, XCB_WINDOW_CLASS_INPUT_OUTPUT,
                              screen->root_visual, XCB_CW_BACK_PIXEL, values);
            xcb_map_window(xcb, w.xid);
            VkXcbSurfaceCreateInfoKHR sci{VK_STRUCTURE_TYPE_XCB_SURFACE_CREATE_INFO_KHR};
            sci.connection = xcb;
            sci.window = w.xid;
            CHECK(vkCreateXcbSurfaceKHR(instance, &sci, nullptr, &w.surface));
        }
        xcb_flush(xcb);
        uint32_t qn = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(physical, &qn, nullptr);
        std::vector<VkQueueFamilyProperties> qf(qn);
        vkGetPhysicalDeviceQueueFamilyProperties(physical, &qn, qf.data());
        family = UINT32_MAX;
        for (uint32_t i = 0; i < qn && family == UINT32_MAX; ++i) {
            VkBool32 present = VK_FALSE;
            vkGetPhysicalDeviceSurfaceSupportKHR(physical, i, windows[0].surface, &present);
            if ((qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && present) family = i;
        }
        if (family == UINT32_MAX) return 1;
        // The requested format and present mode, or a skip.
        uint32_t fn = 0;
        vkGetPhysicalDeviceSurfaceFormatsKHR(physical, windows[0].surface, &fn, nullptr);
        std::vector<VkSurfaceFormatKHR> formats(fn);
        vkGetPhysicalDeviceSurfaceFormatsKHR(physical, windows[0].surface, &fn, formats.data());
        bool has_format = false;
        for (const VkSurfaceFormatKHR& f : formats) has_format |= f.format == format.vk;
        present_mode = o.present_mode == "mailbox"     ? VK_PRESENT_MODE_MAILBOX_KHR
                       : o.present_mode == "immediate" ? VK_PRESENT_MODE_IMMEDIATE_KHR
                                                       : VK_PRESENT_MODE_FIFO_KHR;
        uint32_t pn = 0;
        vkGetPhysicalDeviceSurfacePresentModesKHR(physical, windows[0].surface, &pn, nullptr);
        std::vector<VkPresentModeKHR> modes(pn);
        vkGetPhysicalDeviceSurfacePresentModesKHR(physical, windows[0].surface, &pn, modes.data());
        bool has_mode = false;
        for (VkPresentModeKHR m : modes) has_mode |= m == present_mode;
        if (!has_format || !has_mode) {
            std::fprintf(stderr, "fgsr_layer_app: the surface lacks format %s or present mode %s: skipping\n",
                         o.format.c_str(), o.present_mode.c_str());
            return 77;
        }
        const float prio = 1.0f;
        VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        qci.queueFamilyIndex = family;
        qci.queueCount = 1;
        qci.pQueuePriorities = &prio;
        const char* dexts[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
        VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &qci;
        dci.enabledExtensionCount = 1;
        dci.ppEnabledExtensionNames = dexts;
        CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
        vkGetDeviceQueue(device, family, 0, &queue);
        VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pci.queueFamilyIndex = family;
        CHECK(vkCreateCommandPool(device, &pci, nullptr, &pool));
        const VkDeviceSize bytes =
            VkDeviceSize(std::max(o.width, o.resize_w)) * std::max(o.height, o.resize_h) * 8;
        for (Window& w : windows) {
            for (int s = 0; s < 2; ++s) {
                VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
                ai.commandPool = pool;
                ai.commandBufferCount = 1;
                CHECK(vkAllocateCommandBuffers(device, &ai, &w.cmd[s]));
                VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
                fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
                CHECK(vkCreateFence(device, &fi, nullptr, &w.fence[s]));
                VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
                CHECK(vkCreateSemaphore(device, &si, nullptr, &w.acquired[s]));
                w.staging[s] = make_buffer(bytes);
            }
            if (!create_swapchain(w)) return 1;
        }
        return 0;
    }

    bool create_swapchain(Window& w) {
        VkSurfaceCapabilitiesKHR caps;
        CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, w.surface, &caps));
        VkExtent2D extent = caps.currentExtent;
        if (extent.width == UINT32_MAX) extent = {o.width, o.height};
        if (extent.width == 0 || extent.height == 0) return false;
        VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
        ci.surface = w.surface;
        ci.minImageCount = std::max(caps.minImageCount, 2u);
        if (caps.maxImageCount) ci.minImageCount = std::min(ci.minImageCount, caps.maxImageCount);
        ci.imageFormat = format.vk;
        ci.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
        ci.imageExtent = extent;
        ci.imageArrayLayers = 1;
        ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
        ci.preTransform = caps.currentTransform;
        ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
        ci.presentMode = present_mode;
        ci.clipped = VK_TRUE;
        ci.oldSwapchain = w.swapchain;
        VkSwapchainKHR created;
        CHECK(vkCreateSwapchainKHR(device, &ci, nullptr, &created));
        if (w.swapchain) {
            vkDestroySwapchainKHR(device, w.swapchain, nullptr);
            ++recreations;
        }
        w.swapchain = created;
        w.extent = extent;
        uint32_t n = 0;
        CHECK(vkGetSwapchainImagesKHR(device, w.swapchain, &n, nullptr));
        w.images.resize(n);
        CHECK(vkGetSwapchainImagesKHR(device, w.swapchain, &n, w.images.data()));
        for (VkSemaphore s : w.rendered) vkDestroySemaphore(device, s, nullptr);
        w.rendered.assign(n, VK_NULL_HANDLE);
        for (VkSemaphore& s : w.rendered) {
            VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
            CHECK(vkCreateSemaphore(device, &si, nullptr, &s));
        }
        return true;
    }

    void recreate(Window& w) {
        CHECK(vkDeviceWaitIdle(device));
        if (!create_swapchain(w)) std::exit(1);
    }

    void resize(Window& w, uint32_t width, uint32_t height) {
        const uint32_t values[] = {width, height};
        xcb_configure_window(xcb, w.xid, XCB_CONFIG_WINDOW_WIDTH | XCB_CONFIG_WINDOW_HEIGHT, values);
        xcb_flush(xcb);
        free(xcb_get_input_focus_reply(xcb, xcb_get_input_focus(xcb), nullptr)); // round trip
        for (int i = 0; i < 100; ++i) { // until the surface reports the new size
            VkSurfaceCapabilitiesKHR caps;
            CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, w.surface, &caps));
            if (caps.currentExtent.width == width && caps.currentExtent.height == height) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        recreate(w);
    }

    // One frame of one window; false when the swapchain had to be recreated first (retry).
    // With `batch`, the present is left to present_batch (one vkQueuePresentKHR for every window).
    struct Batch {
        std::vector<VkSwapchainKHR> swapchains;
        std::vector<uint32_t> indices;
        std::vector<VkSemaphore> semaphores;
    };
    bool frame(Window& w, uint32_t f, Batch* batch = nullptr) {
        const int s = int(f % 2);
        CHECK(vkWaitForFences(device, 1, &w.fence[s], VK_TRUE, UINT64_MAX));
        uint32_t index = 0;
        VkResult r =
            vkAcquireNextImageKHR(device, w.swapchain, UINT64_MAX, w.acquired[s], VK_NULL_HANDLE, &index);
        if (r == VK_ERROR_OUT_OF_DATE_KHR) {
            recreate(w);
            return false;
        }
        if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) CHECK(r);
        CHECK(vkResetFences(device, 1, &w.fence[s]));
        render(scene, float(double(f) * o.dt), w.extent.width, w.extent.height, format.vk,
               w.staging[s].mapped);
        VkCommandBuffer cmd = w.cmd[s];
        CHECK(vkResetCommandBuffer(cmd, 0));
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        CHECK(vkBeginCommandBuffer(cmd, &bi));
        VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
        b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = w.images[index];
        b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                             nullptr, 0, nullptr, 1, &b);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {w.extent.width, w.extent.height, 1};
        vkCmdCopyBufferToImage(cmd, w.staging[s].buffer, w.images[index],
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = 0;
        b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0,
                             nullptr, 0, nullptr, 1, &b);
        CHECK(vkEndCommandBuffer(cmd));
        const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.waitSemaphoreCount = 1;
        si.pWaitSemaphores = &w.acquired[s];
        si.pWaitDstStageMask = &stage;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmd;
        si.signalSemaphoreCount = 1;
        si.pSignalSemaphores = &w.rendered[index];
        CHECK(vkQueueSubmit(queue, 1, &si, w.fence[s]));
        if (batch) {
            batch->swapchains.push_back(w.swapchain);
            batch->indices.push_back(index);
            batch->semaphores.push_back(w.rendered[index]);
            return true;
        }
        VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
        pi.waitSemaphoreCount = 1;
        pi.pWaitSemaphores = &w.rendered[index];
        pi.swapchainCount = 1;
        pi.pSwapchains = &w.swapchain;
        pi.pImageIndices = &index;
        r = vkQueuePresentKHR(queue, &pi);
        if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
            recreate(w);
        else
            CHECK(r);
        return true;
    }

    void present_batch(const Batch& b) {
        VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
        pi.waitSemaphoreCount = uint32_t(b.semaphores.size());
        pi.pWaitSemaphores = b.semaphores.data();
        pi.swapchainCount = uint32_t(b.swapchains.size());
        pi.pSwapchains = b.swapchains.data();
        pi.pImageIndices = b.indices.data();
        std::vector<VkResult> results(b.swapchains.size(), VK_SUCCESS);
        pi.pResults = results.data();
        const VkResult r = vkQueuePresentKHR(queue, &pi);
        if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR && r != VK_ERROR_OUT_OF_DATE_KHR) CHECK(r);
        for (size_t i = 0; i < results.size(); ++i)
            if (results[i] == VK_ERROR_OUT_OF_DATE_KHR || results[i] == VK_SUBOPTIMAL_KHR)
                recreate(windows[i]);
    }

    void destroy() {
        vkDeviceWaitIdle(device);
        for (Window& w : windows) {
            for (int s = 0; s < 2; ++s) {
                vkDestroyFence(device, w.fence[s], nullptr);
                vkDestroySemaphore(device, w.acquired[s], nullptr);
                vkDestroyBuffer(device, w.staging[s].buffer, nullptr);
                vkFreeMemory(device, w.staging[s].memory, nullptr);
            }
            for (VkSemaphore s : w.rendered) vkDestroySemaphore(device, s, nullptr);
            vkDestroySwapchainKHR(device, w.swapchain, nullptr);
            vkDestroySurfaceKHR(instance, w.surface, nullptr);
        }
        vkDestroyCommandPool(device, pool, nullptr);
        vkDestroyDevice(device, nullptr);
        vkDestroyInstance(instance, nullptr);
        xcb_disconnect(xcb);
    }
};

int run(const Options& o) {
    App app(o);
    if (const int r = app.init(); r != 0) return r;
    if (o.flash_on_click) { // the windows listen for the probe's click (button or key press)
        const uint32_t mask = XCB_EVENT_MASK_BUTTON_PRESS | XCB_EVENT_MASK_KEY_PRESS;
        for (Window& w : app.windows) xcb_change_window_attributes(app.xcb, w.xid, XCB_CW_EVENT_MASK, &mask);
        xcb_flush(app.xcb);
    }
    const auto start = std::chrono::steady_clock::now();
    for (uint32_t f = 0; f < o.frames; ++f) {
        while (o.flash_on_click) { // each press turns the next frame white (render())
            xcb_generic_event_t* e = xcb_poll_for_event(app.xcb);
            if (!e) break;
            const uint8_t type = e->response_type & 0x7f;
            if (type == XCB_BUTTON_PRESS || type == XCB_KEY_PRESS) g_flash_pending = true;
            std::free(e);
        }
        if (int(f) == o.resize_at)
            for (Window& w : app.windows) app.resize(w, o.resize_w, o.resize_h);
        if (o.fps > 0)
            std::this_thread::sleep_until(start + std::chrono::duration<double>(double(f) / o.fps));
        App::Batch batch;
        for (Window& w : app.windows)
            for (int attempt = 0; attempt < 10 && !app.frame(w, f, o.one_present ? &batch : nullptr);
                 ++attempt) {
            }
        if (o.one_present) app.present_batch(batch);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "{\"frames\": %u, \"seconds\": %.3f, \"fps\": %.2f, \"format\": \"%s\", \"extent\": \"%ux%u\", "
        "\"recreations\": %u}\n",
        o.frames, seconds, double(o.frames) / seconds, o.format.c_str(), app.windows[0].extent.width,
        app.windows[0].extent.height, app.recreations);
    std::fflush(stdout);
    if (!o.destroy) {
        CHECK(vkDeviceWaitIdle(app.device));
        std::exit(0); // the swapchain, device and instance are left to the process's end
    }
    app.destroy();
    return 0;
}

} // namespace fgsr::layer_app
