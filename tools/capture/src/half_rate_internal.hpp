// Vector composition used by make_half_rate (private to fgsr_capture; exposed for experiments).
#pragma once

#include <fgsr/engine/reference.hpp>

#include <glm/glm.hpp>

#include <vector>

namespace fgsr::capture::detail {

enum class ComposeRule {
    depth_matched,  // the rule make_half_rate uses (see compose_vectors)
    nearest_anchor, // group anchored at the nearest of the 2x2 neighbours, no fallback
    bilinear,       // plain bilinear, no depth test
};

struct ComposeParams {
    ComposeRule rule = ComposeRule::depth_matched;
    float group_tolerance = 0.10f; // relative depth difference to the anchor within one surface
    float match_tolerance = 0.10f; // relative depth difference anchor vs depth_k(x) for "same surface"
};

// Two-frame vectors of frame k (internal convention) from the one-frame vectors of frames k
// (fk, to k-1) and k-1 (fk1, to k-2). Both frames must have vectors and the same size.
std::vector<glm::vec2> compose_vectors(const ref::InternalFrame& fk, const ref::InternalFrame& fk1,
                                       const ComposeParams& p);

} // namespace fgsr::capture::detail
