// The engine's device side, shared by its sessions: the Vulkan context, the workgroup size, one
// pipeline per shader variant (variants.hpp), and imported host memory.
#pragma once

#include <fgsr/engine/engine.hpp>

#include "recorder.hpp"
#include "vk.hpp"

#include <memory>

namespace fgsr {

struct Engine::Impl {
    std::unique_ptr<vk::Context> ctx;
    uint32_t group = 8; // workgroup side of every pass
    Pipelines pipelines;
};

struct HostMemory::Impl {
    vk::Buffer buffer;
    const std::byte* data = nullptr;
    size_t size = 0;
};

} // namespace fgsr
