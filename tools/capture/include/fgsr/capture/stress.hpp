// Numerical stress cases: one table shared by the test suite (tests/test_stress.cpp) and
// `fgsr stress` (tools/fgsr/src/stress.cpp). Implemented in tools/capture/src/stress_*.cpp.
//
// A case is a session format and parameters plus a list of steps in the shape a client hands them
// over: frames as FrameView planes (fgsr::FrameView / the daemon's input slots), and requests
// (interpolate / extrapolate at alphas, the super-resolved frame). Steps are built lazily, one at
// a time, so a 100,000-frame run holds only its current frame. Every step states what must happen:
// success with every output pixel finite, or rejection with an error whose message names the
// problem. run_on_engine() feeds a case to an in-process fgsr::Engine; a daemon feeder (fgsrd via
// libfgsr_client) can feed the same steps: a submit plus the generate requests that follow it
// map to one fgsr_submit_info, super_resolve to the SR output of that submit.
#pragma once

#include <fgsr/engine/engine.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace fgsr::stress {

// One client frame with owning planes (client formats and conventions of the case's FrameFormat).
struct Frame {
    std::vector<std::byte> color, depth, mv; // mv empty: vectors unknown
    float jitter_x = 0.f, jitter_y = 0.f;    // pixels
    bool reset = false;                      // scene cut
    FrameView view() const { return FrameView{color, depth, mv, jitter_x, jitter_y, reset}; }
};

enum class Op {
    submit,        // Session::submit(frame)
    interpolate,   // Session::interpolate(alphas)
    extrapolate,   // Session::extrapolate(alphas)
    super_resolve, // Session::super_resolved()
};

struct Step {
    Op op = Op::submit;
    Frame frame;               // submit only
    std::vector<float> alphas; // interpolate / extrapolate only
    // Empty: the step must succeed and every output pixel (and, for submit, every ingested value)
    // must be finite. Otherwise the step must fail with an error whose message contains this text
    // (ASCII case-insensitive): the stated reason.
    std::string reject;
    // Outputs must be bit-identical to those of the previous generate step (determinism).
    bool same_as_previous = false;
    // Drift measurement (super_resolve only): >= 0 keeps the output as reference number
    // `drift_reference`; the output of a step with `drift_compare` >= 0 is scored (PSNR, dB)
    // against the reference of that number.
    int drift_reference = -1;
    int drift_compare = -1;
    // interpolate / extrapolate across a scene cut the session was not told about (no
    // FrameView::reset; colour-only sessions detect cuts from colour): the step passes when it is
    // refused with a reason mentioning "needs two submitted frames" or with the session's
    // frames_submitted() back at 1 (the engine restarted at the cut, as after FrameView::reset),
    // or when every output equals the session's frame 0 or frame
    // 1 as stored (Session::read_frame, within 1e-3 relative to max(1, |value|)): never a warp or
    // a blend of the two scenes. `reject` is unused.
    bool across_cut = false;
    // interpolate / extrapolate on content a session may take for a scene cut (colour-only: no
    // texture, noise, a fade, motion beyond any search range; with vectors, ingest's cut stage: a
    // clean frame after poisoned ones): besides succeeding, the step may be
    // refused as after a reset (a reason mentioning "needs two submitted frames", or the session's
    // frames_submitted() back at 1; through fgsrd NOT_READY with that reason logged). Any other
    // failure still fails the case.
    bool cut_allowed = false;
};

struct Case {
    std::string name;   // unique, "group/what[/variant]"
    std::string checks; // what the case checks, one line for the report
    FrameFormat format;
    Params params;
    // Non-empty: create_session must fail with a message containing this text; the runner then
    // checks that the engine still serves a good session.
    std::string reject_session;
    size_t step_count = 0;
    std::function<Step(size_t index)> step; // steps 0 .. step_count-1, in order
    bool cpu_reference = true;              // also run the CPU reference on the same inputs (small cases)
    // Long runs: the drift figure must stay at or above this PSNR (dB).
    double min_drift_db = 0.0;
    // > 0: the case fails when it takes longer (seconds, wall time of the whole case): a bound
    // against runaway work (e.g. a search that grows with the motion), not a benchmark.
    double max_seconds = 0.0;
};

struct CaseOptions {
    // Frames of the long super-resolution run (the full run is 100,000).
    size_t sr_frames = 300;
    // true: the test suite's form (the large-resolution case at 8192x8 only); false: adds a
    // 1920x1080 single frame.
    bool reduced = true;
};

std::vector<Case> make_cases(const CaseOptions& options);

struct CaseResult {
    std::string name, checks;
    bool pass = false;
    std::string failure;                 // the first failed check (empty when pass)
    std::vector<std::string> rejections; // stated reasons of the rejected inputs, in order
    size_t steps_run = 0;
    size_t outputs_checked = 0; // images (generated, super-resolved, ingested) checked finite
    uint64_t values_checked = 0;
    std::optional<double> drift_db; // lowest PSNR of the drift comparisons
    // Largest difference between a GPU output and the CPU reference on the same inputs, relative
    // to max(1, |reference|) (cases run with the CPU reference only). On CPU devices a difference
    // above 1e-3 fails the case; on GPUs it is reported only.
    std::optional<double> max_cpu_difference;
    double seconds = 0;
    // Daemon feeder (fgsr/stress/daemon.hpp) only: steps, or with `applicable` false the whole
    // case, that the protocol cannot express, each with the reason ("step 3 (submit): ...").
    // They are reported, never counted as passed checks.
    bool applicable = true;
    std::vector<std::string> not_applicable;
};

struct RunOptions {
    // Called with a short line after every `progress_every` steps of long cases (stderr in the CLI).
    std::function<void(const std::string&)> progress;
    size_t progress_every = 1000;
};

// Feeds one case to a session of `engine`. Never throws; a crash is the only failure it cannot
// report. Vulkan validation errors reported during the case fail it.
CaseResult run_on_engine(Engine& engine, const Case& c, const RunOptions& options = {});

} // namespace fgsr::stress
