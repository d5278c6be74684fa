// Building blocks of the numerical stress cases, private to fgsr_capture: special values, the
// synthetic content of the small cases, its encoding into client planes of any accepted format, and
// poisons. Implemented in stress_frames.cpp; used by the case table (stress_cases.cpp) and the
// in-process feeder (stress_engine.cpp).
#pragma once

#include <fgsr/capture/stress.hpp>

#include <glm/glm.hpp>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::stress::detail {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kMax = std::numeric_limits<float>::max();
constexpr float kDenorm = 1.0e-40f; // float32 subnormal

// A value written into a float plane; `half` overrides the half encoding (exact subnormals).
struct Special {
    const char* name;
    float value;
    std::optional<uint16_t> half;
};

// Depth value that means "far plane" for a depth kind.
float far_value(DepthKind k);

// ---------------------------------------------------------------------------------------------
// Content: a textured background (depth 40, still) and a textured rectangle (depth 8) that moves
// by `motion` pixels per frame; frame k shows the rectangle at k * motion. Vectors are exact.

struct Content {
    uint32_t w = 0, h = 0;
    std::vector<glm::vec4> color; // linear
    std::vector<float> depth;     // linear view depth
    std::vector<glm::vec2> mv;    // pixels, y down, to previous
};

Content content(uint32_t w, uint32_t h, int k, glm::vec2 motion);

// The content as client planes of format `f` (vectors only when `with_mv`).
Frame encode(const FrameFormat& f, const Content& c, bool with_mv = true);

enum class Plane { color, depth, mv };

struct Poison {
    Plane plane = Plane::color;
    std::vector<Special> values; // pixel (x, y) takes values[(x + y) % size]
    bool everywhere = false;     // every pixel, not a scattered quarter
};

// Writes the poison's values into its plane of `fr` (a scattered quarter of the pixels, or all).
void apply(Frame& fr, const FrameFormat& f, const Poison& p);

FrameFormat format_of(uint32_t w, uint32_t h, ColorFormat cf = ColorFormat::rgba16f_linear,
                      MvFormat mf = MvFormat::rg32f, Conventions conv = {});
Params params_of(float scale);

// ---------------------------------------------------------------------------------------------
// Case builders: steps made lazily, in order.

using StepFn = std::function<Step()>;

inline std::function<Step(size_t)> sequence(std::vector<StepFn> steps) {
    auto list = std::make_shared<std::vector<StepFn>>(std::move(steps));
    return [list](size_t i) { return (*list)[i](); };
}

inline Step submit(Frame f, std::string reject = {}) {
    Step s;
    s.op = Op::submit;
    s.frame = std::move(f);
    s.reject = std::move(reject);
    return s;
}

inline Step request(Op op, std::vector<float> alphas, std::string reject = {}) {
    Step s;
    s.op = op;
    s.alphas = std::move(alphas);
    s.reject = std::move(reject);
    return s;
}

// The colour-only cases (stress_colour.cpp): sessions without vectors and depth.
void add_colour_only_cases(std::vector<Case>& out);

} // namespace fgsr::stress::detail
