// Resampling lookup tables (paper 3.5 and 4): FGSR_LUT_LEVELS x FGSR_LUT_LEVELS sub-pixel phases x
// 16 weights of a 4x4 footprint, indexed as shaders/resample.h describes.
//
// File format (.lut, little-endian): magic "FGSRLUT1" (8 bytes), uint32 levels (32), uint32 taps
// (16), float32 scale factor it was trained for, uint32 reserved (0), then levels*levels*taps
// float32 weights. Provenance lives in a JSON file beside it (see daemon/engine/luts/README.md).
#pragma once

#include <fgsr/core/result.hpp>

#include <filesystem>
#include <span>
#include <vector>

namespace fgsr {

inline constexpr uint32_t kLutLevels = 32;
inline constexpr uint32_t kLutTaps = 16;
inline constexpr size_t kLutSize = size_t(kLutLevels) * kLutLevels * kLutTaps;

struct Lut {
    float scale = 2.f;          // upscaling factor the table was trained for
    std::vector<float> weights; // kLutSize values
};

// Sets the weights of phase (0, 0) to the identity (tap (1, 1) = 1). A history that is resampled
// at whole-pixel positions every frame (static content) must not drift; any other weights there
// would compound frame after frame. parse_lut (and so load_lut and the shipped tables) applies it.
void force_identity_phase(Lut& lut);

Result<Lut> load_lut(const std::filesystem::path& path);
Result<void> save_lut(const std::filesystem::path& path, const Lut& lut);
// Parses the bytes of a .lut file (load_lut and the embedded defaults use it).
Result<Lut> parse_lut(std::span<const std::byte> bytes, const std::string& what);

// The LUT the engine uses by default for a scale factor: the shipped table trained for the
// nearest scale (embedded at build time from daemon/engine/luts/*.lut), or, if none is shipped,
// Catmull-Rom weights tabulated at the bins' phases.
Lut default_lut(float scale);
// Catmull-Rom weights tabulated at the bins' phases bin / 32 (the untrained starting point).
Lut catmull_rom_lut(float scale);

} // namespace fgsr
