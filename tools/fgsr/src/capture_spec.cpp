// The parser and loader of capture specs (fgsr/cli/capture_spec.hpp).
#include <fgsr/cli/capture_spec.hpp>

#include <fgsr/capture/synthetic.hpp>

#include <algorithm>
#include <filesystem>

namespace fgsr::cli {

CaptureSpec parse_capture_spec(const std::string& spec) {
    CaptureSpec s{spec, false, false};
    const std::string suffix = "@lr";
    if (spec.size() > suffix.size() &&
        spec.compare(spec.size() - suffix.size(), suffix.size(), suffix) == 0) {
        s.dir = spec.substr(0, spec.size() - suffix.size());
        s.lr = true;
    }
    s.builtin = s.dir == "builtin";
    return s;
}

std::string capture_short_name(const std::string& spec) {
    if (spec == "builtin") return spec;
    std::filesystem::path p(spec);
    if (p.filename().empty()) p = p.parent_path();
    return p.filename().string();
}

Result<capture::Capture> load_capture_spec(const std::string& spec, bool prefer_lr, size_t max_frames) {
    const CaptureSpec s = parse_capture_spec(spec);
    // The scene's frame k does not depend on the number of inputs: fewer inputs are the first ones.
    if (s.builtin)
        return capture::make_synthetic_capture(capture::SceneOptions{},
                                               uint32_t(std::clamp<size_t>(max_frames, 2, 11)));
    return capture::load(s.dir, s.lr || prefer_lr, max_frames);
}

} // namespace fgsr::cli
