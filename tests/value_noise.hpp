// Value noise for analytic test scenes: a continuous, non-periodic function of the plane, so that
// sampling it shifted gives an exact translation at any sub-pixel offset and block matching has
// one right answer (test_motion), and a texture of known detail size at any scale (test_sr).
#pragma once

#include <cmath>
#include <cstdint>

namespace fgsr::test {

// A hash of lattice point (x, y) in [0, 1] (16 bits).
inline float lattice(int x, int y, uint32_t seed) {
    uint32_t h = uint32_t(x) * 374761393u + uint32_t(y) * 668265263u + seed * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return float((h ^ (h >> 16)) & 0xffffu) / 65535.f;
}

// The lattice values of cells `scale` wide, interpolated with the smoothstep.
inline float value_noise(float x, float y, float scale, uint32_t seed) {
    const float fx = x / scale, fy = y / scale;
    const int ix = int(std::floor(fx)), iy = int(std::floor(fy));
    float tx = fx - float(ix), ty = fy - float(iy);
    tx = tx * tx * (3 - 2 * tx);
    ty = ty * ty * (3 - 2 * ty);
    const float a = lattice(ix, iy, seed), b = lattice(ix + 1, iy, seed), c = lattice(ix, iy + 1, seed),
                d = lattice(ix + 1, iy + 1, seed);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

} // namespace fgsr::test
