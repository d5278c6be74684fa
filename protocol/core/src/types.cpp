#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

namespace fgsr {

const char* errc_name(Errc c) {
    switch (c) {
    case Errc::invalid_argument:
        return "invalid argument";
    case Errc::size_mismatch:
        return "size mismatch";
    case Errc::unsupported:
        return "unsupported";
    case Errc::empty_input:
        return "empty input";
    case Errc::io:
        return "i/o error";
    case Errc::vulkan:
        return "vulkan error";
    case Errc::no_device:
        return "no device";
    }
    return "unknown error";
}

std::string_view to_string(ColorFormat f) {
    switch (f) {
    case ColorFormat::rgba8_srgb:
        return "rgba8_srgb";
    case ColorFormat::rgba16f_linear:
        return "rgba16f_linear";
    case ColorFormat::rgba32f_linear:
        return "rgba32f_linear";
    }
    return "unknown";
}

std::string_view to_string(DepthKind k) {
    switch (k) {
    case DepthKind::linear:
        return "linear";
    case DepthKind::device:
        return "device";
    case DepthKind::device_reversed:
        return "device_reversed";
    }
    return "unknown";
}

std::string_view to_string(MvFormat f) {
    switch (f) {
    case MvFormat::rg16f:
        return "rg16f";
    case MvFormat::rg32f:
        return "rg32f";
    }
    return "unknown";
}

} // namespace fgsr
