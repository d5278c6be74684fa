// Analytic synthetic scene with exact colour, depth and motion vectors at any instant.
//
// The scene is a textured background plane (depth 50, a camera pan) behind several rigid textured
// layers (rectangles, discs and thin bars 1.5-2 px wide) at distinct depths. Every layer translates
// without rotation on its own parabolic path
//     p(t) = p0 + speed * (v t + a t^2 / 2)            (pixels; a = 0 when !accelerated)
// and its texture is a function of layer-local coordinates (pixel - p(t)), so the texture moves
// rigidly with the layer and the true motion of any surface point between t and t_prev is exactly
// p(t_prev) - p(t). Paths are designed on a 480x270 canvas and scaled to the requested size (x by
// width/480, y by height/270, sizes and textures by the smaller of the two, thin bars stay thin);
// over t in [0, 10] layers overlap, leave and enter the screen, and the tossed ball accelerates.
//
// Time t is in input-frame units: t = 0, 1, 2, ... are the rendered frames.
// Coordinates: pixels, x right, y down, pixel (i, j) covers [i, i+1) x [j, j+1), centre (i+.5, j+.5).
// Output conventions are the engine's internal ones (see fgsr/core/types.hpp).
#pragma once

#include <fgsr/capture/capture.hpp>
#include <fgsr/core/result.hpp>
#include <fgsr/core/types.hpp>

#include <glm/glm.hpp>

#include <cstdint>
#include <string_view>
#include <vector>

namespace fgsr::capture {

struct SceneOptions {
    uint32_t width = 480, height = 270; // output size in pixels, each in [1, 16384]
    uint32_t seed = 1;        // varies colours, textures and (slightly) paths; same seed = same scene
    bool accelerated = true;  // false: every path has uniform velocity (a = 0)
    float speed = 1.0f;       // scales all motion (velocity and acceleration); finite, >= 0
    uint32_t supersample = 4; // colour samples per axis per pixel (box filter), in [1, 16]
};

// Checks the ranges documented on SceneOptions (invalid_argument naming the field otherwise).
Result<void> validate(const SceneOptions& o);

enum class LayerShape : uint8_t {
    plane, // the background: covers everything
    rect,  // axis-aligned rectangle centred on the layer position (thin bars are rects too)
    disc,  // disc centred on the layer position
};

class SyntheticScene {
  public:
    // Options outside the documented ranges are clamped into them (validate() reports them).
    explicit SyntheticScene(SceneOptions o);

    struct Sample {
        ImageRGBA color;            // linear RGBA, alpha 1, supersample^2 box-filtered over each pixel
        std::vector<float> depth;   // linear view depth of the frontmost layer at each pixel centre
        std::vector<glm::vec2> mv;  // pixels, y down: position at t_prev minus position at t of the
                                    // surface point seen at the pixel centre (internal convention)
        std::vector<uint8_t> layer; // index of the frontmost layer at each pixel centre
    };

    // Colour at time t, depth / layer at t, and vectors from t towards t_prev (any two instants).
    Sample render(double t, double t_prev) const;
    // Colour only (cheaper than render): ground truth at arbitrary instants.
    ImageRGBA render_color(double t) const;
    // Frontmost layer index at every pixel centre at time t (width*height, top row first).
    std::vector<uint8_t> layer_map(double t) const;

    const SceneOptions& options() const { return opt_; }

    // Layers: index 0 is the background plane; the order is not the depth order.
    size_t layer_count() const { return layers_.size(); }
    // Layer origin at time t in pixels: the centre of a rect / disc; for the plane, the position at
    // time t of the plane point that sits at the screen origin at t = 0.
    glm::dvec2 layer_position(size_t i, double t) const;
    // Velocity dp/dt (pixels per frame) and acceleration (pixels per frame^2) of layer i at time t.
    glm::dvec2 layer_velocity(size_t i, double t) const;
    glm::dvec2 layer_acceleration(size_t i) const;
    float layer_depth(size_t i) const;
    LayerShape layer_shape(size_t i) const;
    // Half extents in pixels (rect: half width / half height; disc: radius in both; plane: 0).
    glm::dvec2 layer_half_size(size_t i) const;
    std::string_view layer_name(size_t i) const;
    // Whether layer i covers the point (x, y) (pixels) at time t; edges are inclusive.
    bool layer_covers(size_t i, double x, double y, double t) const;
    // Frontmost (smallest depth) layer covering (x, y) at time t; the background if nothing else.
    size_t visible_layer(double x, double y, double t) const;
    // Linear RGB of layer i's texture at the point (x, y) at time t, whether or not it is visible.
    glm::vec3 layer_color(size_t i, double x, double y, double t) const;

  private:
    struct Wave {
        glm::dvec2 k; // radians per design pixel
        double phase;
        double amp;
        glm::vec3 tint; // per-channel weight of this wave
    };
    struct Layer {
        std::string_view name;
        LayerShape shape;
        float depth;
        glm::dvec2 half;     // pixels
        glm::dvec2 p0, v, a; // pixels, pixels/frame, pixels/frame^2 (speed and `accelerated` applied)
        glm::vec3 c1, c2;    // checker colours, linear
        double cell;         // checker cell, design pixels
        Wave waves[3];
    };

    struct Tables; // per-render separable texture tables (synthetic.cpp)

    glm::vec3 texture(const Layer& l, glm::dvec2 local) const;
    void render_rows(const Tables& tab, uint32_t y0, uint32_t y1, float* rgba) const;

    SceneOptions opt_;
    double tex_scale_ = 1.0; // design pixels per output pixel (textures)
    std::vector<Layer> layers_;
    std::vector<size_t> by_depth_; // layer indices, nearest first
};

// The built-in test capture "synthetic-toss": inputs at t = 0 .. inputs-1 in the internal
// conventions (rgba32f linear colour, linear depth, rg32f pixel vectors to the previous input, y
// down; frame 0's vectors are empty = unknown), ground_truth_kind = halfway with ground_truth[k]
// the exact colour at t = k + 0.5 (k = 0 .. inputs-2), source "synthetic".
// Errors: invalid_argument for options outside their ranges or inputs < 2.
Result<Capture> make_synthetic_capture(const SceneOptions& o, uint32_t inputs = 11);

// One input of such a capture: the scene at t with vectors towards t_prev (any two instants; none
// without with_mv), in make_synthetic_capture's format.
Frame synthetic_frame(const SyntheticScene& scene, double t, double t_prev, bool with_mv = true);

} // namespace fgsr::capture
