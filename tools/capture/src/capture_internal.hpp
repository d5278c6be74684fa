// Helpers shared by the capture importers/exporters (private to fgsr_capture); the ones the capture
// format library implements come from fgsr/capture/format_util.hpp.
#pragma once

#include <fgsr/capture/capture.hpp>
#include <fgsr/capture/format_util.hpp>
#include <fgsr/capture/image_io.hpp>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace fgsr::capture::detail {

namespace fs = std::filesystem;

// Files named <digits><ext> (e.g. "0010.png") directly in `dir`, sorted by number.
// Error when `dir` is not a directory.
struct NumberedFile {
    long number = 0;
    std::string stem; // the digits as written ("0010")
    fs::path path;
};
Result<std::vector<NumberedFile>> numbered_files(const fs::path& dir, const std::string& ext);

} // namespace fgsr::capture::detail
