// Captures as the subcommands name them (--capture, --captures, --images): one parser and one
// loader for every subcommand.
//   "builtin"  the generated synthetic scene (fgsr/capture/synthetic.hpp, default options) of 11
//              inputs;
//   "DIR"      a capture directory of any layout capture::load reads;
//   "DIR@lr"   the same, with Mob-FGSR's LR_Inputs (prefer_lr).
#pragma once

#include <fgsr/capture/capture.hpp>
#include <fgsr/core/result.hpp>

#include <cstddef>
#include <string>

namespace fgsr::cli {

struct CaptureSpec {
    std::string dir;      // the directory (or "builtin"), "@lr" removed
    bool builtin = false; // the synthetic scene
    bool lr = false;      // "@lr" was given
};

CaptureSpec parse_capture_spec(const std::string& spec);

// A short name for reports: "builtin", or the directory's last component.
std::string capture_short_name(const std::string& spec);

// Loads the capture `spec` names, at most max_frames inputs (the builtin scene: between 2 and 11
// inputs). prefer_lr: LR_Inputs for Mob-FGSR captures even without "@lr".
Result<capture::Capture> load_capture_spec(const std::string& spec, bool prefer_lr = false,
                                           size_t max_frames = capture::kAllFrames);

} // namespace fgsr::cli
