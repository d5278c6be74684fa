// The engine's passes, numbered and named by the pass table (fgsr/passes.h): fgsr::PassId has the
// values of the protocol's fgsr_pass_id, pass_name() its names.
#pragma once

#include <fgsr/passes.h>

#include <array>
#include <cstdint>
#include <string_view>

namespace fgsr {

// clang-format off
enum class PassId : uint32_t {
#define FGSR_ENGINE_PASS_ID_(ID, name, value) name = value,
    FGSR_PASSES(FGSR_ENGINE_PASS_ID_)
#undef FGSR_ENGINE_PASS_ID_
    count // not a pass: the number of passes, and "no pass" where one is unknown
};
// clang-format on
inline constexpr uint32_t kPassCount = uint32_t(PassId::count);

inline constexpr std::array<std::string_view, kPassCount> kPassNames = {
#define FGSR_ENGINE_PASS_NAME_(ID, name, value) #name,
    FGSR_PASSES(FGSR_ENGINE_PASS_NAME_)
#undef FGSR_ENGINE_PASS_NAME_
};

// "ingest", ..., "denoise"; "unknown" for PassId::count and out-of-range values (as fgsr_pass_name).
constexpr std::string_view pass_name(PassId p) {
    return uint32_t(p) < kPassCount ? kPassNames[uint32_t(p)] : std::string_view("unknown");
}

} // namespace fgsr
