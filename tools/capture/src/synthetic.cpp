// Analytic synthetic scene ("synthetic-toss"); see synthetic.hpp for the model and conventions.
#include <fgsr/capture/synthetic.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <system_error>
#include <thread>

namespace fgsr::capture {

namespace {

constexpr double kDesignW = 480.0, kDesignH = 270.0;

// Deterministic, platform-independent random numbers (splitmix64).
class Rng {
  public:
    explicit Rng(uint64_t seed) : s_(seed) {}
    uint64_t next() {
        uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); } // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  private:
    uint64_t s_;
};

glm::vec3 hsv(double h, double s, double v) {
    h = h - std::floor(h);
    const double hh = h * 6.0;
    const int i = int(hh) % 6;
    const double f = hh - std::floor(hh);
    const double p = v * (1 - s), q = v * (1 - s * f), r = v * (1 - s * (1 - f));
    switch (i) {
    case 0:
        return {float(v), float(r), float(p)};
    case 1:
        return {float(q), float(v), float(p)};
    case 2:
        return {float(p), float(v), float(r)};
    case 3:
        return {float(p), float(q), float(v)};
    case 4:
        return {float(r), float(p), float(v)};
    default:
        return {float(v), float(p), float(q)};
    }
}

// One layer as designed on the 480x270 canvas over t in [0, 10].
struct Design {
    const char* name;
    LayerShape shape;
    float depth;
    double hx, hy;    // half extents (design px); for a disc hx is the radius
    int thin_axis;    // -1: none; 0: x half extent is thin_half output pixels; 1: same for y
    double thin_half; // output pixels
    double px, py, vx, vy, ax, ay;
};

// Paths (design px, frames): the panel drifts right, the disc crosses it from the right and overlaps
// it from t ~ 7, the block enters from the left at t ~ 0.8, the ball is tossed in from the bottom edge
// and falls back under gravity, the tile leaves through the right edge at t ~ 4, the thin vertical
// bar sweeps left and decelerates, the thin horizontal rail rises and stops.
constexpr Design kDesign[] = {
    {"background", LayerShape::plane, 50.f, 0, 0, -1, 0, 0, 0, -4.0, 1.0, 0.35, -0.10},
    {"panel", LayerShape::rect, 25.f, 80, 50, -1, 0, 110, 85, 7.0, 1.5, 0.30, 0.0},
    {"disc", LayerShape::disc, 15.f, 42, 42, -1, 0, 390, 170, -16.0, -4.0, 0.50, 0.30},
    {"rail", LayerShape::rect, 12.f, 150, 0, 1, 1.0, 200, 40, 2.0, 5.0, 0.0, -0.60},
    {"tile", LayerShape::rect, 10.f, 26, 26, -1, 0, 440, 50, 9.0, 3.0, 1.20, 0.0},
    {"block", LayerShape::rect, 8.f, 28, 65, -1, 0, -36, 150, 10.0, -1.0, 0.90, -0.10},
    {"ball", LayerShape::disc, 6.f, 18, 18, -1, 0, 40, 262, 30.0, -50.0, -1.0, 9.0},
    {"bar", LayerShape::rect, 4.f, 0, 90, 0, 0.75, 330, 120, -9.0, 1.0, 0.70, 0.0},
};

} // namespace

Result<void> validate(const SceneOptions& o) {
    if (o.width < 1 || o.width > kMaxFrameSide)
        return make_error(Errc::invalid_argument,
                          "SceneOptions.width " + std::to_string(o.width) + " outside [1, " + std::to_string(kMaxFrameSide) + "]");
    if (o.height < 1 || o.height > kMaxFrameSide)
        return make_error(Errc::invalid_argument,
                          "SceneOptions.height " + std::to_string(o.height) + " outside [1, " + std::to_string(kMaxFrameSide) + "]");
    if (o.supersample < 1 || o.supersample > 16)
        return make_error(Errc::invalid_argument,
                          "SceneOptions.supersample " + std::to_string(o.supersample) + " outside [1, 16]");
    if (!std::isfinite(o.speed) || o.speed < 0.0f)
        return make_error(Errc::invalid_argument,
                          "SceneOptions.speed " + std::to_string(o.speed) + " must be finite and >= 0");
    return {};
}

