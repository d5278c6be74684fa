// Small helpers shared by the fgsr subcommands.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace fgsr::cli {

// "a,b,,c" -> {"a", "b", "c"}
inline std::vector<std::string> split_list(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) out.push_back(item);
    return out;
}

} // namespace fgsr::cli
