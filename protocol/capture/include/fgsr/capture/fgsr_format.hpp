// The pieces of fgsr's capture format (docs/CAPTURE_FORMAT.md) that writers share: save_fgsr (whole
// captures in memory) and libfgsr_client's recorder (frames one at a time, as a session submits
// them) both write through these functions, so there is one implementation of the format.
// Library fgsr_capture_format: OpenEXR and nlohmann-json only (no engine, no Vulkan).
#pragma once

#include <fgsr/capture/capture_types.hpp>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::capture {

// fgsr's own format (manifest.json + one EXR per frame); see docs/CAPTURE_FORMAT.md.
// save_fgsr creates `dir` (and parents) and overwrites files of a previous capture there;
// load_fgsr(save_fgsr(c)) reproduces c's planes bit-exactly.
Result<Capture> load_fgsr(const std::filesystem::path& dir, size_t max_frames = kAllFrames);
Result<void> save_fgsr(const Capture& c, const std::filesystem::path& dir);

// "0000.exr", "0001.exr", ...: the name of the i-th file of a list (frames/, gt/, hr/, hr_gt/).
std::string fgsr_file_name(size_t index);

// Writes one input frame file (colour, depth and, when frame.mv is not empty, vectors) for frames
// of `format`. Planes are tightly packed rows; sizes are checked (Errc::size_mismatch). The
// parent directory must exist.
Result<void> write_fgsr_frame(const std::filesystem::path& file, const FrameFormat& format,
                              const FrameView& frame);

// What manifest.json lists. File names are relative to the capture directory.
struct FgsrManifest {
    std::string name, source;
    FrameFormat format;
    GroundTruth ground_truth_kind = GroundTruth::consecutive;
    bool composed_vectors = false;
    struct FrameEntry {
        std::string file;
        bool mv = false;
        float jitter_x = 0.f, jitter_y = 0.f;
        bool reset = false; // scene cut: "reset": true in the manifest (absent: false)
    };
    std::vector<FrameEntry> frames;
    std::vector<std::string> ground_truth;
    struct Hr {
        uint32_t width = 0, height = 0;
        std::vector<std::string> reference, ground_truth;
    };
    std::optional<Hr> hr;
};

// Writes dir/manifest.json through a temporary file and a rename (a directory with a manifest
// holds a complete capture). Errc::unsupported for enum values the format has no name for.
Result<void> write_fgsr_manifest(const std::filesystem::path& dir, const FgsrManifest& manifest);

} // namespace fgsr::capture