SyntheticScene::SyntheticScene(SceneOptions o) : opt_(o) {
    opt_.width = std::clamp<uint32_t>(opt_.width, 1, kMaxFrameSide);
    opt_.height = std::clamp<uint32_t>(opt_.height, 1, kMaxFrameSide);
    opt_.supersample = std::clamp<uint32_t>(opt_.supersample, 1, 16);
    if (!std::isfinite(opt_.speed) || opt_.speed < 0.0f) opt_.speed = 0.0f;

    const double sx = opt_.width / kDesignW, sy = opt_.height / kDesignH;
    const double s = std::min(sx, sy);
    tex_scale_ = 1.0 / s;
    const double speed = opt_.speed;
    const double acc = opt_.accelerated ? speed : 0.0;

    Rng rng(0x5eed0000ull + uint64_t(opt_.seed) * 0x100000001b3ull);
    const double hue0 = rng.uniform();
    size_t index = 0;
    for (const Design& d : kDesign) {
        Layer l{};
        l.name = d.name;
        l.shape = d.shape;
        l.depth = d.depth;
        // Paths: the designed one, perturbed a little per seed so overlaps and exits are preserved.
        const double jx = rng.uniform(-4.0, 4.0), jy = rng.uniform(-4.0, 4.0);
        const double jv = rng.uniform(0.9, 1.1), ja = rng.uniform(0.9, 1.1);
        l.p0 = {(d.px + jx) * sx, (d.py + jy) * sy};
        l.v = glm::dvec2{d.vx * sx, d.vy * sy} * (jv * speed);
        l.a = glm::dvec2{d.ax * sx, d.ay * sy} * (ja * acc);
        if (d.shape == LayerShape::plane) {
            l.p0 = {0.0, 0.0};
            l.half = {0.0, 0.0};
        } else if (d.shape == LayerShape::disc) {
            l.half = {d.hx * s, d.hx * s};
        } else {
            l.half = {d.hx * s, d.hy * s};
            if (d.thin_axis >= 0) l.half[d.thin_axis] = d.thin_half;
        }
        // Texture: two checker colours of contrasting hue and value, three waves with periods of
        // roughly 30-60, 10-16 and 6-8 design pixels, decreasing amplitude.
        const double hue = hue0 + 0.137 * double(index) + rng.uniform(-0.03, 0.03);
        l.c1 = hsv(hue, rng.uniform(0.45, 0.75), rng.uniform(0.55, 0.75));
        l.c2 = hsv(hue + rng.uniform(0.25, 0.45), rng.uniform(0.35, 0.7), rng.uniform(0.12, 0.3));
        l.cell = d.shape == LayerShape::plane ? rng.uniform(22.0, 30.0) : rng.uniform(9.0, 16.0);
        const double periods[3][2] = {{30.0, 60.0}, {10.0, 16.0}, {6.0, 8.0}};
        const double amps[3] = {0.22, 0.14, 0.07};
        for (int w = 0; w < 3; ++w) {
            const double per = rng.uniform(periods[w][0], periods[w][1]);
            const double ang = rng.uniform(0.0, 2.0 * std::numbers::pi);
            const double kk = 2.0 * std::numbers::pi / per;
            l.waves[w].k = {kk * std::cos(ang), kk * std::sin(ang)};
            l.waves[w].phase = rng.uniform(0.0, 2.0 * std::numbers::pi);
            l.waves[w].amp = amps[w];
            l.waves[w].tint = {float(rng.uniform(0.4, 1.0)), float(rng.uniform(0.4, 1.0)),
                               float(rng.uniform(0.4, 1.0))};
        }
        layers_.push_back(l);
        ++index;
    }
    by_depth_.resize(layers_.size());
    for (size_t i = 0; i < layers_.size(); ++i) by_depth_[i] = i;
    std::stable_sort(by_depth_.begin(), by_depth_.end(),
                     [&](size_t x, size_t y) { return layers_[x].depth < layers_[y].depth; });
}

