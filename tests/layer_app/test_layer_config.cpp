// The layer's configuration without Vulkan: defaults, [global], [[profile]] matching, environment
// overrides, every kind of error, and reloading a changed file.
#include "config.hpp"

#include <fgsr/protocol.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

using fgsr::layer::ConfigEnv;
using fgsr::layer::ConfigWatcher;
using fgsr::layer::LayerConfig;
using fgsr::layer::Mode;
using fgsr::layer::Motion;
using fgsr::layer::Pacing;
using fgsr::layer::parse_config;

namespace {

LayerConfig ok(std::string_view text, std::string_view exe = "game", ConfigEnv env = {}) {
    auto r = parse_config(text, exe, env);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? *r : LayerConfig{};
}

std::string error_of(std::string_view text, ConfigEnv env = {}) {
    auto r = parse_config(text, "game", env);
    EXPECT_FALSE(r.ok()) << "accepted: " << text;
    return r.ok() ? "" : r.error().message;
}

constexpr const char* kProfiles = R"(
[global]
multiplier = 2
mode = "interpolate"
pacing = "none"
socket = "/tmp/x.sock"

[[profile]]
name = "cube"
active_in = ["vkcube", "other"]
multiplier = 3

[[profile]]
active_in = ["vkcube", "game"]
multiplier = 4
mode = "extrapolate"
fps_limit = 30
motion = "fast"
)";

} // namespace

TEST(LayerConfig, EmptyTextGivesTheDefaults) {
    const LayerConfig c = ok("");
    EXPECT_TRUE(c.enabled);
    EXPECT_EQ(c.multiplier, 2u);
    EXPECT_EQ(c.mode, Mode::interpolate);
    EXPECT_EQ(c.pacing, Pacing::even);
    EXPECT_EQ(c.fps_limit, 0.0);
    EXPECT_EQ(c.motion, Motion::full);
    EXPECT_TRUE(c.socket_path.empty());
    EXPECT_TRUE(c.profile.empty());
}

TEST(LayerConfig, GlobalTableApplies) {
    const LayerConfig c =
        ok("[global]\nenabled = false\nmultiplier = 4\nmode = \"extrapolate\"\npacing = \"none\"\n"
           "socket = \"/run/s\"\nfps_limit = 24.5\nmotion = \"fast\"\n");
    EXPECT_FALSE(c.enabled);
    EXPECT_EQ(c.multiplier, 4u);
    EXPECT_EQ(c.mode, Mode::extrapolate);
    EXPECT_EQ(c.pacing, Pacing::none);
    EXPECT_EQ(c.socket_path, "/run/s");
    EXPECT_DOUBLE_EQ(c.fps_limit, 24.5);
    EXPECT_EQ(c.motion, Motion::fast);
}

TEST(LayerConfig, FirstMatchingProfileWinsOverGlobal) {
    const LayerConfig cube = ok(kProfiles, "vkcube");
    EXPECT_EQ(cube.multiplier, 3u);
    EXPECT_EQ(cube.mode, Mode::interpolate); // from [global]
    EXPECT_EQ(cube.pacing, Pacing::none);
    EXPECT_EQ(cube.socket_path, "/tmp/x.sock");
    EXPECT_EQ(cube.profile, "cube");
    const LayerConfig game = ok(kProfiles, "game");
    EXPECT_EQ(game.multiplier, 4u);
    EXPECT_EQ(game.mode, Mode::extrapolate);
    EXPECT_DOUBLE_EQ(game.fps_limit, 30.0);
    EXPECT_EQ(game.motion, Motion::fast);
    EXPECT_EQ(cube.motion, Motion::full);
    EXPECT_EQ(game.profile, "game"); // unnamed: the executable's name
    const LayerConfig none = ok(kProfiles, "unlisted");
    EXPECT_EQ(none.multiplier, 2u);
    EXPECT_TRUE(none.profile.empty());
}

TEST(LayerConfig, ActiveInMayBeOneString) {
    EXPECT_EQ(ok("[[profile]]\nactive_in = \"game\"\nmultiplier = 3\n").multiplier, 3u);
}

