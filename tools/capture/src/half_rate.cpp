// Half-rate evaluation of consecutive captures: every other frame becomes an input, the frames in
// between become halfway ground truth, and one-frame vectors are composed into two-frame vectors.
// The rule is documented in docs/CAPTURE_FORMAT.md, "Half-rate evaluation".
#include "capture_internal.hpp"
#include "half_rate_internal.hpp"

#include <fgsr/engine/reference.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

static_assert(sizeof(glm::vec4) == 16 && sizeof(glm::vec2) == 8, "tightly packed glm vectors");

namespace fgsr::capture {

namespace detail {

// Composition of one-frame vectors (internal convention: pixels, y down, to previous).
//
// For pixel x of frame k (centre c = x + 0.5), y = c + mv_k(x) is where its surface was in frame
// k-1. The surface's vector there is mv_{k-1}(y), so its frame k-2 position is
// y + mv_{k-1}(y) and the two-frame vector is mv_k(x) + mv_{k-1}(y).
//
// mv_{k-1} is sampled at y from the 2x2 pixel centres around y, but only among those that show
// x's surface: plain bilinear sampling would mix foreground and background vectors at edges,
// giving vectors of neither. The reference depth is depth_k(x), the depth of the very surface
// point being followed (one frame earlier it differs only by the point's own motion along the
// view axis). Of the four neighbours, the one whose frame k-1 depth is relatively closest to
// depth_k(x) is the anchor; the neighbours within `group_tolerance` (relative) of the anchor's
// depth form the surface and get renormalised bilinear weights. If even the anchor is farther
// than `match_tolerance` (relative) from depth_k(x), the surface was not visible at y in frame
// k-1 (it was disoccluded between k-1 and k): there is no vector to follow and the composed
// vector assumes constant velocity, 2 * mv_k(x). The same fallback applies when y lies outside
// the image.
std::vector<glm::vec2> compose_vectors(const ref::InternalFrame& fk, const ref::InternalFrame& fk1,
                                       const ComposeParams& p) {
    const int w = int(fk.width), h = int(fk.height);
    std::vector<glm::vec2> out(size_t(w) * size_t(h));
    for (int py = 0; py < h; ++py) {
        for (int px = 0; px < w; ++px) {
            const size_t i = size_t(py) * size_t(w) + size_t(px);
            const glm::vec2 m = fk.mv[i];
            const glm::vec2 y = glm::vec2(float(px) + 0.5f, float(py) + 0.5f) + m;
            if (!(y.x >= 0.f && y.y >= 0.f && y.x <= float(w) && y.y <= float(h))) {
                out[i] = 2.f * m;
                continue;
            }
            const float sx = y.x - 0.5f, sy = y.y - 0.5f;
            const float fx0 = std::floor(sx), fy0 = std::floor(sy);
            const float tx = sx - fx0, ty = sy - fy0;
            const int x0 = int(fx0), y0 = int(fy0);
            int nx[4], ny[4];
            float wt[4];
            for (int k = 0; k < 4; ++k) {
                nx[k] = std::clamp(x0 + (k & 1), 0, w - 1);
                ny[k] = std::clamp(y0 + (k >> 1), 0, h - 1);
                wt[k] = ((k & 1) ? tx : 1.f - tx) * ((k >> 1) ? ty : 1.f - ty);
            }
            glm::vec2 v(0.f);
            if (p.rule == ComposeRule::bilinear) {
                for (int k = 0; k < 4; ++k) v += wt[k] * fk1.mv[size_t(ny[k]) * size_t(w) + size_t(nx[k])];
                out[i] = m + v;
                continue;
            }
            float d[4];
            for (int k = 0; k < 4; ++k) d[k] = fk1.depth[size_t(ny[k]) * size_t(w) + size_t(nx[k])];
            float ref = fk.depth[i];
            int anchor = 0;
            if (p.rule == ComposeRule::nearest_anchor) {
                for (int k = 1; k < 4; ++k)
                    if (d[k] < d[anchor]) anchor = k;
            } else {
                for (int k = 1; k < 4; ++k)
                    if (std::abs(d[k] - ref) < std::abs(d[anchor] - ref)) anchor = k;
                if (!(std::abs(d[anchor] - ref) <= p.match_tolerance * ref)) {
                    out[i] = 2.f * m;
                    continue;
                }
            }
            float wsum = 0.f;
            for (int k = 0; k < 4; ++k) {
                if (std::abs(d[k] - d[anchor]) <= p.group_tolerance * d[anchor]) {
                    v += wt[k] * fk1.mv[size_t(ny[k]) * size_t(w) + size_t(nx[k])];
                    wsum += wt[k];
                }
            }
            // The anchor always belongs to its group; its weight may still be 0 (y on a pixel row
            // or column): then take the anchor's vector.
            out[i] =
                m + (wsum > 0.f ? v / wsum : fk1.mv[size_t(ny[anchor]) * size_t(w) + size_t(nx[anchor])]);
        }
    }
    return out;
}

} // namespace detail

Result<Capture> make_half_rate(const Capture& c) {
    if (c.ground_truth_kind != GroundTruth::consecutive)
        return make_error(Errc::invalid_argument,
                          "make_half_rate: capture '" + c.name + "' is not a capture of consecutive frames");
    if (c.inputs.empty())
        return make_error(Errc::empty_input, "make_half_rate: capture '" + c.name + "' has no frames");
    for (size_t i = 0; i < c.inputs.size(); ++i) {
        auto v = params::validate(c.format, c.inputs[i].view());
        if (!v)
            return make_error(v.error().code, "make_half_rate: capture '" + c.name + "' frame " +
                                                  std::to_string(i) + ": " + v.error().message);
    }
    const bool split_hr = !c.hr_reference.empty();
    if (split_hr && c.hr_reference.size() != c.inputs.size())
        return make_error(Errc::size_mismatch, "make_half_rate: capture '" + c.name + "' has " +
                                                   std::to_string(c.hr_reference.size()) +
                                                   " hr references for " + std::to_string(c.inputs.size()) +
                                                   " frames");

    Capture out;
    out.name = c.name;
    out.source = c.source;
    out.format.width = c.format.width;
    out.format.height = c.format.height;
    out.format.color_format = ColorFormat::rgba32f_linear;
    out.format.mv_format = MvFormat::rg32f;
    out.format.conventions = Conventions{}; // linear depth, pixels, to_previous, y down
    out.ground_truth_kind = GroundTruth::halfway;
    out.composed_vectors = true;
    out.hr_format = c.hr_format;

    const size_t n = c.inputs.size();
    const size_t px = size_t(c.format.width) * c.format.height;
    ref::InternalFrame prev; // frame k-1 while frame k is processed
    for (size_t k = 0; k < n; ++k) {
        const bool input = k % 2 == 0;
        // Odd frames are ground truth only if an input follows; the last odd frame is dropped,
        // but its vectors are still needed by the next even frame (none follows, so skip it).
        if (!input && k + 1 >= n) break;
        ref::InternalFrame cur = ref::ingest(c.format, c.inputs[k].view());
        // Colour from decode_color, not ingest: ingest stores halves, the originals are exact floats.
        const ImageRGBA color = decode_color(c.format, c.inputs[k]);
        if (input) {
            Frame f;
            f.jitter_x = c.inputs[k].jitter_x;
            f.jitter_y = c.inputs[k].jitter_y;
            // A cut at the dropped frame before it is a cut here too.
            f.reset = c.inputs[k].reset || (k >= 1 && c.inputs[k - 1].reset);
            f.color.resize(px * 16);
            std::memcpy(f.color.data(), color.rgba.data(), px * 16);
            f.depth = detail::floats_to_bytes(cur.depth);
            if (k >= 2 && cur.has_mv && prev.has_mv && !f.reset) {
                const std::vector<glm::vec2> mv = detail::compose_vectors(cur, prev, detail::ComposeParams{});
                f.mv.resize(px * 8);
                std::memcpy(f.mv.data(), mv.data(), px * 8);
            }
            out.inputs.push_back(std::move(f));
            if (split_hr) out.hr_reference.push_back(c.hr_reference[k]);
        } else {
            ImageRGBA gt;
            gt.width = cur.width;
            gt.height = cur.height;
            gt.rgba = color.rgba;
            out.ground_truth.push_back(std::move(gt));
            if (split_hr) out.hr_ground_truth.push_back(c.hr_reference[k]);
        }
        prev = std::move(cur);
    }
    return out;
}

} // namespace fgsr::capture