glm::dvec2 SyntheticScene::layer_position(size_t i, double t) const {
    const Layer& l = layers_.at(i);
    return l.p0 + l.v * t + 0.5 * l.a * (t * t);
}

glm::dvec2 SyntheticScene::layer_velocity(size_t i, double t) const {
    const Layer& l = layers_.at(i);
    return l.v + l.a * t;
}

glm::dvec2 SyntheticScene::layer_acceleration(size_t i) const {
    return layers_.at(i).a;
}
float SyntheticScene::layer_depth(size_t i) const {
    return layers_.at(i).depth;
}
LayerShape SyntheticScene::layer_shape(size_t i) const {
    return layers_.at(i).shape;
}
glm::dvec2 SyntheticScene::layer_half_size(size_t i) const {
    return layers_.at(i).half;
}
std::string_view SyntheticScene::layer_name(size_t i) const {
    return layers_.at(i).name;
}

namespace {

inline bool covers(LayerShape shape, glm::dvec2 half, glm::dvec2 local) {
    switch (shape) {
    case LayerShape::plane:
        return true;
    case LayerShape::rect:
        return std::abs(local.x) <= half.x && std::abs(local.y) <= half.y;
    case LayerShape::disc:
        return local.x * local.x + local.y * local.y <= half.x * half.x;
    }
    return false;
}

} // namespace

bool SyntheticScene::layer_covers(size_t i, double x, double y, double t) const {
    const Layer& l = layers_.at(i);
    return covers(l.shape, l.half, glm::dvec2{x, y} - layer_position(i, t));
}

size_t SyntheticScene::visible_layer(double x, double y, double t) const {
    for (size_t i : by_depth_)
        if (layer_covers(i, x, y, t)) return i;
    return 0;
}

glm::vec3 SyntheticScene::texture(const Layer& l, glm::dvec2 local) const {
    const glm::dvec2 q = local * tex_scale_; // design pixels
    const double pi = std::numbers::pi;
    const double chk = std::clamp(3.0 * std::sin(pi * q.x / l.cell) * std::sin(pi * q.y / l.cell), -1.0, 1.0);
    const glm::vec3 base = glm::mix(l.c1, l.c2, float(0.5 + 0.5 * chk));
    glm::vec3 mod(1.0f);
    for (const Wave& w : l.waves) mod += float(w.amp * std::sin(glm::dot(w.k, q) + w.phase)) * w.tint;
    return base * mod;
}

glm::vec3 SyntheticScene::layer_color(size_t i, double x, double y, double t) const {
    return texture(layers_.at(i), glm::dvec2{x, y} - layer_position(i, t));
}

// The texture is separable per sample row and column: with q = (p - pos) * tex_scale,
//   checker:  sin(pi qx / cell) * sin(pi qy / cell)
//   wave w:   sin(kx qx + ky qy + phase) = sin(kx qx) cos(ky qy + phase) + cos(kx qx) sin(ky qy + phase)
// so one render evaluates the trigonometry once per (layer, sample column) and (layer, sample row)
// and each sample costs a few multiply-adds. Same function as texture() up to rounding (~1e-15).
struct SyntheticScene::Tables {
    static constexpr size_t kTerms = 7; // checker, then (sin, cos) per wave
    std::vector<glm::dvec2> pos;        // layer positions at t
    size_t cols = 0, rows = 0;          // sample columns / rows (width * ss, height * ss)
    std::vector<double> col, row;       // [layer][sample][term]
};

