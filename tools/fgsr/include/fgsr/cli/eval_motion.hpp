// Motion in `fgsr eval` and `fgsr bench`: the colour-only method (`fgsr-colour`: the engine runs
// with the capture's vectors and depth withheld and estimates motion from colour), the end-point
// error of a session's vectors against the capture's, and `--vectors-from` (vectors of .flo files,
// e.g. the DIS reference, in place of the capture's).
//
// EPE of a method, per input frame k >= 1 after it was submitted: the mean over the pixels visible
// in both frames (capture::visible_in_both with the capture's own vectors and depths of frames k
// and k-1: the vector lands inside frame k-1 and frame k-1's depth at the nearest pixel is within
// capture::kVisibleDepthTolerance = 10 % of frame k's) of |v_session - v_capture|, where
// v_session is the session's newest frame (Session::read_frame(1).mv: the estimate of a colour-only
// session, the ingested given vectors otherwise; zero where the engine has none) and v_capture the
// capture's vectors in the internal convention (fgsr::ref::ingest of the frame). Frames without
// capture vectors (the first, those after a cut, unknown ones) and frames where no pixel is
// visible are not scored; the method's figure is the mean over scored frames.
#pragma once

#include <fgsr/cli/eval.hpp>

#include <fgsr/capture/capture.hpp>
#include <fgsr/engine/engine.hpp>

#include <cstdint>
#include <filesystem>
#include <vector>

namespace fgsr::cli {

// Methods that run the engine on colour alone: "fgsr-colour" (parameters of `fgsr`).
bool is_colour_method(const std::string& method);

// The format of a colour-only session: `f` with has_vectors = has_depth = false.
FrameFormat colour_only(FrameFormat f);

// The view a session of `session_format` is handed of a frame: without vectors when the format has
// none, without depth when it has none (withheld, not merely ignored).
FrameView session_view(const FrameFormat& session_format, const FrameView& frame);

// Whether `session` refused to generate because it restarted at a scene cut it detected in its
// newest input (Session::last_scene_cut: block matching without vectors, the cut stage with them
// (Params::vector_cuts); then as after FrameView::reset).
// Eval then shows the nearest input (the `repeat` rule; sr modes: the newest super-resolved
// frame), scores it, counts it in MethodScore::scene_cuts and times nothing for it.
bool restarted_at_cut(const Session& session);

// `frame` with the motion timings (Session::last_motion_timings of the newest input's submit) added
// as passes of their own (gpu_ms includes them): what a colour-only frame costs, the estimation of
// its newest input included.
GeneratedFrame with_motion_timings(GeneratedFrame frame, const std::vector<PassTiming>& motion);

// The capture's vectors and depths, frame by frame, in the internal convention: the reference the
// EPE is measured against. Feed every input in submit order.
class VectorReference {
  public:
    // format: the capture's (with its vectors and depth).
    explicit VectorReference(const FrameFormat& format);

    // The next input, as the capture gives it (its own vectors and depth).
    // Errors: the frame does not match the format (params::validate's).
    Result<void> add_frame(const FrameView& frame);
    // Whether the newest input can be scored: it has vectors and a previous frame (not a cut).
    bool scorable() const { return scorable_; }
    // The visible pixels of the newest input (capture::visible_in_both); empty when not scorable.
    const std::vector<uint8_t>& visible() const { return visible_; }
    // The newest input's vectors in the internal convention (2 floats per pixel).
    const std::vector<float>& vectors() const { return mv_; }

    // EPE of the newest frame of `session` (read_frame(1).mv) against the newest input, appended
    // to score.epe; nothing when the input is not scorable or no pixel is visible. With `read`, a
    // scorable input's vectors are also handed back there (eval --out writes them).
    // Errors: read_frame's, size_mismatch for a session of another size.
    Result<void> score(const Session& session, MethodScore& score, std::vector<float>* read = nullptr) const;
    // The same for a vector field already in the internal convention (2 floats per pixel).
    Result<void> score(const std::vector<float>& mv, MethodScore& score) const;

  private:
    FrameFormat format_;
    uint32_t width_ = 0, height_ = 0;
    std::vector<float> mv_, depth_, previous_depth_;
    std::vector<uint8_t> visible_;
    size_t visible_count_ = 0;
    bool has_previous_ = false, scorable_ = false;
};

// --vectors-from DIR: the vectors of inputs 1 .. last_input of `cap` (as eval feeds them: after
// the half-rate conversion of captures of consecutive frames, so input k is capture frame 2k
// there) are replaced by DIR/%04d.flo (k, 4 digits) read as pixels, x right, y down, to the
// previous input; input 0 gets none. The format becomes rg32f pixel vectors to previous, y down,
// and has_depth = false (the depth planes stay in the frames, for the EPE's visibility, but are
// withheld from sessions). Returns the capture's own format and vector planes (for the reference).
// Errors: io / size_mismatch naming the file (missing, malformed, another size).
struct CaptureVectors {
    FrameFormat format;
    std::vector<std::vector<std::byte>> mv; // per input
};
Result<CaptureVectors> replace_vectors_from(capture::Capture& cap, const std::filesystem::path& dir,
                                            size_t last_input);

// With eval --out: input k's vectors as DIR/flow/%04d.flo (what --vectors-from reads) and, when
// `visible` is not empty, the pixels the EPE counts as DIR/flow/%04d-visible.png (white).
// Errors: io naming the file.
Result<void> write_vectors(const std::filesystem::path& dir, size_t k, uint32_t width, uint32_t height,
                           const std::vector<float>& mv, const std::vector<uint8_t>& visible = {});

// The capture's own view of input k: `frame` with `own`'s vectors when they were replaced.
FrameView reference_view(const capture::Frame& frame, const CaptureVectors* own, size_t k);

} // namespace fgsr::cli