TEST(LayerConfig, EnvironmentOverridesFileAndProfile) {
    ConfigEnv env;
    env.multiplier = "2";
    env.mode = "interpolate";
    env.fps_limit = "15";
    env.motion = "full";
    const LayerConfig c = ok(kProfiles, "game", env);
    EXPECT_EQ(c.multiplier, 2u);
    EXPECT_EQ(c.motion, Motion::full); // the profile's "fast" overridden
    EXPECT_EQ(c.mode, Mode::interpolate);
    EXPECT_DOUBLE_EQ(c.fps_limit, 15.0);
    ConfigEnv only_mode;
    only_mode.mode = "extrapolate";
    EXPECT_EQ(ok("", "game", only_mode).mode, Mode::extrapolate);
    ConfigEnv only_motion;
    only_motion.motion = "fast";
    EXPECT_EQ(ok("", "game", only_motion).motion, Motion::fast);
}

// motion = "fast" reaches fgsrd as FGSR_SESSION_FAST_MOTION only when the daemon knows the flag
// (minor 5): an older daemon would refuse the whole session for an unknown flag.
TEST(LayerConfig, FastMotionIsAskedOnlyOfDaemonsThatKnowIt) {
    EXPECT_GE(uint32_t(FGSR_PROTOCOL_MINOR), fgsr::layer::kFastMotionMinor);
    EXPECT_TRUE(fgsr::layer::asks_fast_motion(Motion::fast, FGSR_PROTOCOL_MINOR));
    EXPECT_TRUE(fgsr::layer::asks_fast_motion(Motion::fast, 5));
    EXPECT_FALSE(fgsr::layer::asks_fast_motion(Motion::fast, 4));
    EXPECT_FALSE(fgsr::layer::asks_fast_motion(Motion::fast, 0));
    EXPECT_FALSE(fgsr::layer::asks_fast_motion(Motion::full, FGSR_PROTOCOL_MINOR));
}

TEST(LayerConfig, ErrorsNameTheKeyAndTheAllowedValues) {
    EXPECT_NE(error_of("[global\nmultiplier = 2").find("line 1"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmultipler = 2").find("global.multipler: unknown key"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmultiplier = 5").find("2, 3 or 4"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmultiplier = 1").find("out of range"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmultiplier = \"2\"").find("expected an integer"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmode = \"fast\"").find("interpolate or extrapolate"), std::string::npos);
    EXPECT_NE(error_of("[global]\npacing = \"smooth\"").find("even or none"), std::string::npos);
    EXPECT_NE(error_of("[global]\nenabled = 1").find("true or false"), std::string::npos);
    EXPECT_NE(error_of("[global]\nfps_limit = -1").find("0..1000"), std::string::npos);
    EXPECT_NE(error_of("[global]\nsocket = 3").find("expected a string"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmotion = \"quick\"").find("full or fast"), std::string::npos);
    EXPECT_NE(error_of("[global]\nmotion = true").find("global.motion: expected a string"),
              std::string::npos);
    // The unknown-key message lists every key a table may hold.
    const std::string unknown = error_of("[global]\nspeed = 1");
    for (const char* key : {"enabled", "multiplier", "mode", "pacing", "fps_limit", "motion", "socket"})
        EXPECT_NE(unknown.find(key), std::string::npos) << key << " in " << unknown;
    EXPECT_NE(error_of("global = 3").find("expected a table"), std::string::npos);
    EXPECT_NE(error_of("[other]\nx = 1").find("unknown top-level key"), std::string::npos);
    EXPECT_NE(error_of("[[profile]]\nmultiplier = 3").find("active_in missing"), std::string::npos);
    EXPECT_NE(error_of("[[profile]]\nactive_in = [1]").find("expected strings"), std::string::npos);
    // A bad profile is an error even when another one matched first.
    EXPECT_NE(error_of("[[profile]]\nactive_in = [\"game\"]\n[[profile]]\nactive_in = [\"x\"]\nmode = \"y\"")
                  .find("profile[1]"),
              std::string::npos);
    ConfigEnv bad;
    bad.multiplier = "two";
    EXPECT_NE(error_of("", bad).find("FGSR_MULTIPLIER"), std::string::npos);
    bad.multiplier = "8";
    EXPECT_NE(error_of("", bad).find("out of range"), std::string::npos);
    ConfigEnv bad_mode;
    bad_mode.mode = "both";
    EXPECT_NE(error_of("", bad_mode).find("FGSR_MODE"), std::string::npos);
    ConfigEnv bad_fps;
    bad_fps.fps_limit = "fast";
    EXPECT_NE(error_of("", bad_fps).find("FGSR_FPS_LIMIT"), std::string::npos);
    ConfigEnv bad_motion;
    bad_motion.motion = "slow";
    EXPECT_NE(error_of("", bad_motion).find("FGSR_MOTION"), std::string::npos);
}

