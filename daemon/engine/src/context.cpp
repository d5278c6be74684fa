// The engine's device and context (context.hpp): Engine (device selection, the workgroup size, a
// pipeline per variant of shaders/variants.def created at its first use, device queries) and
// imported host memory.
#include "context.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace fgsr {

HostMemory::HostMemory(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HostMemory::~HostMemory() = default;
const std::byte* HostMemory::data() const {
    return impl_->data;
}
size_t HostMemory::size() const {
    return impl_->size;
}

Result<const vk::Pipeline*> Pipelines::get(Variant v) {
    const uint32_t i = uint32_t(v);
    if (ready_[i].load(std::memory_order_acquire)) return &pipes_[i];
    std::lock_guard lock(creating_[i]);
    if (!ready_[i].load(std::memory_order_relaxed)) {
        const VariantInfo& info = kVariants[i];
        const std::string shader = std::string(info.shader) + "_g" + std::to_string(group_);
        auto pipe =
            vk::Pipeline::create(*ctx_, shader, variant_bindings(v), pass_push(info.pass), variant_texels(v));
        if (!pipe) return pipe.error();
        pipes_[i] = std::move(*pipe);
        ready_[i].store(true, std::memory_order_release);
    }
    return &pipes_[i];
}

Result<void> Pipelines::create_all(uint32_t threads) {
    std::atomic<uint32_t> next{0};
    std::mutex error_mutex;
    std::optional<Error> first_error;
    auto work = [&] {
        for (uint32_t v; (v = next.fetch_add(1)) < kVariantCount;) {
            auto r = get(Variant(v));
            if (!r) {
                std::lock_guard lock(error_mutex);
                if (!first_error) first_error = r.error();
            }
        }
    };
    std::vector<std::jthread> pool;
    for (uint32_t t = 1; t < std::max(threads, 1u); ++t) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error&) { // no more threads: the ones there do the rest
            break;
        }
    }
    work();
    pool.clear(); // joins
    if (first_error) return *first_error;
    return {};
}

uint32_t Pipelines::created() const {
    uint32_t n = 0;
    for (const auto& r : ready_) n += r.load(std::memory_order_acquire) ? 1 : 0;
    return n;
}

Engine::Engine(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Engine::~Engine() = default;

Result<std::unique_ptr<Engine>> Engine::create(const DeviceOptions& options) {
    if (options.workgroup != 0 && options.workgroup != 8 && options.workgroup != 32)
        return make_error(Errc::invalid_argument,
                          "workgroup " + std::to_string(options.workgroup) + ": 0 (by device), 8 or 32");
    auto impl = std::make_unique<Impl>();
    auto ctx = vk::create_context(options);
    if (!ctx) return ctx.error();
    impl->ctx = std::move(*ctx);
    // Measured on lavapipe (2 cores, 1080p interpolation): 8x8 groups 364 ms, 16x16 157 ms,
    // 32x32 28 ms; its cost per workgroup dominates, so CPU devices get the 32x32 build.
    if (impl->ctx->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU &&
        impl->ctx->props.limits.maxComputeWorkGroupInvocations >= 1024 &&
        impl->ctx->props.limits.maxComputeWorkGroupSize[0] >= 32 &&
        impl->ctx->props.limits.maxComputeWorkGroupSize[1] >= 32)
        impl->group = 32;
    if (options.workgroup != 0) {
        const auto& lim = impl->ctx->props.limits;
        if (options.workgroup * options.workgroup > lim.maxComputeWorkGroupInvocations ||
            options.workgroup > lim.maxComputeWorkGroupSize[0] ||
            options.workgroup > lim.maxComputeWorkGroupSize[1])
            return make_error(Errc::unsupported, "workgroup " + std::to_string(options.workgroup) +
                                                     ": beyond the device's limits");
        impl->group = options.workgroup;
    }
    impl->pipelines.init(*impl->ctx, impl->group); // each variant's pipeline at its first use
    return std::unique_ptr<Engine>(new Engine(std::move(impl)));
}

std::string Engine::device_name() const {
    return impl_->ctx->props.deviceName;
}
bool Engine::is_cpu_device() const {
    return impl_->ctx->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}
uint32_t Engine::workgroup() const {
    return impl_->group;
}
uint64_t Engine::validation_errors() const {
    return impl_->ctx->validation_errors.load();
}
bool Engine::calibrated_time() const {
    return impl_->ctx->get_calibrated_timestamps != nullptr;
}
size_t Engine::host_import_alignment() const {
    return impl_->ctx->host_import ? size_t(impl_->ctx->host_import_alignment) : 0;
}
Result<std::unique_ptr<HostMemory>> Engine::import_host_memory(void* data, size_t size) {
    auto b = vk::Buffer::import_host(*impl_->ctx, data, size);
    if (!b) return b.error();
    auto impl = std::make_unique<HostMemory::Impl>();
    impl->buffer = std::move(*b);
    impl->data = static_cast<const std::byte*>(data);
    impl->size = size;
    return std::unique_ptr<HostMemory>(new HostMemory(std::move(impl)));
}
uint32_t Engine::pipelines_created() const {
    return impl_->pipelines.created();
}
uint32_t Engine::pipeline_variants() {
    return kVariantCount;
}
Result<std::vector<std::string>> Engine::list_devices() {
    return vk::enumerate_devices();
}

} // namespace fgsr
