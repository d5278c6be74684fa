// Copies between a client's planes and libfgsr_client's shared-memory slots, shared by the tools
// that feed fgsrd through the client library: `fgsr replay` and the stress daemon feeder
// (fgsr/stress/daemon.hpp). Part of fgsr_stress_daemon.
#pragma once

#include <fgsr/client.h>
#include <fgsr/core/types.hpp>

#include <cstddef>
#include <cstdint>
#include <span>

namespace fgsr::stress {

// An rgba32f output (rows row_pitch apart) as a tightly packed image.
ImageRGBA output_image(const fgsr_output& out);

// Copies `rows` rows of row_bytes each from the tightly packed `src` into `dst`, rows `pitch`
// bytes apart. Nothing when src is empty or rows is 0.
void copy_plane(void* dst, uint32_t pitch, std::span<const std::byte> src, size_t row_bytes, uint32_t rows);

} // namespace fgsr::stress