// toml++ 3.3 reaches undefined behaviour on U+00A1..U+0499, U+2C5E..U+3057 and U+FB26..U+FEFE
// (other than U+3000), even inside strings: found by tests/fuzz/fuzz_layer_config ("x = 1\u00e9",
// and a string continued after a line-ending backslash). Such text is an error naming the
// character and its position, before toml++ sees it; other non-ASCII text is kept.
TEST(LayerConfig, CharactersTomlppCannotClassifyAreAnErrorWithTheirPosition) {
    EXPECT_NE(error_of("[global]\nmultiplier = 2\xc3\xa9").find("line 2, column 15: character U+00E9"),
              std::string::npos);
    EXPECT_NE(error_of("x = 1\xef\xbb\xb9").find("line 1, column 6: character U+FEF9"), std::string::npos);
    EXPECT_NE(error_of("[global]\nsocket = \"\"\"a \\\n\xc3\xa9\"\"\"").find("line 3, column 1"),
              std::string::npos);
    EXPECT_NE(error_of("# caf\xc3\xa9").find("U+00E9"), std::string::npos);
    EXPECT_NE(error_of("# \xe3\x81\x81").find("U+3041"), std::string::npos);
    // Neighbours that toml++ classifies: U+00A0, U+3000 (whitespace), U+4E2D, U+FEFF.
    const LayerConfig c =
        ok("# \xc2\xa0 \xe3\x80\x80 \xef\xbb\xbf\n[global]\nsocket = \"/tmp/\xe4\xb8\xad.sock\"\n");
    EXPECT_EQ(c.socket_path, "/tmp/\xe4\xb8\xad.sock");
}

TEST(LayerConfig, WatcherReloadsAChangedFileAtMostEveryInterval) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("fgsr-layer-config-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "fgsr.toml").string();
    ConfigWatcher missing(path, "game", {});
    ASSERT_TRUE(missing.current().ok()); // no file: the defaults
    EXPECT_EQ(missing.current()->multiplier, 2u);
    { std::ofstream(path) << "[global]\nmultiplier = 3\n"; }
    ConfigWatcher w(path, "game", {}, 50'000'000);
    ASSERT_TRUE(w.current().ok());
    EXPECT_EQ(w.current()->multiplier, 3u);
    EXPECT_FALSE(w.poll(1'000'000'000)); // unchanged
    { std::ofstream(path) << "[global]\nmultiplier = 4\nmode = \"extrapolate\"\n"; }
    EXPECT_FALSE(w.poll(1'010'000'000)); // within the interval: not even looked at
    EXPECT_TRUE(w.poll(1'100'000'000));
    ASSERT_TRUE(w.current().ok());
    EXPECT_EQ(w.current()->multiplier, 4u);
    EXPECT_EQ(w.current()->mode, Mode::extrapolate);
    { std::ofstream(path) << "[global]\nmultiplier = 9\n"; }
    EXPECT_TRUE(w.poll(1'200'000'000));
    ASSERT_FALSE(w.current().ok()); // a bad edit: the error, which names the file
    EXPECT_NE(w.current().error().message.find(path), std::string::npos);
    std::filesystem::remove(path);
    EXPECT_TRUE(w.poll(1'300'000'000)); // removed: back to the defaults
    ASSERT_TRUE(w.current().ok());
    EXPECT_EQ(w.current()->multiplier, 2u);
    std::filesystem::remove_all(dir);
}
