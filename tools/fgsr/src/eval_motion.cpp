// Colour-only sessions, the EPE reference and --vectors-from (fgsr/cli/eval_motion.hpp).
#include <fgsr/cli/eval_motion.hpp>

#include <fgsr/capture/flow_io.hpp>
#include <fgsr/capture/image_io.hpp>
#include <fgsr/capture/metrics.hpp>
#include <fgsr/engine/params.hpp>
#include <fgsr/engine/reference.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstring>

namespace fgsr::cli {

namespace {

// 1 where the client's raw vector is finite (ingest turns the others into zero vectors).
std::vector<uint8_t> known_vectors(const FrameFormat& f, std::span<const std::byte> mv) {
    const size_t n = size_t(f.width) * f.height;
    std::vector<uint8_t> known(n, 1);
    for (size_t i = 0; i < n; ++i) {
        bool finite = true;
        for (size_t a = 0; a < 2; ++a) {
            if (f.mv_format == MvFormat::rg32f) {
                float v;
                std::memcpy(&v, mv.data() + 8 * i + 4 * a, 4);
                finite = finite && std::isfinite(v);
            } else {
                uint16_t h;
                std::memcpy(&h, mv.data() + 4 * i + 2 * a, 2);
                finite = finite && (h & 0x7c00u) != 0x7c00u; // exponent all ones: inf or NaN
            }
        }
        known[i] = finite ? 1 : 0;
    }
    return known;
}

} // namespace

bool is_colour_method(const std::string& method) {
    return method == "fgsr-colour";
}

FrameFormat colour_only(FrameFormat f) {
    f.has_vectors = false;
    f.has_depth = false;
    return f;
}

FrameView session_view(const FrameFormat& session_format, const FrameView& frame) {
    FrameView v = frame;
    if (!session_format.has_vectors) v.mv = {};
    if (!session_format.has_depth) v.depth = {};
    return v;
}

bool restarted_at_cut(const Session& session) {
    return session.last_scene_cut() && session.frames_submitted() < 2;
}

GeneratedFrame with_motion_timings(GeneratedFrame frame, const std::vector<PassTiming>& motion) {
    for (const PassTiming& p : motion) {
        frame.passes.push_back(p);
        frame.gpu_ms += p.ms;
    }
    return frame;
}

VectorReference::VectorReference(const FrameFormat& format)
    : format_(format), width_(format.width), height_(format.height) {
    format_.has_vectors = true;
    format_.has_depth = true;
}

Result<void> VectorReference::add_frame(const FrameView& frame) {
    FGSR_TRY(params::validate(format_, frame));
    const ref::InternalFrame f = ref::ingest(format_, frame);
    const bool previous = has_previous_ && !frame.reset;
    previous_depth_ = std::move(depth_);
    depth_ = f.depth;
    mv_.resize(f.mv.size() * 2);
    for (size_t i = 0; i < f.mv.size(); ++i) {
        mv_[2 * i] = f.mv[i].x;
        mv_[2 * i + 1] = f.mv[i].y;
    }
    has_previous_ = true;
    scorable_ = previous && f.has_mv;
    visible_.clear();
    visible_count_ = 0;
    if (!scorable_) return {};
    const std::vector<uint8_t> known = known_vectors(format_, frame.mv);
    auto mask = capture::visible_in_both(mv_, depth_, previous_depth_, width_, height_,
                                         capture::kVisibleDepthTolerance, known);
    if (!mask) return mask.error();
    visible_ = std::move(*mask);
    for (uint8_t v : visible_) visible_count_ += v;
    return {};
}

Result<void> VectorReference::score(const std::vector<float>& mv, MethodScore& score) const {
    score.scores_vectors = true;
    if (!scorable_ || visible_count_ == 0) return {};
    auto e = capture::end_point_error(mv, mv_, visible_, width_, height_);
    if (!e) return e.error();
    score.epe.push_back(*e);
    return {};
}

Result<void> VectorReference::score(const Session& session, MethodScore& score, std::vector<float>* read) const {
    score.scores_vectors = true;
    if (!scorable_ || (visible_count_ == 0 && !read)) return {};
    auto f = session.read_frame(1);
    if (!f) return f.error();
    FGSR_TRY(this->score(f->mv, score));
    if (read) *read = std::move(f->mv);
    return {};
}

Result<CaptureVectors> replace_vectors_from(capture::Capture& cap, const std::filesystem::path& dir,
                                            size_t last_input) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        return make_error(Errc::io, "--vectors-from: " + dir.string() + " is not a directory");
    CaptureVectors own;
    own.format = cap.format;
    own.mv.resize(cap.inputs.size());
    const uint32_t w = cap.format.width, h = cap.format.height;
    for (size_t k = 0; k < cap.inputs.size(); ++k) {
        own.mv[k] = std::move(cap.inputs[k].mv);
        cap.inputs[k].mv.clear();
        if (k == 0 || k > last_input) continue; // never submitted with vectors
        const std::filesystem::path file = dir / fmt::format("{:04d}.flo", k);
        auto flow = capture::read_flo(file, w, h);
        if (!flow)
            return make_error(flow.error().code,
                              "--vectors-from: input " + std::to_string(k) + ": " + flow.error().message);
        cap.inputs[k].mv.resize(flow->xy.size() * sizeof(float));
        std::memcpy(cap.inputs[k].mv.data(), flow->xy.data(), cap.inputs[k].mv.size());
    }
    cap.format.mv_format = MvFormat::rg32f;
    cap.format.conventions.mv_units = MvUnits::pixels;
    cap.format.conventions.mv_direction = MvDirection::to_previous;
    cap.format.conventions.mv_y_up = false;
    cap.format.has_depth = false;
    return own;
}

Result<void> write_vectors(const std::filesystem::path& dir, size_t k, uint32_t width, uint32_t height,
                           const std::vector<float>& mv, const std::vector<uint8_t>& visible) {
    std::error_code ec;
    std::filesystem::create_directories(dir / "flow", ec);
    if (ec) return make_error(Errc::io, "cannot create " + (dir / "flow").string() + ": " + ec.message());
    const std::string stem = fmt::format("{:04d}", k);
    FGSR_TRY(capture::write_flo(dir / "flow" / (stem + ".flo"), capture::FlowField{width, height, mv}));
    if (visible.empty()) return {};
    ImageRGBA mask{width, height, std::vector<float>(visible.size() * 4, 1.0f)};
    for (size_t i = 0; i < visible.size(); ++i)
        for (size_t c = 0; c < 3; ++c) mask.rgba[4 * i + c] = visible[i] ? 1.0f : 0.0f;
    return capture::write_png(dir / "flow" / (stem + "-visible.png"), mask);
}

FrameView reference_view(const capture::Frame& frame, const CaptureVectors* own, size_t k) {
    FrameView v = frame.view();
    if (own) v.mv = own->mv[k];
    return v;
}

} // namespace fgsr::cli
