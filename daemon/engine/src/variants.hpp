// The engine's side of the pass table: the shader variants (shaders/variants.def) as fgsr::Variant,
// what each one binds (shaders/bindings.h) and pushes, and Slots, a pass's descriptor bindings
// indexed by the binding numbers of bindings.h.
#pragma once

#include <fgsr/engine/passes.hpp>
#include <fgsr/protocol.h>

#include "bindings.h"
#include "common.h" // shaders/: the push-constant structs

#include "vk.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace fgsr {

// The engine's pass ids are the protocol's (both follow from fgsr/passes.h).
#define FGSR_ENGINE_PASS_CHECK_(ID, name, value)                                                             \
    static_assert(uint32_t(PassId::name) == uint32_t(FGSR_PASS_##ID) && uint32_t(PassId::name) == value);
FGSR_PASSES(FGSR_ENGINE_PASS_CHECK_)
#undef FGSR_ENGINE_PASS_CHECK_
static_assert(kPassCount == uint32_t(FGSR_PASS_COUNT_));

// PLAIN: the pass's <PASS>_COUNT bindings; TILED: TILED_EXTRA more after them (shaders/tiles.h).
enum class Layout : uint32_t { PLAIN, TILED };

// One enumerator per line of shaders/variants.def, in its order: the engine's pipelines.
enum class Variant : uint32_t {
#define FGSR_VARIANT(name, source, pass, layout, defines) name,
#include "variants.def"
#undef FGSR_VARIANT
    count
};
inline constexpr uint32_t kVariantCount = uint32_t(Variant::count);

struct VariantInfo {
    std::string_view shader; // embedded "<shader>_g<group>"
    PassId pass;             // timing, bindings and push constants
    Layout layout;
};
inline constexpr std::array<VariantInfo, kVariantCount> kVariants = {{
#define FGSR_VARIANT(name, source, pass, layout, defines) {#name, PassId(FGSR_PASS_##pass), Layout::layout},
#include "variants.def"
#undef FGSR_VARIANT
}};

// generate_sr's push block is GenParams followed by SrParams.
struct GenSrPush {
    gpu::GenParams g;
    gpu::SrParams s;
};
static_assert(offsetof(GenSrPush, s) == sizeof(gpu::GenParams) && sizeof(GenSrPush) <= 128);
static_assert(offsetof(gpu::SplatParams, count) == sizeof(gpu::GenParams) &&
              sizeof(gpu::SplatParams) == sizeof(gpu::GenParams) + (2 + FGSR_SPLAT_ALPHAS) * 4);

// Storage buffers a pass binds before the tiled ones (shaders/bindings.h, <PASS>_COUNT).
constexpr uint32_t pass_bindings(PassId p) {
    switch (p) {
    case PassId::ingest:
        return INGEST_COUNT;
    case PassId::splat:
        return SPLAT_COUNT;
    case PassId::refine:
        return REFINE_COUNT;
    case PassId::disocc:
        return DISOCC_COUNT;
    case PassId::warp:
        return WARP_COUNT;
    case PassId::blend:
        return BLEND_COUNT;
    case PassId::generate:
        return GENERATE_COUNT;
    case PassId::sr:
        return SR_COUNT;
    case PassId::generate_sr:
        return GENSR_COUNT;
    case PassId::classify:
        return CLASSIFY_COUNT;
    case PassId::denoise:
        return DENOISE_COUNT;
    case PassId::luma:
        return LUMA_COUNT;
    case PassId::match:
        return MATCH_COUNT;
    case PassId::flow:
        return FLOW_COUNT;
    case PassId::polish:
        return POLISH_COUNT;
    case PassId::agree:
        return AGREE_COUNT;
    case PassId::count:
        break;
    }
    return 0;
}

// Push-constant bytes of a pass.
constexpr uint32_t pass_push(PassId p) {
    switch (p) {
    case PassId::ingest:
        return sizeof(gpu::IngestParams);
    case PassId::splat:
        return sizeof(gpu::SplatParams);
    case PassId::refine:
    case PassId::disocc:
    case PassId::warp:
    case PassId::blend:
    case PassId::generate:
        return sizeof(gpu::GenParams);
    case PassId::sr:
        return sizeof(gpu::SrParams);
    case PassId::generate_sr:
        return sizeof(GenSrPush);
    case PassId::classify:
        return sizeof(gpu::ClassifyParams);
    case PassId::denoise:
        return sizeof(gpu::DenoiseParams);
    case PassId::luma:
        return sizeof(gpu::LumaParams);
    case PassId::match:
        return sizeof(gpu::MatchParams);
    case PassId::flow:
        return sizeof(gpu::FlowParams);
    case PassId::polish:
        return sizeof(gpu::PolishParams);
    case PassId::agree:
        return sizeof(gpu::AgreeParams);
    case PassId::count:
        break;
    }
    return 0;
}

// Bindings a pass reads as uniform texel buffers (R32_SFLOAT, texelFetch), one bit per binding
// number; every other binding is a storage buffer (shaders/bindings.h, <PASS>_TEXELS).
constexpr uint32_t pass_texels(PassId p) {
    switch (p) {
    case PassId::luma:
        return LUMA_TEXELS;
    case PassId::match:
        return MATCH_TEXELS;
    case PassId::flow:
        return FLOW_TEXELS;
    case PassId::polish:
        return POLISH_TEXELS;
    default:
        return 0;
    }
}

constexpr uint32_t layout_bindings(PassId p, Layout l) {
    return pass_bindings(p) + (l == Layout::TILED ? uint32_t(TILED_EXTRA) : 0u);
}
constexpr const VariantInfo& variant_info(Variant v) {
    return kVariants[uint32_t(v)];
}
constexpr uint32_t variant_bindings(Variant v) {
    return layout_bindings(variant_info(v).pass, variant_info(v).layout);
}
constexpr uint32_t variant_texels(Variant v) {
    return pass_texels(variant_info(v).pass);
}

// Every variant names a pass, fits the descriptor writes of Recorder::bind, and has a push block.
constexpr uint32_t kMaxBindings = 17; // the agree pass (bindings.h AGREE_COUNT)
constexpr bool variants_valid() {
    for (const VariantInfo& v : kVariants)
        if (uint32_t(v.pass) >= kPassCount || layout_bindings(v.pass, v.layout) > kMaxBindings ||
            pass_push(v.pass) == 0 || pass_push(v.pass) > 128)
            return false;
    return true;
}
static_assert(variants_valid());

// A storage-buffer binding: a whole engine buffer, or a range of one (imported host memory).
// Default-constructed it is unbound, which Recorder::bind refuses.
struct BufRef {
    BufRef() = default;
    BufRef(const vk::Buffer& b) : buffer(b.handle()), view(b.texel_view()) {}
    BufRef(VkBuffer b, VkDeviceSize o = 0, VkDeviceSize r = VK_WHOLE_SIZE) : buffer(b), offset(o), range(r) {}
    VkBuffer buffer = VK_NULL_HANDLE;
    VkBufferView view = VK_NULL_HANDLE; // the whole buffer's texel view, for texel bindings
    VkDeviceSize offset = 0;
    VkDeviceSize range = VK_WHOLE_SIZE;
};

// Buffers for the bindings I... (numbers of shaders/bindings.h), in that order: at<SR_COLOR>(b),
// or several at once (a group the passes share, e.g. the GEN_* frames).
template <uint32_t... I> struct At { std::array<BufRef, sizeof...(I)> buf; };
template <uint32_t I> At<I> at(BufRef b) {
    return At<I>{{b}};
}

// A buffer bound to a slot the variant does not read: Vulkan needs every binding of the set
// layout bound to a valid buffer, and any buffer of the right kind serves.
inline BufRef unused(BufRef b) {
    return b;
}

// The descriptor bindings of one dispatch of pass P in layout L (slot i is binding i): the pass's
// <PASS>_COUNT bindings, plus TILED_EXTRA for TILED. Made only by make_slots, which checks at
// compile time that its parts bind every slot exactly once.
template <PassId P, Layout L = Layout::PLAIN> struct Slots {
    static constexpr PassId pass = P;
    static constexpr Layout layout = L;
    static constexpr uint32_t count = layout_bindings(P, L);
    std::array<BufRef, count> slot{};
    const BufRef& operator[](uint32_t binding) const { return slot[binding]; }
};
static_assert(Slots<PassId::ingest>::count == INGEST_COUNT && Slots<PassId::splat>::count == SPLAT_COUNT &&
              Slots<PassId::refine>::count == REFINE_COUNT && Slots<PassId::disocc>::count == DISOCC_COUNT &&
              Slots<PassId::warp>::count == WARP_COUNT && Slots<PassId::blend>::count == BLEND_COUNT &&
              Slots<PassId::generate>::count == GENERATE_COUNT && Slots<PassId::sr>::count == SR_COUNT &&
              Slots<PassId::generate_sr>::count == GENSR_COUNT &&
              Slots<PassId::classify>::count == CLASSIFY_COUNT &&
              Slots<PassId::denoise>::count == DENOISE_COUNT &&
              Slots<PassId::splat, Layout::TILED>::count == SPLAT_COUNT + TILED_EXTRA);

namespace detail {

template <class T> struct BindingsOf;
template <uint32_t... I> struct BindingsOf<At<I...>> {
    static constexpr std::array<uint32_t, sizeof...(I)> value{I...};
};

// Whether the parts bind each of the N slots exactly once.
template <uint32_t N, class... Parts> constexpr bool binds_each_once() {
    std::array<uint32_t, N> seen{};
    bool ok = true;
    auto add = [&](const auto& bindings) {
        for (uint32_t b : bindings) {
            if (b >= N)
                ok = false;
            else
                ++seen[b];
        }
    };
    (add(BindingsOf<Parts>::value), ...);
    for (uint32_t c : seen) ok = ok && c == 1;
    return ok;
}

template <class S, uint32_t... I> void fill(S& s, const At<I...>& part) {
    size_t k = 0;
    ((s.slot[I] = part.buf[k++]), ...);
}

} // namespace detail

template <PassId P, Layout L = Layout::PLAIN, class... Parts> Slots<P, L> make_slots(const Parts&... parts) {
    static_assert(detail::binds_each_once<Slots<P, L>::count, Parts...>(),
                  "every binding of the pass (shaders/bindings.h) must be bound exactly once");
    Slots<P, L> s;
    (detail::fill(s, parts), ...);
    return s;
}

} // namespace fgsr
