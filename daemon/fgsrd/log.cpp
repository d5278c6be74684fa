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

std::string printable(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (size_t i = 0; i < s.size(); ++i) {
        const auto c = static_cast<unsigned char>(s[i]);
        // C0 controls, DEL, and the UTF-8 encodings of the C1 controls (U+0080..U+009F:
        // some terminals take U+009B as CSI).
        const bool c1 =
            c == 0xc2 && i + 1 < s.size() && (static_cast<unsigned char>(s[i + 1]) & 0xe0) == 0x80;
        if (c < 0x20 || c == 0x7f)
            out += fmt::format("\\x{:02x}", c);
        else if (c1) {
            out += fmt::format("\\xc2\\x{:02x}", static_cast<unsigned char>(s[i + 1]));
            ++i;
        } else
            out += s[i];
    }
    return out;
}

void write(Level level, std::string_view message) {
    static constexpr const char* names[] = {"debug", "info", "warning", "error", "off"};
    // One line per call, whatever the message holds (client names and reasons come from clients).
    const std::string line = printable(message);
    std::fprintf(stderr, "fgsrd: %s: %s\n", names[int(level)], line.c_str());
}

} // namespace fgsrd::log
