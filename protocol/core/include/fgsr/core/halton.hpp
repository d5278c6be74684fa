// The Halton low-discrepancy sequence: sub-pixel jitter of synthetic and test captures.
#pragma once

#include <cstdint>

namespace fgsr {

// Radical inverse of i in `base` (i >= 1 gives values in (0, 1); i = 0 gives 0), summed in double.
inline float halton(uint32_t i, uint32_t base) {
    double f = 1, r = 0;
    for (; i > 0; i /= base) {
        f /= base;
        r += f * double(i % base);
    }
    return float(r);
}

} // namespace fgsr
