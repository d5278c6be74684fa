// The layer test application's scene: textured layers moving on known paths, rendered on the CPU
// at any instant, so that a generated frame has an exact ground truth (the frame at its instant)
// and a naive baseline (the 50/50 blend of its neighbours). Colours are display-encoded (sRGB)
// values in [0, 1]; frame k is the scene at t = k * dt seconds.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace fgsr::layer_app {

class Scene {
  public:
    Scene() : tex_(kTex * kTex * 3, 0.0f) {
        // A periodic (seamless) value-noise texture per channel: two octaves of random grids,
        // smoothly interpolated. No repeating pattern, so that motion is unambiguous.
        uint32_t state = 12345u;
        auto random = [&] {
            state = state * 1664525u + 1013904223u;
            return float(state >> 8) / float(1u << 24);
        };
        for (int c = 0; c < 3; ++c)
            for (int octave = 0; octave < 2; ++octave) {
                const int cells = octave == 0 ? 16 : 64;
                const float amplitude = octave == 0 ? 0.7f : 0.3f;
                std::vector<float> grid(size_t(cells * cells));
                for (float& g : grid) g = random();
                auto at = [&](int gx, int gy) { return grid[size_t((gy % cells) * cells + gx % cells)]; };
                for (int y = 0; y < kTex; ++y)
                    for (int x = 0; x < kTex; ++x) {
                        const float gx = float(x * cells) / kTex, gy = float(y * cells) / kTex;
                        const int x0 = int(gx), y0 = int(gy);
                        const float ax = gx - float(x0), ay = gy - float(y0);
                        const float sx = ax * ax * (3 - 2 * ax), sy = ay * ay * (3 - 2 * ay); // smoothstep
                        const float v = (at(x0, y0) * (1 - sx) + at(x0 + 1, y0) * sx) * (1 - sy) +
                                        (at(x0, y0 + 1) * (1 - sx) + at(x0 + 1, y0 + 1) * sx) * sy;
                        tex_[size_t(y * kTex + x) * 3 + size_t(c)] += amplitude * v;
                    }
            }
    }

    // RGB display values of pixel centre (x, y) of a w x h frame at time t (seconds).
    void shade(float t, uint32_t w, uint32_t h, uint32_t x, uint32_t y, float rgb[3]) const {
        const float s = float(h) / 720.0f; // textures scale with the frame: same image at any size
        const float px = float(x) + 0.5f, py = float(y) + 0.5f;
        // Background: scrolls right and slightly down.
        sample(px / s - 40.0f * t, py / s - 10.0f * t, 1.0f, rgb);
        // Rectangle: linear path.
        const float rx = (0.15f + 0.18f * t) * float(w), ry = 0.30f * float(h);
        const float rw = 0.22f * float(w), rh = 0.30f * float(h);
        if (px >= rx && px < rx + rw && py >= ry && py < ry + rh) {
            sample((px - rx) / s, (py - ry) / s + 97.0f, 0.6f, rgb);
            rgb[0] = 0.3f + 0.7f * rgb[0];
        }
        // Disc: circular path (its texture travels with it).
        const float a = 1.3f * t;
        const float cx = (0.62f + 0.14f * std::cos(a)) * float(w),
                    cy = (0.50f + 0.22f * std::sin(a)) * float(h);
        const float r = 0.14f * float(h);
        const float dx = px - cx, dy = py - cy;
        if (dx * dx + dy * dy < r * r) {
            sample(dx / s + 31.0f, dy / s + 55.0f, 1.3f, rgb);
            rgb[2] = 0.2f + 0.8f * rgb[2];
        }
    }

    // The frame at time t as RGBA8 display-encoded bytes, rows w * 4 bytes.
    void render_rgba8(float t, uint32_t w, uint32_t h, uint8_t* out) const {
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                float c[3];
                shade(t, w, h, x, y, c);
                uint8_t* p = out + (size_t(y) * w + x) * 4;
                for (int i = 0; i < 3; ++i)
                    p[i] = uint8_t(std::lround(std::clamp(c[i], 0.0f, 1.0f) * 255.0f));
                p[3] = 255;
            }
    }

  private:
    static constexpr int kTex = 256;

    // Bilinear, wrapping lookup at texel (u, v) scaled by `zoom` texels per pixel.
    void sample(float u, float v, float zoom, float rgb[3]) const {
        u *= zoom;
        v *= zoom;
        const float fu = std::floor(u), fv = std::floor(v);
        const float au = u - fu, av = v - fv;
        const int x0 = int(fu) & (kTex - 1), y0 = int(fv) & (kTex - 1);
        const int x1 = (x0 + 1) & (kTex - 1), y1 = (y0 + 1) & (kTex - 1);
        for (int i = 0; i < 3; ++i) {
            const float a = tex_[size_t(y0 * kTex + x0) * 3 + i], b = tex_[size_t(y0 * kTex + x1) * 3 + i];
            const float c = tex_[size_t(y1 * kTex + x0) * 3 + i], d = tex_[size_t(y1 * kTex + x1) * 3 + i];
            rgb[i] = (a * (1 - au) + b * au) * (1 - av) + (c * (1 - au) + d * au) * av;
        }
    }

    std::vector<float> tex_;
};

} // namespace fgsr::layer_app
