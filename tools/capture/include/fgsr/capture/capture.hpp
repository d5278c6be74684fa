// Captures: sequences of rendered frames plus ground truth, as every fgsr tool reads them.
// Importers return frames in one of the engine's accepted input formats with the conventions the
// source declares (the engine's ingest pass converts); see fgsr/core/types.hpp.
#pragma once

#include <fgsr/capture/capture_types.hpp>
#include <fgsr/capture/fgsr_format.hpp>
#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::capture {

// Loads any supported capture directory, detecting the layout:
//   capture.json with "kind" fg/sr (Blender), HR_Inputs/ or LR_Inputs/ (Mob-FGSR PNG),
//   manifest.json (fgsr's own format). `prefer_lr` picks LR_Inputs for Mob-FGSR captures.
// `max_frames` keeps only the first frames (inputs, with their ground truth / references).
// Errors: Errc::io naming the file or directory that is missing or malformed.
Result<Capture> load(const std::filesystem::path& dir, bool prefer_lr = false,
                     size_t max_frames = kAllFrames);

// Blender capture (capture.json kind "fg" or "sr", see shared/captures/README.md). Colour is
// rgba16f_linear, depth linear, vectors rg32f {pixels, to_previous, mv_y_up = true} exactly as
// Blender stores them; the first frame's vectors are left empty (unknown). "fg" captures get
// GroundTruth::halfway (gt/), "sr" captures GroundTruth::consecutive plus hr_reference (hr/)
// and per-frame jitter (sample offset in low-resolution pixels, x right, y down).
Result<Capture> load_blender(const std::filesystem::path& dir, size_t max_frames = kAllFrames);

// Mob-FGSR PNG capture (HR_Inputs/ or LR_Inputs/ when `lr`). Colour rgba8_srgb, depth linear as
// stored (smaller is nearer), vectors rg32f {uv, from_previous, mv_y_up = true}. With `lr`, the
// HR_Inputs views (the authors' reference) become hr_reference when present.
Result<Capture> load_mobfgsr(const std::filesystem::path& dir, bool lr, size_t max_frames = kAllFrames);

// fgsr's own format (load_fgsr, save_fgsr): fgsr/capture/fgsr_format.hpp.

// Converts a capture of consecutive frames into a half-rate one: inputs are frames 0, 2, 4, ...,
// ground truth (halfway) are frames 1, 3, 5, ... converted to linear RGBA (only those followed by
// an input), and each input's vectors are composed into two-frame vectors (unknown for input 0 and
// wherever frame k's or frame k-1's one-frame vectors are unknown).
// The result has the engine's internal conventions (rgba32f colour, linear depth, rg32f pixel
// vectors to previous, y down), GroundTruth::halfway and composed_vectors = true.
// The rule for the composed vectors (documented in docs/CAPTURE_FORMAT.md, "Half-rate
// evaluation"): for pixel x of input frame k (an even frame of c), y = x + mv_k(x) is its position
// in frame k-1; the two-frame vector is mv_k(x) + mv_{k-1}(y), with mv_{k-1} sampled at y
// bilinearly among the 2x2 neighbours that belong to x's surface (depth test against depth_k(x));
// when no neighbour does, or y is outside the image, 2 * mv_k(x) (constant velocity).
// Requires ground_truth_kind == consecutive (Errc::invalid_argument otherwise) and frames that pass
// params::validate. hr_reference, when present (one per frame), is split the same way into
// hr_reference (even frames) and hr_ground_truth (odd frames).
Result<Capture> make_half_rate(const Capture& c);

// Decodes one input frame's colour to linear RGBA (for scoring and the `repeat` / `blend` methods).
// As the engine's ingest does, non-finite values become 0 and values are clamped to [0, 65504];
// rgba8_srgb alpha is byte/255.
// Precondition: frame.color holds width*height pixels of f.color_format; otherwise the result is
// an empty image (width = height = 0).
ImageRGBA decode_color(const FrameFormat& f, const Frame& frame);

} // namespace fgsr::capture
