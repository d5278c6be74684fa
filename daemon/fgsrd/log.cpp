#include "log.hpp"

namespace fgsrd::log {

Level& threshold() {
    static Level level = Level::info;
    return level;
}

bool parse_level(std::string_view s, Level& out) {
    static constexpr std::string_view names[] = {"debug", "info", "warn", "error", "off"};
    for (int i = 0; i < 5; ++i)
        if (s == names[i]) {
            out = Level(i);
            return true;
        }
    return false;
}

void write(Level level, std::string_view message) {
    static constexpr const char* names[] = {"debug", "info", "warning", "error", "off"};
    std::fprintf(stderr, "fgsrd: %s: %.*s\n", names[int(level)], int(message.size()), message.data());
}

} // namespace fgsrd::log