void SyntheticScene::render_rows(const Tables& tab, uint32_t y0, uint32_t y1, float* rgba) const {
    const uint32_t w = opt_.width, ss = opt_.supersample;
    const double inv = 1.0 / ss;
    const float norm = 1.0f / float(ss * ss);
    constexpr size_t T = Tables::kTerms;
    for (uint32_t y = y0; y < y1; ++y) {
        for (uint32_t x = 0; x < w; ++x) {
            // Layers whose bounding box touches this pixel, nearest first (the plane always does).
            size_t cand[16];
            size_t nc = 0;
            for (size_t i : by_depth_) {
                const Layer& l = layers_[i];
                if (l.shape != LayerShape::plane) {
                    const glm::dvec2 c = tab.pos[i];
                    if (c.x + l.half.x < x || c.x - l.half.x > x + 1.0 || c.y + l.half.y < y ||
                        c.y - l.half.y > y + 1.0)
                        continue;
                }
                if (nc < 16) cand[nc++] = i;
            }
            glm::dvec3 acc(0.0);
            for (uint32_t sy = 0; sy < ss; ++sy) {
                const size_t ry = size_t(y) * ss + sy;
                for (uint32_t sx = 0; sx < ss; ++sx) {
                    const size_t cx = size_t(x) * ss + sx;
                    const glm::dvec2 p{x + (sx + 0.5) * inv, y + (sy + 0.5) * inv};
                    for (size_t k = 0; k < nc; ++k) {
                        const size_t li = cand[k];
                        const Layer& l = layers_[li];
                        if (!covers(l.shape, l.half, p - tab.pos[li])) continue;
                        const double* a = &tab.col[(li * tab.cols + cx) * T];
                        const double* b = &tab.row[(li * tab.rows + ry) * T];
                        const double chk = std::clamp(3.0 * a[0] * b[0], -1.0, 1.0);
                        glm::dvec3 mod(1.0);
                        for (int wv = 0; wv < 3; ++wv) {
                            const double sn = a[1 + 2 * wv] * b[2 + 2 * wv] + a[2 + 2 * wv] * b[1 + 2 * wv];
                            mod += (l.waves[wv].amp * sn) * glm::dvec3(l.waves[wv].tint);
                        }
                        const glm::dvec3 base = glm::mix(glm::dvec3(l.c1), glm::dvec3(l.c2), 0.5 + 0.5 * chk);
                        acc += base * mod;
                        break;
                    }
                }
            }
            float* o = rgba + (size_t(y - y0) * w + x) * 4;
            o[0] = float(acc.r) * norm;
            o[1] = float(acc.g) * norm;
            o[2] = float(acc.b) * norm;
            o[3] = 1.0f;
        }
    }
}

ImageRGBA SyntheticScene::render_color(double t) const {
    ImageRGBA img;
    img.width = opt_.width;
    img.height = opt_.height;
    img.rgba.assign(size_t(img.width) * img.height * 4, 0.0f);

    const uint32_t ss = opt_.supersample;
    constexpr size_t T = Tables::kTerms;
    const double pi = std::numbers::pi;
    Tables tab;
    tab.cols = size_t(img.width) * ss;
    tab.rows = size_t(img.height) * ss;
    tab.pos.resize(layers_.size());
    tab.col.resize(layers_.size() * tab.cols * T);
    tab.row.resize(layers_.size() * tab.rows * T);
    for (size_t li = 0; li < layers_.size(); ++li) {
        const Layer& l = layers_[li];
        tab.pos[li] = layer_position(li, t);
        for (size_t i = 0; i < tab.cols; ++i) {
            const double qx = ((double(i) + 0.5) / ss - tab.pos[li].x) * tex_scale_;
            double* a = &tab.col[(li * tab.cols + i) * T];
            a[0] = std::sin(pi * qx / l.cell);
            for (int wv = 0; wv < 3; ++wv) {
                a[1 + 2 * wv] = std::sin(l.waves[wv].k.x * qx);
                a[2 + 2 * wv] = std::cos(l.waves[wv].k.x * qx);
            }
        }
        for (size_t j = 0; j < tab.rows; ++j) {
            const double qy = ((double(j) + 0.5) / ss - tab.pos[li].y) * tex_scale_;
            double* b = &tab.row[(li * tab.rows + j) * T];
            b[0] = std::sin(pi * qy / l.cell);
            for (int wv = 0; wv < 3; ++wv) {
                b[1 + 2 * wv] = std::sin(l.waves[wv].k.y * qy + l.waves[wv].phase);
                b[2 + 2 * wv] = std::cos(l.waves[wv].k.y * qy + l.waves[wv].phase);
            }
        }
    }

    // Rows are independent; split them over a few threads (the result does not depend on the split).
    const uint32_t hw = std::max(1u, std::thread::hardware_concurrency());
    const uint32_t nthreads = std::clamp<uint32_t>(hw, 1, 16);
    const uint32_t band = std::max<uint32_t>(1, (img.height + nthreads * 4 - 1) / (nthreads * 4));
    std::vector<std::thread> pool;
    std::atomic<uint32_t> next{0};
    auto work = [&] {
        for (;;) {
            const uint32_t y0 = next.fetch_add(band);
            if (y0 >= img.height) return;
            const uint32_t y1 = std::min(img.height, y0 + band);
            render_rows(tab, y0, y1, img.rgba.data() + size_t(y0) * img.width * 4);
        }
    };
    try {
        for (uint32_t i = 1; i < nthreads; ++i) pool.emplace_back(work);
    } catch (const std::system_error&) {
        // No more threads: the ones started and this one finish the rows between them.
    }
    work();
    for (auto& th : pool) th.join();
    return img;
}

