// The daemon feeder of the numerical stress cases (fgsr/capture/stress.hpp): each case replayed
// through fgsrd with libfgsr_client. A separate library (fgsr_stress_daemon) so that fgsr_capture
// does not link the client.
//
// Mapping of a case to the protocol:
//   - session: fgsr_session_desc from the case's FrameFormat and Params (formats, conventions,
//     scale, t_depth/t_bright/sr_a/sr_b, motion model, dilation, jittered vectors), modes
//     INTERPOLATE | EXTRAPOLATE (| SR when scale > 1), output_format rgba32f, FIFO, 2 input slots,
//     2 * FGSR_MAX_ALPHAS + 1 output slots. Params without a desc field (LUT, blend, resample,
//     separate passes, gap/hole filling, thresholds or sr_a of 0, which means "default" on the
//     wire) make the whole case n/a.
//   - a submit step and the requests that follow it up to the next submit: one fgsr_submit_info
//     (interpolate requests concatenated into interp_alphas, super_resolve as WANT_SR, extrapolate
//     requests into extrap_alphas; RESET, HAS_MV when the vector plane is present, jitter).
//     Requests that must be refused and that the client refuses before sending (alphas out of
//     range, more than FGSR_MAX_ALPHAS, SR of a session that does not upscale, non-finite jitter)
//     are probed with a fgsr_submit of their own that must fail; they count as rejected with the
//     client's status. Other rejections must complete with a non-OK status (BAD_FRAME,
//     NOT_READY, ...) and the daemon's log must state the reason (the case's reject text).
//   - n/a, reported with the reason: plane sizes other than the layout's (fixed by the slot
//     layout), requests before the first frame, an empty alpha list, alphas beyond
//     FGSR_MAX_ALPHAS per submit for a request that must succeed.
// After every case the daemon must answer STATS on the case's session and a fresh client; after
// a refused session it must serve a good one (two frames, one interpolation).
#pragma once

#include <fgsr/capture/stress.hpp>

#include <functional>
#include <string>

namespace fgsr::stress {

struct DaemonTarget {
    std::string socket; // fgsrd's socket path
    // The daemon's stderr log so far (whole text); empty function: the log is not readable, so
    // rejection reasons are recorded by status only and reported as unchecked.
    std::function<std::string()> log;
    // False once the daemon process has exited (crashed); empty function: not observable.
    std::function<bool()> alive;
};

// Feeds one case through the daemon. Never throws. Cases with frames of more than
// `max_pixels` pixels are n/a ("too slow through the daemon"); 0: no limit.
CaseResult run_on_daemon(const DaemonTarget& target, const Case& c, const RunOptions& options = {},
                         size_t max_pixels = 0);

} // namespace fgsr::stress
