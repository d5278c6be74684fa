// fgsr_layer_app: the layer's test application. Renders the analytic scene of scene.hpp on the CPU,
// uploads each frame into a swapchain image of an XCB window (its own Vulkan code, no windowing
// library) and presents it; or scores dumped generated frames against the exact frames.
//
//   fgsr_layer_app [--frames 60] [--width 1280 --height 720] [--fps 0] [--dt 0.0333]
//                  [--format bgra8|rgba8|bgra8-srgb|rgba8-srgb|rgba16f|a2b10g10r10]
//                  [--present-mode fifo|mailbox|immediate] [--resize-at K:WxH] [--windows 1|2]
//                  [--no-destroy] [--one-present] [--flash-on-click] [--probe-instances N]
//   fgsr_layer_app --score DIR [--dt 0.0333] [--write-exact]
//                  (no Vulkan: scores DIR's gen_*.json/.rgba; --write-exact writes gen_*.exact.rgba)
//
// --probe-instances N: first create and destroy a Vulkan instance N times, enumerating its devices,
// as a launcher probing the GPUs does; the loader loads and unloads the layers each time.
// --flash-on-click (for `fgsr probe --run-command`, docs/PROBE.md): each mouse button or key press
// in a window turns the next frame white, for a photodiode latency probe to see the click.
// Prints one JSON line: run: {"frames", "seconds", "fps", "format", "extent", "recreations"}; score:
// {"generated", "psnr_generated", "psnr_blend", "psnr_repeat", "psnr_generated_min"} (mean PSNR in dB
// of the RGB display values against the exact frame at each generated frame's instant; blend: the
// 50/50 blend of the neighbouring real frames; repeat: the nearest real frame; to_linear_blend: the
// generated frame against the neighbours mixed at its alpha in linear light, above 40 dB when the
// daemon blends instead of estimating motion). Exit 0 on success, 77 when
// the surface lacks the requested format or present mode (a skip), 1 on errors.
#include "scene.hpp"

#include <xcb/xcb.h>

#include <vulkan/vulkan.h>
#include <vulkan/vulkan_xcb.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace fgsr::layer_app {

struct Options {
    uint32_t frames = 60, width = 1280, height = 720, windows = 1;
    double fps = 0, dt = 1.0 / 30.0;
    std::string format = "bgra8", present_mode = "fifo", score_dir;
    int resize_at = -1;
    uint32_t resize_w = 0, resize_h = 0;
    bool destroy = true;
    bool one_present = false; // all windows in one vkQueuePresentKHR
    bool write_exact = false; // --score: also write DIR/gen_*.exact.rgba
    bool flash_on_click = false;
    uint32_t probe_instances = 0;
};

// --flash-on-click: set by a button or key press, cleared by the frame it turns white.
bool g_flash_pending = false;

