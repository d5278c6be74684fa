// Levelled logging to stderr: "fgsrd: <level>: message". Thread-safe (one fprintf per line).
#pragma once

#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <string_view>

namespace fgsrd::log {

enum class Level { debug = 0, info = 1, warn = 2, error = 3, off = 4 };

// The minimum level written; set once at start-up.
Level& threshold();
// Parses "debug", "info", "warn", "error" or "off"; false for anything else.
bool parse_level(std::string_view s, Level& out);
// Writes one line: control characters (newline, ESC, ...), DEL and backslash are escaped as \xNN,
// so text from clients cannot forge lines or terminal sequences.
void write(Level level, std::string_view message);
// The same escaping, for text from clients kept elsewhere (a client's name).
std::string printable(std::string_view s);

template <class... A> void debug(fmt::format_string<A...> f, A&&... a) {
    if (threshold() <= Level::debug) write(Level::debug, fmt::format(f, std::forward<A>(a)...));
}
template <class... A> void info(fmt::format_string<A...> f, A&&... a) {
    if (threshold() <= Level::info) write(Level::info, fmt::format(f, std::forward<A>(a)...));
}
template <class... A> void warn(fmt::format_string<A...> f, A&&... a) {
    if (threshold() <= Level::warn) write(Level::warn, fmt::format(f, std::forward<A>(a)...));
}
template <class... A> void error(fmt::format_string<A...> f, A&&... a) {
    if (threshold() <= Level::error) write(Level::error, fmt::format(f, std::forward<A>(a)...));
}

} // namespace fgsrd::log
