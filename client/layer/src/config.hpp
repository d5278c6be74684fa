// The layer's configuration (VK_LAYER_FGSR_frame_generation): a TOML file with a [global] table and
// [[profile]] tables matched by executable name, then the environment overrides. No Vulkan here, so
// that tests link it alone (library fgsr_layer_config).
//
//   [global]                       # every key optional
//   enabled = true
//   multiplier = 2                 # presents per application present: 2, 3 or 4
//   mode = "interpolate"           # "interpolate" (about one frame of latency) | "extrapolate" (none)
//   pacing = "even"                # "even": generated frames at even intervals | "none": back to back
//   socket = "/run/user/1000/fgsr/fgsrd.sock"   # empty: libfgsr_client's default
//   fps_limit = 30                 # cap on the application's own frame rate (0: none), so that
//                                  # the daemon keeps up; presents then reach fps_limit * multiplier
//   motion = "full"                # motion estimated from colour: "full" | "fast" (no refinement
//                                  # of the estimate, up to 960x540: a frame in about 0.7x the
//                                  # time on a CPU device, 0.3-0.4 dB lower on average, up to
//                                  # 1.2 dB; FGSR_SESSION_FAST_MOTION)
//
//   [[profile]]
//   active_in = ["vkcube", "game.x86_64"]       # executable names (basename); first match wins
//   multiplier = 3
//
// Unknown keys, wrong types and out-of-range values are errors (one message naming the key); the
// layer then passes frames through. Env overrides: FGSR_MULTIPLIER, FGSR_MODE, FGSR_FPS_LIMIT,
// FGSR_MOTION.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <ctime>
#include <optional>
#include <string>
#include <string_view>

namespace fgsr::layer {

enum class Mode { interpolate, extrapolate };
enum class Pacing { even, none };
enum class Motion { full, fast };

struct LayerConfig {
    bool enabled = true;
    uint32_t multiplier = 2; // 2..4
    Mode mode = Mode::interpolate;
    Pacing pacing = Pacing::even;
    double fps_limit = 0;    // application presents per second at most (0: no cap), 0..1000
    Motion motion = Motion::full;
    std::string socket_path; // empty: libfgsr_client's default ($FGSR_SOCKET, $XDG_RUNTIME_DIR/...)
    std::string profile;     // name (or first active_in entry) of the profile applied; empty: none
};

// The environment variables the configuration reads, captured once (tests pass their own).
struct ConfigEnv {
    std::optional<std::string> multiplier; // FGSR_MULTIPLIER
    std::optional<std::string> mode;       // FGSR_MODE
    std::optional<std::string> fps_limit;  // FGSR_FPS_LIMIT
    std::optional<std::string> motion;     // FGSR_MOTION
};
ConfigEnv config_env_from_process();

// The configuration for `exe_name` from TOML text (empty text: defaults), then the env overrides.
// Errors: Errc::io (TOML syntax, with line and column), Errc::invalid_argument (unknown key, wrong
// type, value out of range; the message names the key and the allowed values).
Result<LayerConfig> parse_config(std::string_view toml_text, std::string_view exe_name, const ConfigEnv& env);

// Where the file lives: $FGSR_CONFIG, else $XDG_CONFIG_HOME/fgsr/fgsr.toml, else
// $HOME/.config/fgsr/fgsr.toml; empty when none of those variables is set.
std::string config_path_from_process();

// The basename of this process's executable (/proc/self/exe, else program_invocation_short_name).
std::string executable_name();

const char* mode_name(Mode m);
const char* motion_name(Motion m);

// Whether the layer's session asks fgsrd for fast motion estimation (FGSR_SESSION_FAST_MOTION,
// protocol minor 5): when the configuration says so and the daemon knows the flag. A daemon of an
// older minor would refuse the session, so the layer then gets the full estimation (and logs it).
inline constexpr uint32_t kFastMotionMinor = 5;
inline bool asks_fast_motion(Motion m, uint32_t daemon_minor) {
    return m == Motion::fast && daemon_minor >= kFastMotionMinor;
}

// Loads the file at `path` (a missing file gives the defaults, plus env) and watches it: poll()
// re-reads it when its mtime or size changed, at most every `min_interval_ns`. Not thread-safe.
class ConfigWatcher {
  public:
    ConfigWatcher(std::string path, std::string exe_name, ConfigEnv env,
                  uint64_t min_interval_ns = 500'000'000);

    // The current configuration, or the error of the last load.
    const Result<LayerConfig>& current() const { return current_; }
    // Checks the file (when min_interval_ns has passed since the last check, at monotonic time
    // now_ns); true when it changed and current() was reloaded.
    bool poll(uint64_t now_ns);
    const std::string& path() const { return path_; }

  private:
    void load();

    std::string path_, exe_name_;
    ConfigEnv env_;
    uint64_t min_interval_ns_;
    uint64_t last_check_ns_ = 0;
    bool exists_ = false;
    timespec mtime_{};
    int64_t size_ = -1;
    Result<LayerConfig> current_;
};

} // namespace fgsr::layer
