// The layer's TOML configuration: parsing, profile matching, env overrides, reloading (config.hpp).
#include "config.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

// toml++ header-only (Debian's libtomlplusplus-dev); it throws toml::parse_error, caught below.
#define TOML_HEADER_ONLY 1
#include <toml++/toml.h>

namespace fgsr::layer {
namespace {

// The first code point of `text` that toml++ 3.3 (Debian 12) cannot classify: its
// is_non_ascii_horizontal_whitespace reaches __builtin_unreachable (undefined behaviour) for
// U+00A1..U+0499, U+2C5E..U+3057 and U+FB26..U+FEFE other than U+3000, and the parser asks it
// about characters inside strings too (after a line-ending backslash, or when it looks ahead past
// a malformed value). Found by tests/fuzz/fuzz_layer_config. Returns its byte offset and value.
struct CodePoint {
    size_t offset;
    char32_t value;
};
std::optional<CodePoint> unclassifiable_code_point(std::string_view text) {
    for (size_t i = 0; i < text.size();) {
        const auto b = static_cast<unsigned char>(text[i]);
        const size_t len = b < 0x80           ? 1
                           : (b >> 5) == 0x6  ? 2
                           : (b >> 4) == 0xE  ? 3
                           : (b >> 3) == 0x1E ? 4
                                              : 1;
        if (len == 1 || i + len > text.size()) { // ASCII, or not UTF-8 (toml++ refuses that itself)
            ++i;
            continue;
        }
        char32_t c = b & (0xFF >> (len + 1));
        for (size_t k = 1; k < len; ++k) c = (c << 6) | (static_cast<unsigned char>(text[i + k]) & 0x3F);
        const bool bad = (c >= 0xA1 && c <= 0x499) || (c >= 0x2C5E && c <= 0x3057 && c != 0x3000) ||
                         (c >= 0xFB26 && c <= 0xFEFE);
        if (bad) return CodePoint{i, c};
        i += len;
    }
    return std::nullopt;
}

std::optional<std::string> env_value(const char* name) {
    const char* v = std::getenv(name);
    if (!v) return std::nullopt;
    return std::string(v);
}

Result<uint32_t> parse_multiplier(int64_t v, const std::string& where) {
    if (v < 2 || v > 4)
        return make_error(Errc::invalid_argument,
                          where + ": multiplier " + std::to_string(v) + " out of range (2, 3 or 4)");
    return uint32_t(v);
}

Result<Mode> parse_mode(std::string_view v, const std::string& where) {
    if (v == "interpolate") return Mode::interpolate;
    if (v == "extrapolate") return Mode::extrapolate;
    return make_error(Errc::invalid_argument,
                      where + ": mode \"" + std::string(v) + "\" unknown (interpolate or extrapolate)");
}

Result<Pacing> parse_pacing(std::string_view v, const std::string& where) {
    if (v == "even") return Pacing::even;
    if (v == "none") return Pacing::none;
    return make_error(Errc::invalid_argument,
                      where + ": pacing \"" + std::string(v) + "\" unknown (even or none)");
}

Result<Motion> parse_motion(std::string_view v, const std::string& where) {
    if (v == "full") return Motion::full;
    if (v == "fast") return Motion::fast;
    return make_error(Errc::invalid_argument,
                      where + ": motion \"" + std::string(v) + "\" unknown (full or fast)");
}

// Applies the keys of one table ([global] or a [[profile]]) onto cfg. active_in/name are allowed
// only in profiles (and read by the caller).
Result<void> apply_table(const toml::table& t, LayerConfig& cfg, const std::string& where, bool profile) {
    for (const auto& [key_node, value] : t) {
        const std::string key(key_node.str());
        const std::string at = where + "." + key;
        if (key == "enabled") {
            const auto v = value.value<bool>();
            if (!value.is_boolean() || !v)
                return make_error(Errc::invalid_argument, at + ": expected true or false");
            cfg.enabled = *v;
        } else if (key == "multiplier") {
            if (!value.is_integer())
                return make_error(Errc::invalid_argument, at + ": expected an integer (2, 3 or 4)");
            auto m = parse_multiplier(*value.value<int64_t>(), where);
            if (!m) return m.error();
            cfg.multiplier = *m;
        } else if (key == "mode") {
            if (!value.is_string()) return make_error(Errc::invalid_argument, at + ": expected a string");
            auto m = parse_mode(*value.value<std::string_view>(), where);
            if (!m) return m.error();
            cfg.mode = *m;
        } else if (key == "pacing") {
            if (!value.is_string()) return make_error(Errc::invalid_argument, at + ": expected a string");
            auto p = parse_pacing(*value.value<std::string_view>(), where);
            if (!p) return p.error();
            cfg.pacing = *p;
        } else if (key == "fps_limit") {
            const auto v = value.value<double>();
            if (!(value.is_integer() || value.is_floating_point()) || !v || !(*v >= 0 && *v <= 1000))
                return make_error(Errc::invalid_argument,
                                  at + ": expected a number of frames per second, 0..1000");
            cfg.fps_limit = *v;
        } else if (key == "motion") {
            if (!value.is_string()) return make_error(Errc::invalid_argument, at + ": expected a string");
            auto m = parse_motion(*value.value<std::string_view>(), where);
            if (!m) return m.error();
            cfg.motion = *m;
        } else if (key == "socket") {
            if (!value.is_string()) return make_error(Errc::invalid_argument, at + ": expected a string");
            cfg.socket_path = std::string(*value.value<std::string_view>());
        } else if (profile && (key == "active_in" || key == "name")) {
            continue;
        } else {
            return make_error(
                Errc::invalid_argument,
                at + ": unknown key (enabled, multiplier, mode, pacing, fps_limit, motion, socket" +
                    std::string(profile ? ", active_in, name)" : ")"));
        }
    }
    return {};
}

// True when the profile's active_in lists exe_name; an error when active_in is missing or malformed.
Result<bool> profile_matches(const toml::table& p, std::string_view exe_name, const std::string& where) {
    const toml::node* a = p.get("active_in");
    if (!a)
        return make_error(Errc::invalid_argument, where + ": active_in missing (a list of executable names)");
    const toml::array* arr = a->as_array();
    if (!arr) {
        if (const auto s = a->value<std::string_view>()) return *s == exe_name; // one name as a string
        return make_error(Errc::invalid_argument, where + ".active_in: expected a list of strings");
    }
    bool match = false;
    for (const toml::node& e : *arr) {
        const auto s = e.value<std::string_view>();
        if (!e.is_string() || !s)
            return make_error(Errc::invalid_argument, where + ".active_in: expected strings");
        match |= *s == exe_name;
    }
    return match;
}

} // namespace

ConfigEnv config_env_from_process() {
    return ConfigEnv{env_value("FGSR_MULTIPLIER"), env_value("FGSR_MODE"), env_value("FGSR_FPS_LIMIT"),
                     env_value("FGSR_MOTION")};
}

const char* mode_name(Mode m) {
    return m == Mode::interpolate ? "interpolate" : "extrapolate";
}

const char* motion_name(Motion m) {
    return m == Motion::full ? "full" : "fast";
}

Result<LayerConfig> parse_config(std::string_view toml_text, std::string_view exe_name,
                                 const ConfigEnv& env) {
    LayerConfig cfg;
    if (const auto bad = unclassifiable_code_point(toml_text)) {
        const std::string_view before = toml_text.substr(0, bad->offset);
        const size_t line = size_t(std::count(before.begin(), before.end(), '\n')) + 1;
        const size_t newline = before.rfind('\n');
        const size_t column = bad->offset - (newline == std::string_view::npos ? 0 : newline + 1) + 1;
        char code[16];
        std::snprintf(code, sizeof(code), "U+%04X", unsigned(bad->value));
        return make_error(Errc::io, "TOML text at line " + std::to_string(line) + ", column " +
                                        std::to_string(column) + ": character " + code +
                                        " is not supported (U+00A1..U+0499, U+2C5E..U+3057, U+FB26..U+FEFE)");
    }
    toml::table root;
    try {
        root = toml::parse(toml_text);
    } catch (const toml::parse_error& e) {
        std::ostringstream s;
        s << "TOML syntax error at line " << e.source().begin.line << ", column " << e.source().begin.column
          << ": " << e.description();
        return make_error(Errc::io, s.str());
    }
    for (const auto& [key_node, value] : root) {
        const std::string key(key_node.str());
        if (key == "global") {
            if (!value.is_table())
                return make_error(Errc::invalid_argument, "global: expected a table ([global])");
        } else if (key == "profile") {
            if (!value.is_array_of_tables())
                return make_error(Errc::invalid_argument, "profile: expected tables ([[profile]])");
        } else {
            return make_error(Errc::invalid_argument, key + ": unknown top-level key (global, profile)");
        }
    }
    if (const toml::table* g = root["global"].as_table()) {
        auto r = apply_table(*g, cfg, "global", false);
        if (!r) return r.error();
    }
    if (const toml::array* profiles = root["profile"].as_array()) {
        bool applied = false;
        for (size_t i = 0; i < profiles->size(); ++i) {
            const toml::table* p = (*profiles)[i].as_table();
            const std::string where = "profile[" + std::to_string(i) + "]";
            auto match = profile_matches(*p, exe_name, where);
            if (!match) return match.error();
            // Every profile is checked, the first match applied.
            LayerConfig scratch = cfg;
            auto r = apply_table(*p, scratch, where, true);
            if (!r) return r.error();
            if (*match && !applied) {
                applied = true;
                cfg = scratch;
                const auto name = p->get("name") ? p->get("name")->value<std::string>() : std::nullopt;
                cfg.profile = name ? *name : std::string(exe_name);
            }
        }
    }
    if (env.multiplier) {
        char* end = nullptr;
        errno = 0;
        const long v = std::strtol(env.multiplier->c_str(), &end, 10);
        if (env.multiplier->empty() || *end != 0 || errno != 0)
            return make_error(Errc::invalid_argument,
                              "FGSR_MULTIPLIER=\"" + *env.multiplier + "\": expected 2, 3 or 4");
        auto m = parse_multiplier(v, "FGSR_MULTIPLIER");
        if (!m) return m.error();
        cfg.multiplier = *m;
    }
    if (env.fps_limit) {
        char* end = nullptr;
        const double v = std::strtod(env.fps_limit->c_str(), &end);
        if (env.fps_limit->empty() || *end != 0 || !(v >= 0 && v <= 1000))
            return make_error(Errc::invalid_argument,
                              "FGSR_FPS_LIMIT=\"" + *env.fps_limit + "\": expected 0..1000");
        cfg.fps_limit = v;
    }
    if (env.mode) {
        auto m = parse_mode(*env.mode, "FGSR_MODE");
        if (!m) return m.error();
        cfg.mode = *m;
    }
    if (env.motion) {
        auto m = parse_motion(*env.motion, "FGSR_MOTION");
        if (!m) return m.error();
        cfg.motion = *m;
    }
    return cfg;
}

std::string config_path_from_process() {
    if (const char* p = std::getenv("FGSR_CONFIG"); p && *p) return p;
    if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return std::string(x) + "/fgsr/fgsr.toml";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.config/fgsr/fgsr.toml";
    return {};
}

std::string executable_name() {
    char buf[PATH_MAX];
    const ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
    if (n > 0) {
        const std::string path(buf, size_t(n));
        return path.substr(path.find_last_of('/') + 1);
    }
    return program_invocation_short_name ? program_invocation_short_name : "";
}

ConfigWatcher::ConfigWatcher(std::string path, std::string exe_name, ConfigEnv env, uint64_t min_interval_ns)
    : path_(std::move(path)), exe_name_(std::move(exe_name)), env_(std::move(env)),
      min_interval_ns_(min_interval_ns), current_(LayerConfig{}) {
    load();
}

void ConfigWatcher::load() {
    struct stat st {};
    exists_ = !path_.empty() && stat(path_.c_str(), &st) == 0;
    mtime_ = exists_ ? st.st_mtim : timespec{};
    size_ = exists_ ? int64_t(st.st_size) : -1;
    std::string text;
    if (exists_) {
        std::ifstream f(path_, std::ios::binary);
        if (!f) {
            current_ = make_error(Errc::io, path_ + ": cannot read");
            return;
        }
        std::stringstream s;
        s << f.rdbuf();
        text = s.str();
    }
    auto r = parse_config(text, exe_name_, env_);
    if (!r) {
        current_ = make_error(r.error().code, path_ + ": " + r.error().message);
        return;
    }
    current_ = std::move(r);
}

bool ConfigWatcher::poll(uint64_t now_ns) {
    if (now_ns - last_check_ns_ < min_interval_ns_ && last_check_ns_ != 0) return false;
    last_check_ns_ = now_ns;
    struct stat st {};
    const bool exists = !path_.empty() && stat(path_.c_str(), &st) == 0;
    const bool changed = exists != exists_ ||
                         (exists && (st.st_mtim.tv_sec != mtime_.tv_sec ||
                                     st.st_mtim.tv_nsec != mtime_.tv_nsec || int64_t(st.st_size) != size_));
    if (!changed) return false;
    load();
    return true;
}

} // namespace fgsr::layer
