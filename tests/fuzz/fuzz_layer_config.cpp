// Fuzz target: the Vulkan layer's configuration (parse_config: TOML text, executable name,
// environment overrides). The input is the TOML text; when it ends in a zero byte, the four bytes
// before that pick the executable name and the environment values from small tables (so committed
// TOML seeds are plain text files).
// A configuration that parses is within its documented ranges, and parsing is deterministic.
#include "fuzz_support.hpp"

#include "config.hpp"

#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <optional>
#include <string>

namespace {

constexpr std::array<const char*, 5> kExeNames = {"game", "vkcube", "game.x86_64", "", "other"};
constexpr std::array<const char*, 12> kEnvValues = {"2",     "3",   "4",           "5",           "-1", "",
                                                    "1e309", "nan", "interpolate", "extrapolate", "30", "4x"};

std::optional<std::string> env_pick(uint8_t v) {
    if (v % 2 == 0) return std::nullopt;
    return std::string(kEnvValues[(v / 2) % kEnvValues.size()]);
}

bool same(const fgsr::layer::LayerConfig& a, const fgsr::layer::LayerConfig& b) {
    return a.enabled == b.enabled && a.multiplier == b.multiplier && a.mode == b.mode &&
           a.pacing == b.pacing && a.fps_limit == b.fps_limit && a.socket_path == b.socket_path &&
           a.profile == b.profile && a.motion == b.motion;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    FuzzedDataProvider in(data, size);
    // An input that ends in a zero byte carries four selector bytes before it (exe name, then
    // FGSR_MULTIPLIER, FGSR_MODE and FGSR_FPS_LIMIT); any other input is TOML text alone.
    fgsr::layer::ConfigEnv env;
    const char* exe = kExeNames[0];
    if (size >= 5 && data[size - 1] == 0) {
        in.ConsumeIntegral<uint8_t>(); // the zero byte
        env.fps_limit = env_pick(in.ConsumeIntegral<uint8_t>());
        env.mode = env_pick(in.ConsumeIntegral<uint8_t>());
        env.multiplier = env_pick(in.ConsumeIntegral<uint8_t>());
        exe = kExeNames[in.ConsumeIntegral<uint8_t>() % kExeNames.size()];
    }
    const std::string text = in.ConsumeRemainingBytesAsString();
    const auto cfg = fgsr::layer::parse_config(text, exe, env);
    if (!cfg) {
        FGSR_FUZZ_CHECK(!cfg.error().message.empty());
        return 0;
    }
    FGSR_FUZZ_CHECK(cfg->multiplier >= 2 && cfg->multiplier <= 4);
    FGSR_FUZZ_CHECK(std::isfinite(cfg->fps_limit) && cfg->fps_limit >= 0 && cfg->fps_limit <= 1000);
    FGSR_FUZZ_CHECK(cfg->mode == fgsr::layer::Mode::interpolate ||
                    cfg->mode == fgsr::layer::Mode::extrapolate);
    FGSR_FUZZ_CHECK(cfg->pacing == fgsr::layer::Pacing::even || cfg->pacing == fgsr::layer::Pacing::none);
    FGSR_FUZZ_CHECK(cfg->motion == fgsr::layer::Motion::full || cfg->motion == fgsr::layer::Motion::fast);
    const auto again = fgsr::layer::parse_config(text, exe, env);
    FGSR_FUZZ_CHECK(again && same(*cfg, *again));
    return 0;
}