#define CHECK(expr)                                                                                          \
    do {                                                                                                     \
        const VkResult r_ = (expr);                                                                          \
        if (r_ != VK_SUCCESS) {                                                                              \
            std::fprintf(stderr, "fgsr_layer_app: %s failed: %d\n", #expr, int(r_));                         \
            std::exit(1);                                                                                    \
        }                                                                                                    \
    } while (0)

float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linear_to_srgb(float c) {
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

uint16_t to_half(float f) { // values in [0, 1]: normal or zero halves
    if (f < 6.2e-5f) return 0;
    uint32_t b;
    std::memcpy(&b, &f, 4);
    const uint32_t e = ((b >> 23) & 0xff) - 127 + 15;
    return uint16_t(e << 10 | ((b >> 13) & 0x3ff));
}

struct Format {
    VkFormat vk;
    uint32_t bpp;
};

Format parse_format(const std::string& s) {
    if (s == "bgra8") return {VK_FORMAT_B8G8R8A8_UNORM, 4};
    if (s == "rgba8") return {VK_FORMAT_R8G8B8A8_UNORM, 4};
    if (s == "bgra8-srgb") return {VK_FORMAT_B8G8R8A8_SRGB, 4};
    if (s == "rgba8-srgb") return {VK_FORMAT_R8G8B8A8_SRGB, 4};
    if (s == "rgba16f") return {VK_FORMAT_R16G16B16A16_SFLOAT, 8};
    if (s == "a2b10g10r10") return {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 4};
    std::fprintf(stderr, "fgsr_layer_app: unknown format %s\n", s.c_str());
    std::exit(1);
}

// Writes the scene at t into `dst` (rows w * bpp bytes) in the swapchain's format.
void render(const Scene& scene, float t, uint32_t w, uint32_t h, VkFormat f, uint8_t* dst) {
    const bool flash = std::exchange(g_flash_pending, false);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            float c[3];
            scene.shade(t, w, h, x, y, c);
            if (flash) c[0] = c[1] = c[2] = 1.0f;
            for (float& v : c) v = std::clamp(v, 0.0f, 1.0f);
            const size_t i = size_t(y) * w + x;
            switch (f) {
            case VK_FORMAT_B8G8R8A8_UNORM:
            case VK_FORMAT_B8G8R8A8_SRGB:
                dst[i * 4 + 0] = uint8_t(std::lround(c[2] * 255));
                dst[i * 4 + 1] = uint8_t(std::lround(c[1] * 255));
                dst[i * 4 + 2] = uint8_t(std::lround(c[0] * 255));
                dst[i * 4 + 3] = 255;
                break;
            case VK_FORMAT_R16G16B16A16_SFLOAT: {
                uint16_t* p = reinterpret_cast<uint16_t*>(dst) + i * 4;
                for (int k = 0; k < 3; ++k) p[k] = to_half(srgb_to_linear(c[k]));
                p[3] = to_half(1.0f);
                break;
            }
            case VK_FORMAT_A2B10G10R10_UNORM_PACK32: {
                uint32_t v = 3u << 30;
                for (int k = 0; k < 3; ++k) v |= uint32_t(std::lround(c[k] * 1023)) << (10 * k);
                std::memcpy(dst + i * 4, &v, 4);
                break;
            }
            default:
                for (int k = 0; k < 3; ++k) dst[i * 4 + k] = uint8_t(std::lround(c[k] * 255));
                dst[i * 4 + 3] = 255;
            }
        }
}

// ---- scoring --------------------------------------------------------------------------------------

double psnr(const uint8_t* a, const uint8_t* b, size_t pixels) {
    double se = 0;
    for (size_t i = 0; i < pixels; ++i)
        for (int k = 0; k < 3; ++k) {
            const double d = double(a[i * 4 + k]) - double(b[i * 4 + k]);
            se += d * d;
        }
    const double mse = se / double(pixels * 3);
    return mse <= 1e-12 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::string json_field(const std::string& j, const std::string& key) {
    const size_t p = j.find("\"" + key + "\"");
    if (p == std::string::npos) return {};
    size_t v = j.find(':', p) + 1;
    while (v < j.size() && (j[v] == ' ' || j[v] == '"')) ++v;
    size_t e = v;
    while (e < j.size() && j[e] != ',' && j[e] != '}' && j[e] != '"') ++e;
    return j.substr(v, e - v);
}

int score(const Options& o) {
    Scene scene;
    DIR* d = opendir(o.score_dir.c_str());
    if (!d) {
        std::fprintf(stderr, "fgsr_layer_app: cannot open %s\n", o.score_dir.c_str());
        return 1;
    }
    std::vector<std::string> names;
    while (dirent* e = readdir(d)) {
        const std::string n = e->d_name;
        if (n.size() > 5 && n.rfind("gen_", 0) == 0 && n.substr(n.size() - 5) == ".json") names.push_back(n);
    }
    closedir(d);
    double sum_gen = 0, sum_blend = 0, sum_repeat = 0, sum_linear_blend = 0, min_gen = 1e9;
    uint32_t n = 0;
    for (const std::string& name : names) {
        std::ifstream jf(o.score_dir + "/" + name);
        std::stringstream js;
        js << jf.rdbuf();
        const std::string j = js.str();
        const uint32_t w = uint32_t(std::stoul(json_field(j, "width"))),
                       h = uint32_t(std::stoul(json_field(j, "height")));
        const uint64_t k = std::stoull(json_field(j, "app_present"));
        const double alpha = std::stod(json_field(j, "alpha"));
        const bool interp = json_field(j, "mode") == "interpolate";
        if (w == 0 || h == 0 || w > 8192 || h > 8192 || (interp && k == 0)) continue;
        std::vector<uint8_t> gen(size_t(w) * h * 4), exact(gen.size()), a(gen.size()), b(gen.size()),
            blend(gen.size());
        std::ifstream rf(o.score_dir + "/" + name.substr(0, name.size() - 5) + ".rgba", std::ios::binary);
        if (!rf.read(reinterpret_cast<char*>(gen.data()), std::streamsize(gen.size()))) continue;
        const double t = interp ? (double(k) - 1.0 + alpha) * o.dt : (double(k) + alpha) * o.dt;
        scene.render_rgba8(float(t), w, h, exact.data());
        // Baseline: the 50/50 blend of the neighbours (interpolation); the newest frame repeated
        // (extrapolation: its only neighbour).
        scene.render_rgba8(float(interp ? (double(k) - 1.0) * o.dt : double(k) * o.dt), w, h, a.data());
        scene.render_rgba8(float(double(k) * o.dt), w, h, b.data());
        for (size_t i = 0; i < gen.size(); ++i) blend[i] = uint8_t((unsigned(a[i]) + unsigned(b[i]) + 1) / 2);
        if (o.write_exact) { // for looking at: the exact frame beside each dumped one
            std::ofstream(o.score_dir + "/" + name.substr(0, name.size() - 5) + ".exact.rgba",
                          std::ios::binary)
                .write(reinterpret_cast<const char*>(exact.data()), std::streamsize(exact.size()));
        }
        const double pg = psnr(gen.data(), exact.data(), size_t(w) * h);
        // What a daemon without motion estimation returns: the neighbours mixed at alpha in linear
        // light. A generated frame within 40 dB of it is that blend.
        for (size_t i = 0; i < gen.size(); ++i) {
            const float la = srgb_to_linear(float(a[i]) / 255.0f), lb = srgb_to_linear(float(b[i]) / 255.0f);
            const float mix = float(interp ? 1.0 - alpha : 0.0) * la + float(interp ? alpha : 1.0) * lb;
            blend[i] = uint8_t(std::lround(std::clamp(linear_to_srgb(mix), 0.0f, 1.0f) * 255.0f));
        }
        sum_linear_blend += psnr(gen.data(), blend.data(), size_t(w) * h);
        for (size_t i = 0; i < gen.size(); ++i) blend[i] = uint8_t((unsigned(a[i]) + unsigned(b[i]) + 1) / 2);
        // Repeat: the real frame nearest to the generated instant.
        sum_repeat += psnr((interp && alpha < 0.5 ? a : b).data(), exact.data(), size_t(w) * h);
        sum_gen += pg;
        min_gen = std::min(min_gen, pg);
        sum_blend += psnr(blend.data(), exact.data(), size_t(w) * h);
        ++n;
    }
    if (n == 0) {
        std::printf("{\"generated\": 0}\n");
        return 1;
    }
    std::printf("{\"generated\": %u, \"psnr_generated\": %.3f, \"psnr_blend\": %.3f, \"psnr_repeat\": %.3f, "
                "\"psnr_generated_min\": %.3f, \"psnr_to_linear_blend\": %.3f}\n",
                n, sum_gen / n, sum_blend / n, sum_repeat / n, min_gen, sum_linear_blend / n);
    return 0;
}

} // namespace fgsr::layer_app

#include "vk_window.hpp"

namespace fgsr::layer_app {

// --probe-instances: instances created and destroyed before the run.
void probe_instances(uint32_t count) {
    for (uint32_t k = 0; k < count; ++k) {
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.pApplicationName = "fgsr_layer_app probe";
        app.apiVersion = VK_API_VERSION_1_1;
        VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        ci.pApplicationInfo = &app;
        VkInstance instance = VK_NULL_HANDLE;
        CHECK(vkCreateInstance(&ci, nullptr, &instance));
        uint32_t n = 0;
        CHECK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
        vkDestroyInstance(instance, nullptr);
    }
}

} // namespace fgsr::layer_app

int main(int argc, char** argv) {
    using namespace fgsr::layer_app;
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "fgsr_layer_app: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--frames")
            o.frames = uint32_t(std::stoul(next()));
        else if (a == "--width")
            o.width = uint32_t(std::stoul(next()));
        else if (a == "--height")
            o.height = uint32_t(std::stoul(next()));
        else if (a == "--fps")
            o.fps = std::stod(next());
        else if (a == "--dt")
            o.dt = std::stod(next());
        else if (a == "--format")
            o.format = next();
        else if (a == "--present-mode")
            o.present_mode = next();
        else if (a == "--windows")
            o.windows = uint32_t(std::stoul(next()));
        else if (a == "--no-destroy")
            o.destroy = false;
        else if (a == "--one-present")
            o.one_present = true;
        else if (a == "--write-exact")
            o.write_exact = true;
        else if (a == "--flash-on-click")
            o.flash_on_click = true;
        else if (a == "--probe-instances")
            o.probe_instances = uint32_t(std::stoul(next()));
        else if (a == "--score")
            o.score_dir = next();
        else if (a == "--resize-at") {
            const std::string v = next();
            if (std::sscanf(v.c_str(), "%d:%ux%u", &o.resize_at, &o.resize_w, &o.resize_h) != 3) {
                std::fprintf(stderr, "fgsr_layer_app: --resize-at K:WxH\n");
                return 1;
            }
        } else {
            std::fprintf(stderr, "fgsr_layer_app: unknown option %s\n", a.c_str());
            return 1;
        }
    }
    if (!o.score_dir.empty()) return score(o);
    probe_instances(o.probe_instances);
    return run(o);
}