std::vector<uint8_t> SyntheticScene::layer_map(double t) const {
    std::vector<uint8_t> out(size_t(opt_.width) * opt_.height);
    for (uint32_t y = 0; y < opt_.height; ++y)
        for (uint32_t x = 0; x < opt_.width; ++x)
            out[size_t(y) * opt_.width + x] = uint8_t(visible_layer(x + 0.5, y + 0.5, t));
    return out;
}

SyntheticScene::Sample SyntheticScene::render(double t, double t_prev) const {
    Sample s;
    s.color = render_color(t);
    s.layer = layer_map(t);
    const size_t n = s.layer.size();
    s.depth.resize(n);
    s.mv.resize(n);
    std::vector<glm::vec2> motion(layers_.size());
    for (size_t i = 0; i < layers_.size(); ++i)
        motion[i] = glm::vec2(layer_position(i, t_prev) - layer_position(i, t));
    for (size_t i = 0; i < n; ++i) {
        s.depth[i] = layers_[s.layer[i]].depth;
        s.mv[i] = motion[s.layer[i]];
    }
    return s;
}

namespace {

template <class T> std::vector<std::byte> to_bytes(const std::vector<T>& v) {
    std::vector<std::byte> out(v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

} // namespace

Frame synthetic_frame(const SyntheticScene& scene, double t, double t_prev, bool with_mv) {
    const SyntheticScene::Sample s = scene.render(t, t_prev);
    Frame f;
    f.color = to_bytes(s.color.rgba);
    f.depth = to_bytes(s.depth);
    if (with_mv) f.mv = to_bytes(s.mv);
    return f;
}

Result<Capture> make_synthetic_capture(const SceneOptions& o, uint32_t inputs) {
    FGSR_TRY(validate(o));
    if (inputs < 2)
        return make_error(Errc::invalid_argument,
                          "make_synthetic_capture: inputs " + std::to_string(inputs) + " < 2");
    static_assert(sizeof(glm::vec2) == 8, "rg32f vectors are two packed floats");
    const SyntheticScene scene(o);
    Capture c;
    c.name = "synthetic-toss";
    c.source = "synthetic";
    c.format.width = o.width;
    c.format.height = o.height;
    c.format.color_format = ColorFormat::rgba32f_linear;
    c.format.mv_format = MvFormat::rg32f;
    c.format.conventions = Conventions{}; // linear depth, pixels, to_previous, y down
    c.ground_truth_kind = GroundTruth::halfway;
    c.inputs.reserve(inputs);
    for (uint32_t k = 0; k < inputs; ++k)
        c.inputs.push_back(synthetic_frame(scene, double(k), double(k) - 1.0, k > 0));
    c.ground_truth.reserve(inputs - 1);
    for (uint32_t k = 0; k + 1 < inputs; ++k) c.ground_truth.push_back(scene.render_color(k + 0.5));
    return c;
}

} // namespace fgsr::capture
