// Motion estimation from colour for sessions without vectors (FrameFormat::has_vectors false), and
// for the correction of given ones (Params::correct_vectors):
// the luma pyramid of each submitted frame, block matching coarse to fine in both directions, the
// field's summary on the host (dominant motion, scene cut), then the per-pixel vectors and depth
// proxy (shaders/luma.h, match.h, flow.h; docs/MOTION.md).
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include "session.hpp"

#include <algorithm>
#include <cstring>

namespace fgsr {

std::vector<ref::MotionLevel> ref::motion_levels(uint32_t width, uint32_t height) {
    std::vector<MotionLevel> levels;
    uint32_t w = width, h = height, offset = 0, blocks = 0;
    for (uint32_t k = 0; k < MOTION_MAX_LEVELS; ++k) {
        if (k > 0 && std::min(w, h) < MOTION_MIN_SIDE) break;
        MotionLevel l;
        l.width = w;
        l.height = h;
        l.blocks_x = (w + MOTION_BLOCK - 1) / MOTION_BLOCK;
        l.blocks_y = (h + MOTION_BLOCK - 1) / MOTION_BLOCK;
        l.offset = offset;
        l.field_offset = blocks;
        offset += w * h;
        blocks += l.blocks_x * l.blocks_y;
        levels.push_back(l);
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    return levels;
}

uint32_t ref::motion_field_blocks(const std::vector<MotionLevel>& levels) {
    return levels.empty() ? 0 : levels.back().field_offset + levels.back().blocks_x * levels.back().blocks_y;
}

size_t ref::motion_first_level(const std::vector<MotionLevel>& levels) {
    if (levels.size() < 3) return 0;
    return uint64_t(levels[0].width) * levels[0].height > kMotionHalfResPixels ? 1 : 0;
}

gpu::MatchParams ref::match_params(const std::vector<MotionLevel>& levels, size_t k, bool forward,
                                   bool propagate, bool temporal, bool light) {
    const MotionLevel& l = levels[k];
    const uint32_t half = motion_field_blocks(levels);
    const uint32_t dir = forward ? half : 0, first_pass = 2 * half + dir;
    const size_t finest = motion_first_level(levels);
    gpu::MatchParams m{};
    m.width = l.width;
    m.height = l.height;
    m.blocks_x = l.blocks_x;
    m.blocks_y = l.blocks_y;
    m.src_offset = l.offset;
    m.dst_offset = l.offset;
    m.same_offset = MOTION_NONE;
    m.temporal_offset = MOTION_NONE;
    m.zero_bias = k + 1 < levels.size() ? kMotionZeroBias : 0.f;
    m.light_cap = light ? kMotionLightCap : kMotionNoLightCap;
    if (propagate) {
        m.field_offset = l.field_offset + dir;
        m.same_offset = l.field_offset + first_pass;
        m.radius = kMotionRadiusFine;
        m.lambda = k == finest ? kMotionLambdaFine : kMotionLambda;
        // The finest level's final blocks: their contrast for the fill stage, their SAD for the cut test.
        m.store = MATCH_STORE_SUBPIXEL | (k == finest ? MATCH_STORE_CONTRAST | MATCH_STORE_SAD : 0u);
        return m;
    }
    // The previous -> current field only checks the vectors (flow.h): one pass, straight into the
    // final region.
    m.field_offset = l.field_offset + (forward ? dir : first_pass);
    // A first pass's vectors are read rounded by the propagation; the level-0 check field is read
    // against a tolerance of pixels (flow.h): neither needs a sub-pixel fit. The coarser levels of
    // the check field seed the next level (doubled, rounded): they do.
    m.store = !forward ? 0u : (k == finest ? MATCH_STORE_CONTRAST : MATCH_STORE_SUBPIXEL);
    if (temporal && !forward) m.temporal_offset = 4 * half + l.field_offset;
    if (k + 1 < levels.size()) {
        m.coarse_offset = levels[k + 1].field_offset + dir;
        m.coarse_blocks_x = levels[k + 1].blocks_x;
        m.coarse_blocks_y = levels[k + 1].blocks_y;
        m.radius = k == finest ? kMotionRadiusFine : kMotionRadiusMiddle;
        m.lambda = k == finest ? kMotionLambdaFine : kMotionLambda;
    } else {
        m.radius = kMotionRadiusCoarsest;
        m.lambda = kMotionLambdaCoarsest;
    }
    return m;
}

gpu::MatchParams ref::fill_params(const std::vector<MotionLevel>& levels, bool forward) {
    gpu::MatchParams m = match_params(levels, motion_first_level(levels), forward, true, false);
    std::swap(m.field_offset, m.same_offset); // final blocks in, first-pass region out
    return m;
}

gpu::MatchParams ref::cut_match_params(const std::vector<MotionLevel>& levels) {
    const size_t finest = motion_first_level(levels);
    gpu::MatchParams m = match_params(levels, finest, false, true, false);
    m.same_offset = kCutRegion * motion_field_blocks(levels) + 2 * levels[finest].field_offset;
    return m;
}

gpu::FlowParams ref::flow_params(const std::vector<MotionLevel>& levels, glm::vec2 global, bool write_depth,
                                 VectorCorrection correct, bool coarse) {
    gpu::FlowParams f{};
    const size_t finest = motion_first_level(levels);
    f.width = levels[0].width;
    f.height = levels[0].height;
    f.blocks_x = levels[finest].blocks_x;
    f.blocks_y = levels[finest].blocks_y;
    f.block_shift = uint32_t(finest);
    // The filled finest blocks (fill_params): the first-pass regions, free after propagation.
    f.back_offset = 2 * motion_field_blocks(levels) + levels[finest].field_offset;
    f.fwd_offset = 3 * motion_field_blocks(levels) + levels[finest].field_offset;
    f.global_x = global.x;
    f.global_y = global.y;
    f.fb_tolerance = kMotionFbTolerance;
    f.depth_scale = kMotionDepthScale;
    f.write_depth = write_depth && !correct.on ? 1u : 0u;
    f.correct = correct.on ? 1u : 0u;
    f.correct_ratio = correct.ratio;
    f.correct_margin = correct.margin;
    f.correct_depth = correct.depth;
    f.correct_front = correct.front;
    if (coarse && !correct.on && polish_coarse_top(levels) > 0) {
        f.coarse_level = 1;
        f.coarse_width = levels[1].width;
        f.coarse_height = levels[1].height;
    }
    return f;
}

gpu::PolishParams ref::polish_params(uint32_t width, uint32_t height, uint32_t parity) {
    gpu::PolishParams p{};
    p.width = width;
    p.height = height;
    p.parity = parity;
    p.alpha = kPolishAlpha;
    p.eps_data = kPolishEpsData;
    p.eps_smooth = kPolishEpsSmooth;
    p.zeta = kPolishZeta;
    p.omega = kPolishOmega;
    return p;
}

uint32_t ref::search_patches(uint32_t side, uint32_t stride) {
    return side <= SEARCH_PATCH ? 1u : (side - SEARCH_PATCH + stride - 1) / stride + 1;
}

gpu::PolishParams ref::search_params(const std::vector<MotionLevel>& levels, uint32_t level, uint32_t round) {
    gpu::PolishParams p = polish_coarse_params(levels, level, 0, false);
    p.patch_stride = kSearchStride;
    p.patches_x = search_patches(p.width);
    p.patches_y = search_patches(p.height);
    p.search_steps = kSearchSteps;
    search_round_regions(p, round);
    p.prop_reach = kSearchReach;
    return p;
}

void ref::search_round_regions(gpu::PolishParams& p, uint32_t round) {
    const uint32_t n = p.patches_x * p.patches_y;
    p.patch_in = round == 0 ? MOTION_NONE : ((round - 1) & 1u) * n;
    p.patch_out = (round & 1u) * n;
}

bool ref::searches_level(const std::vector<MotionLevel>& levels, uint32_t level) {
    return level >= kSearchFinest && level <= polish_coarse_top(levels) &&
           std::min(levels[level].width, levels[level].height) >= kSearchMinSide;
}

uint32_t ref::search_patch_capacity(const std::vector<MotionLevel>& levels) {
    uint32_t most = 1;
    for (uint32_t level = 1; level < levels.size(); ++level)
        if (searches_level(levels, level))
            most = std::max(most, search_patches(levels[level].width) * search_patches(levels[level].height));
    return 2 * most; // two rounds: the propagation reads the first's
}

uint32_t ref::polish_coarse_top(const std::vector<MotionLevel>& levels) {
    return levels.size() < 2 ? 0u : std::min<uint32_t>(kPolishCoarseTop, uint32_t(levels.size() - 1));
}

uint32_t ref::polish_coarse_vectors(const std::vector<MotionLevel>& levels) {
    const uint32_t top = polish_coarse_top(levels);
    if (top == 0) return 0;
    return levels[top].offset + levels[top].width * levels[top].height - levels[1].offset;
}

gpu::PolishParams ref::polish_coarse_params(const std::vector<MotionLevel>& levels, uint32_t level,
                                            uint32_t parity, bool seed) {
    const MotionLevel& l = levels[level];
    gpu::PolishParams p = polish_params(l.width, l.height, parity);
    p.luma_offset = l.offset;
    p.mv_offset = l.offset - levels[1].offset;
    p.level = level;
    if (seed && level < polish_coarse_top(levels)) {
        const MotionLevel& src = levels[level + 1];
        p.src_width = src.width;
        p.src_height = src.height;
        p.src_offset = src.offset - levels[1].offset;
    }
    // The finest matched blocks, as flow reads them (flow_params).
    const size_t finest = motion_first_level(levels);
    p.blocks_x = levels[finest].blocks_x;
    p.blocks_y = levels[finest].blocks_y;
    p.block_offset = 2 * motion_field_blocks(levels) + levels[finest].field_offset;
    p.block_shift = uint32_t(finest);
    return p;
}

ref::MotionSummary ref::summarise_motion(std::span<const glm::vec4> blocks, float typical_share,
                                         std::span<const CutBlock> relit) {
    MotionSummary s;
    if (blocks.empty()) return s;
    // Dominant motion: the block vector with the most others within kMotionModeRadius, over at most
    // 256 candidates and 4096 voters (strided samples), then the mean of its voters.
    const size_t n = blocks.size();
    const size_t cand_step = std::max<size_t>(1, n / 256), vote_step = std::max<size_t>(1, n / 4096);
    const float r2 = kMotionModeRadius * kMotionModeRadius;
    size_t best_votes = 0;
    glm::vec2 mode(0.f);
    for (size_t i = 0; i < n; i += cand_step) {
        const glm::vec2 c(blocks[i].x, blocks[i].y);
        size_t votes = 0;
        for (size_t j = 0; j < n; j += vote_step) {
            const glm::vec2 d = glm::vec2(blocks[j].x, blocks[j].y) - c;
            votes += glm::dot(d, d) <= r2 ? 1 : 0;
        }
        if (votes > best_votes) best_votes = votes, mode = c;
    }
    glm::vec2 sum(0.f);
    size_t count = 0, high = 0, high_matched = 0;
    const bool relights = relit.size() == n;
    const LightingFit fit = relights ? fit_lighting(relit) : LightingFit{};
    for (size_t i = 0; i < n; ++i) {
        const glm::vec4& b = blocks[i];
        const glm::vec2 d = glm::vec2(b.x, b.y) - mode;
        if (glm::dot(d, d) <= r2) sum += glm::vec2(b.x, b.y), ++count;
        const bool unmatched = block_unmatched(b.z, b.w);
        high_matched += unmatched ? 1 : 0;
        high += unmatched && (!relights || relit_unmatched(relit[i], fit)) ? 1 : 0;
    }
    s.matched_share = float(high_matched) / float(n);
    s.global = count ? sum / float(count) : mode;
    s.mismatch_share = float(high) / float(n);
    s.cut = is_cut(s.mismatch_share, typical_share);
    return s;
}

ref::MotionSummary ref::summarise_motion(const std::vector<MotionLevel>& levels, const glm::vec4* field,
                                         float typical_share, bool relit) {
    const size_t finest = motion_first_level(levels);
    const MotionLevel& l = levels[finest];
    const size_t n = size_t(l.blocks_x) * l.blocks_y;
    // The cut statistics (kCutRegion): two vec4 per block, a CutBlock's layout.
    const glm::vec4* stats = field + size_t(kCutRegion) * motion_field_blocks(levels) + 2 * size_t(l.field_offset);
    std::span<const CutBlock> cut;
    if (relit) cut = {reinterpret_cast<const CutBlock*>(stats), n};
    MotionSummary s = summarise_motion({field + l.field_offset, n}, typical_share, cut);
    s.global *= float(1u << finest);
    return s;
}

Result<void> Session::Impl::init_motion() {
    estimator.levels = ref::motion_levels(format.width, format.height);
    const uint32_t floats =
        estimator.levels.back().offset + estimator.levels.back().width * estimator.levels.back().height;
    for (vk::Buffer& b : estimator.pyramid) {
        auto r = vk::Buffer::create(*ctx, VkDeviceSize(floats) * 4, false);
        if (!r) return r.error();
        b = std::move(*r);
        FGSR_TRY(b.make_texel_view()); // match and flow read the pyramids with texelFetch
    }
    // Host-visible: the host summarises the level-0 current -> previous blocks between the two
    // command buffers of a submit (a few hundred KB at 1080p).
    auto f = vk::Buffer::create(
        *ctx, VkDeviceSize(ref::motion_field_blocks(estimator.levels)) * ref::kFieldRegions * 16, true);
    if (!f) return f.error();
    estimator.field = std::move(*f);
    // The lighting gain of the last pair (read by the host) and its scaling's dispatch (luma.h).
    auto g = vk::Buffer::create(*ctx, (LUMA_GAIN_DISPATCH + 3) * 4, true);
    if (!g) return g.error();
    estimator.gain = std::move(*g);
    // polish reads the vectors with texelFetch (and writes them through a storage binding).
    for (GpuFrame& fr : frames) FGSR_TRY(fr.mv.make_texel_view(VK_FORMAT_R32G32_SFLOAT));
    // The coarse levels' fields: polish writes and reads them as the vectors, flow reads level 1.
    auto c = vk::Buffer::create(
        *ctx, VkDeviceSize(std::max<uint32_t>(1, ref::polish_coarse_vectors(estimator.levels))) * 8, false);
    if (!c) return c.error();
    estimator.coarse = std::move(*c);
    FGSR_TRY(estimator.coarse.make_texel_view(VK_FORMAT_R32G32_SFLOAT));
    // The patch inverse search's vectors (search.h), one level at a time.
    auto pt =
        vk::Buffer::create(*ctx, VkDeviceSize(ref::search_patch_capacity(estimator.levels)) * 16, false);
    if (!pt) return pt.error();
    estimator.patches = std::move(*pt);
    return estimator.field.make_texel_view(VK_FORMAT_R32G32B32A32_SFLOAT); // flow reads it with texelFetch
}

Result<void> Session::Impl::record_luma(int slot) {
    const vk::Buffer& pyr = estimator.pyramid[size_t(slot)];
    const auto b = make_slots<PassId::luma>(at<LUMA_COLOR>(frames[size_t(slot)].color), at<LUMA_PYRAMID>(pyr),
                                            at<LUMA_PYRAMID_TEXELS>(pyr));
    for (size_t k = 0; k < estimator.levels.size(); ++k) {
        const ref::MotionLevel& l = estimator.levels[k];
        const ref::MotionLevel& src = estimator.levels[k == 0 ? 0 : k - 1];
        gpu::LumaParams p{src.width, src.height, l.width, l.height, src.offset, l.offset, uint32_t(k), 0u};
        if (k > 0) rec.barrier();
        if (k > 0)
            FGSR_TRY(rec.dispatch_pixels(Variant::luma, b, &p, l.width, l.height));
        else if (l.width % 4 == 0 && l.offset % 4 == 0) // 4 pixels per invocation (luma.comp)
            FGSR_TRY(rec.dispatch_pixels(Variant::luma_level0_quad, b, &p, l.width / 4, l.height));
        else
            FGSR_TRY(rec.dispatch_pixels(Variant::luma_level0, b, &p, l.width, l.height));
    }
    return {};
}

Result<void> Session::Impl::record_luma_gain(int cur, int prev) {
    const vk::Buffer& pyr = estimator.pyramid[size_t(prev)];
    const auto b = make_slots<PassId::luma>(at<LUMA_COLOR>(estimator.gain), at<LUMA_PYRAMID>(pyr),
                                            at<LUMA_PYRAMID_TEXELS>(estimator.pyramid[size_t(cur)]));
    const ref::MotionLevel& top = estimator.levels.back();
    const uint32_t floats = top.offset + top.width * top.height;
    const gpu::LumaParams p{top.width * top.height, 0u, floats, 0u, top.offset, 0u, 0u, 0u};
    FGSR_TRY(rec.dispatch(Variant::luma_gain_sum, b, &p, 1, 1));
    rec.barrier();
    // No workgroups where the gain is 1 (the stage above writes the dispatch).
    return rec.dispatch_indirect(Variant::luma_gain_apply, b, &p, estimator.gain,
                                 VkDeviceSize(LUMA_GAIN_DISPATCH) * 4);
}

namespace {
// The build of match for a pass's parameters (shaders/match.h, FGSR_MATCH_KIND): one per kind of
// pass and stores, so that none runs another's candidates with its lanes masked off; the generic
// build for any other combination.
Variant match_variant(const gpu::MatchParams& m) {
    const uint32_t kind = m.same_offset != MOTION_NONE ? 2u : m.coarse_blocks_x > 0u ? 1u : 0u;
    // The builds below the coarsest level also fix the search radius (FGSR_MATCH_RADIUS).
    const uint32_t radius = kind == 0u ? 0u : uint32_t(m.radius);
    switch (radius << 8 | kind << 4 | m.store) {
    case 0x000:
        return Variant::match_k0_s0;
    case 0x002:
        return Variant::match_k0_s2;
    case 0x110:
        return Variant::match_k1_s0;
    case 0x210:
        return Variant::match_k1_s0_r2;
    case 0x111:
        return Variant::match_k1_s1;
    case 0x212:
        return Variant::match_k1_s2;
    case 0x122:
        return Variant::match_k2_s2;
    case 0x127:
        return Variant::match_k2_s7;
    default:
        return Variant::match;
    }
}
} // namespace

Result<void> Session::Impl::record_match(int cur, int prev, bool light) {
    const vk::Buffer& a = estimator.pyramid[size_t(cur)];
    const vk::Buffer& b = estimator.pyramid[size_t(prev)];
    const auto back =
        make_slots<PassId::match>(at<MATCH_SRC>(a), at<MATCH_DST>(b), at<MATCH_FIELD>(estimator.field));
    const auto fwd =
        make_slots<PassId::match>(at<MATCH_SRC>(b), at<MATCH_DST>(a), at<MATCH_FIELD>(estimator.field));
    // The previous submit's current -> previous levels become this one's temporal candidates.
    const bool temporal = estimator.field_valid;
    if (temporal) {
        const VkDeviceSize half = VkDeviceSize(ref::motion_field_blocks(estimator.levels)) * 16;
        const VkBufferCopy region{0, 4 * half, half};
        vkCmdCopyBuffer(rec.cmd(), estimator.field.handle(), estimator.field.handle(), 1, &region);
        rec.barrier();
    }
    const size_t finest = ref::motion_first_level(estimator.levels);
    // Not when correcting given vectors: the correction is there for shading that moves on its own,
    // whose blocks match the still ground's vector about as well, and the ground's blocks outvote
    // them (Motion.CorrectedVectorsFollowAMovingShadow: 32.94 dB without the stages, 30.51 with
    // them); a period-off estimate does not explain the colour better than the given vector does,
    // and the correction keeps the given one there.
    const bool consensus = params.motion_consensus && !correction().on;
    for (size_t k = estimator.levels.size(); k-- > finest;) {
        const ref::MotionLevel& l = estimator.levels[k];
        const gpu::MatchParams pb = ref::match_params(estimator.levels, k, false, false, temporal, light);
        const gpu::MatchParams pf = ref::match_params(estimator.levels, k, true, false, temporal, light);
        FGSR_TRY(rec.dispatch_pixels(match_variant(pb), back, &pb, l.blocks_x, l.blocks_y));
        FGSR_TRY(rec.dispatch_pixels(match_variant(pf), fwd, &pf, l.blocks_x, l.blocks_y));
        rec.barrier();
        const gpu::MatchParams pp = ref::match_params(estimator.levels, k, false, true, temporal, light);
        FGSR_TRY(rec.dispatch_pixels(match_variant(pp), back, &pp, l.blocks_x, l.blocks_y));
        rec.barrier();
        if (!consensus || k == finest) continue;
        FGSR_TRY(rec.dispatch_pixels(Variant::match_ambiguity, back, &pp, l.blocks_x, l.blocks_y));
        rec.barrier();
        FGSR_TRY(rec.dispatch_pixels(Variant::match_consensus, back, &pp, l.blocks_x, l.blocks_y));
        rec.barrier();
    }
    const gpu::MatchParams fb = ref::fill_params(estimator.levels, false),
                           ff = ref::fill_params(estimator.levels, true);
    const ref::MotionLevel& lf = estimator.levels[finest];
    FGSR_TRY(rec.dispatch_pixels(Variant::match_fill, back, &fb, lf.blocks_x, lf.blocks_y));
    FGSR_TRY(rec.dispatch_pixels(Variant::match_fill, fwd, &ff, lf.blocks_x, lf.blocks_y));
    rec.barrier();
    return {};
}

Result<void> Session::Impl::record_cut_match(int cur, int prev) {
    const auto back = make_slots<PassId::match>(at<MATCH_SRC>(estimator.pyramid[size_t(cur)]),
                                                at<MATCH_DST>(estimator.pyramid[size_t(prev)]),
                                                at<MATCH_FIELD>(estimator.field));
    const gpu::MatchParams p = ref::cut_match_params(estimator.levels);
    FGSR_TRY(rec.dispatch_pixels(Variant::match_cut, back, &p, p.blocks_x, p.blocks_y));
    rec.barrier(); // also makes the blocks visible to the host
    return {};
}

ref::MotionSummary Session::Impl::summarise_motion(bool relit) const {
    const auto* blocks = static_cast<const glm::vec4*>(estimator.field.mapped());
    return ref::summarise_motion(estimator.levels, blocks, estimator.typical_share, relit);
}

Result<void> Session::Impl::record_flow(int cur, int prev, glm::vec2 global, bool coarse) {
    const GpuFrame& f = frames[size_t(cur)];
    const auto b = make_slots<PassId::flow>(
        at<FLOW_CUR>(estimator.pyramid[size_t(cur)]), at<FLOW_PREV>(estimator.pyramid[size_t(prev)]),
        at<FLOW_FIELD>(estimator.field), at<FLOW_MV>(f.mv), at<FLOW_DEPTH>(f.depth),
        at<FLOW_PREV_DEPTH>(frames[size_t(prev)].depth), at<FLOW_COARSE>(estimator.coarse));
    const gpu::FlowParams p =
        ref::flow_params(estimator.levels, global, !format.has_depth, correction(), coarse);
    // Steps 4 and 5 are builds of their own (shaders/flow.h); no session runs both.
    const Variant v = p.correct != 0u       ? Variant::flow_correct
                      : p.coarse_level > 0u ? Variant::flow_coarse
                                            : Variant::flow;
    return rec.dispatch_pixels(v, b, &p, format.width, format.height);
}

Result<void> Session::Impl::record_polish(int cur, int prev) {
    const GpuFrame& f = frames[size_t(cur)];
    const auto b = make_slots<PassId::polish>(
        at<POLISH_CUR>(estimator.pyramid[size_t(cur)]), at<POLISH_PREV>(estimator.pyramid[size_t(prev)]),
        at<POLISH_MV>(f.mv), at<POLISH_MV_TEXELS>(f.mv), at<POLISH_FIELD>(estimator.field),
        at<POLISH_PATCHES>(estimator.patches));
    for (uint32_t k = 0; k < 2 * ref::kPolishIterations; ++k) {
        if (k > 0) rec.barrier();
        const gpu::PolishParams p = ref::polish_params(format.width, format.height, k & 1u);
        FGSR_TRY(rec.dispatch_pixels(Variant::polish, b, &p, (format.width + 1) / 2, format.height));
    }
    return {};
}

Result<void> Session::Impl::record_polish_coarse(int cur, int prev, bool search, bool sweep) {
    const auto b = make_slots<PassId::polish>(
        at<POLISH_CUR>(estimator.pyramid[size_t(cur)]), at<POLISH_PREV>(estimator.pyramid[size_t(prev)]),
        at<POLISH_MV>(estimator.coarse), at<POLISH_MV_TEXELS>(estimator.coarse),
        at<POLISH_FIELD>(estimator.field), at<POLISH_PATCHES>(estimator.patches));
    for (uint32_t level = ref::polish_coarse_top(estimator.levels); level >= 1; --level) {
        const ref::MotionLevel& l = estimator.levels[level];
        const gpu::PolishParams seed = ref::polish_coarse_params(estimator.levels, level, 0, true);
        FGSR_TRY(rec.dispatch_pixels(Variant::polish_seed, b, &seed, l.width, l.height));
        if (search && ref::searches_level(estimator.levels, level)) {
            for (uint32_t r = 0; r <= ref::kSearchRounds; ++r) {
                rec.barrier();
                const gpu::PolishParams sp = ref::search_params(estimator.levels, level, r);
                FGSR_TRY(rec.dispatch_pixels(Variant::polish_search, b, &sp, sp.patches_x, sp.patches_y));
            }
            rec.barrier();
            const gpu::PolishParams dp = ref::search_params(estimator.levels, level, ref::kSearchRounds);
            FGSR_TRY(rec.dispatch_pixels(Variant::polish_densify, b, &dp, l.width, l.height));
        }
        // The sweeps only where the frame's own are run (ref::polishes): above, for time.
        const uint32_t sweeps = sweep ? ref::kPolishCoarseIterations : 0u;
        for (uint32_t k = 0; k < 2 * sweeps; ++k) {
            rec.barrier();
            const gpu::PolishParams p = ref::polish_coarse_params(estimator.levels, level, k & 1u, false);
            FGSR_TRY(rec.dispatch_pixels(Variant::polish, b, &p, (l.width + 1) / 2, l.height));
        }
        rec.barrier();
    }
    return {};
}

std::vector<PassTiming> Session::last_motion_timings() const {
    if (!impl_->agreeing()) return impl_->estimator.timings;
    // Params::colour_agree: the colour-only twin's ingest of the frame and its motion estimation
    // (this session estimates nothing itself, or corrects its vectors with its own).
    std::vector<PassTiming> t = impl_->estimator.timings;
    t.push_back(impl_->colour_twin->last_ingest_timing());
    for (PassTiming& p : impl_->colour_twin->last_motion_timings()) t.push_back(std::move(p));
    if (impl_->sr() && impl_->colour_twin->impl_->sr_history.valid)
        t.push_back(impl_->colour_twin->impl_->sr_history.timing); // the twin's upscale (its ESR's history)
    return t;
}

bool Session::last_scene_cut() const {
    return impl_->last_scene_cut;
}

float Session::last_cut_share() const {
    return impl_->last_cut_share;
}

float Session::last_lighting_gain() const {
    return impl_->last_lighting_gain;
}

} // namespace fgsr
