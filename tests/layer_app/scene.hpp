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
    Scene() : tex_(kTex * kTex * 3) {
        // Two periodic (seamless) textures of a few sine waves with integer frequencies.
        for (int y = 0; y < kTex; ++y)
            for (int x = 0; x < kTex; ++x) {
                const float u = 2.0f * float(M_PI) * float(x) / kTex,
                            v = 2.0f * float(M_PI) * float(y) / kTex;
                float* p = &tex_[size_t(y * kTex + x) * 3];
                p[0] = 0.5f + 0.25f * std::sin(7 * u + 3 * v) + 0.2f * std::sin(13 * u - 5 * v + 1.0f);
                p[1] = 0.5f + 0.25f * std::sin(4 * u - 9 * v + 2.0f) + 0.2f * std::cos(11 * v + 3 * u);
                p[2] = 0.5f + 0.3f * std::sin(6 * u + 6 * v + 0.5f) * std::cos(3 * u - 8 * v);
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
        // Disc: circular path, rotating texture.
        const float a = 1.3f * t;
        const float cx = (0.62f + 0.14f * std::cos(a)) * float(w),
                    cy = (0.50f + 0.22f * std::sin(a)) * float(h);
        const float r = 0.14f * float(h);
        const float dx = px - cx, dy = py - cy;
        if (dx * dx + dy * dy < r * r) {
            const float c = std::cos(a), sn = std::sin(a);
            sample((c * dx + sn * dy) / s + 31.0f, (-sn * dx + c * dy) / s + 55.0f, 1.7f, rgb);
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
