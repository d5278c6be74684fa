// Private to `fgsr replay` (replay.cpp): what replay "presents" and when, written as PresentMon CSV
// rows (fgsr/core/presentmon.hpp, `--telemetry`) and reported to fgsrd (fgsr_report_presents).
//
// Replay has no display, so it defines its presents. Display order, per submit in sequence order:
// the interpolated outputs of the submit (output index order), then the application's own frame
// (in sr mode the upscaled output takes its place: no Application row for that frame), then the
// extrapolated outputs. Replay presents each frame as soon as it holds it and every frame before it
// in display order has been presented or has failed:
//   - an output is held when fgsr_wait returns it; it is presented right then;
//   - the application's frame is held from its submit; it is presented right after the outputs
//     that come before it, or, when none does, right after its submit (or, when earlier submits
//     are still being completed, right after the last completion of the one before it).
// So present times never decrease along the rows. A present's time is fgsr's monotonic clock when
// it happens; MsUntilDisplayed is that minus the frame's submit.
//
// Outputs that failed (NOT_READY, BAD_FRAME, DEVICE_ERROR, ...) and submits that the daemon dropped
// (mailbox) or rejected as a whole are not presented but still get a row: fgsr_status names the
// status (PresentMon style: "DROPPED", "NOT_READY", ...), TimeInSeconds is when the client learned
// of it, and MsBetweenPresents and MsUntilDisplayed are NA; they are reported with
// FGSR_REPORT_DROPPED. Not thread-safe; replay's one thread uses it.
#pragma once

#include <fgsr/client.hpp>
#include <fgsr/core/result.hpp>

#include <cstdint>
#include <cstdio>
#include <deque>
#include <string>
#include <vector>

namespace fgsr::cli {

// fgsr_status as its enum name without the prefix ("OK", "DROPPED", "NOT_READY"), the spelling of
// the fgsr_status column.
const char* status_code_name(int32_t status);

class ReplayPresenter {
  public:
    // csv: the open --telemetry file, or null (reports only). Writes the header when csv is set.
    ReplayPresenter(client::Session& session, FILE* csv);

    // The application's frame of submit `sequence`, handed to fgsr_submit at submit_ns; `interp`
    // interpolated outputs come before it; `upscaled`: the upscaled output takes its place.
    void submitted(uint64_t sequence, uint64_t submit_ns, uint32_t interp, bool upscaled);
    // A completion that fgsr_wait returned at received_ns.
    void completed(const fgsr_output& out, uint64_t received_ns);
    // Sends the reports gathered since the last flush (an UNSUPPORTED daemon: none from then on) and
    // checks the CSV's stream. Errors: the report call's status, or a write error of the CSV.
    Result<void> flush();

    size_t rows() const { return rows_; }

  private:
    struct Pending {
        uint64_t sequence = 0, submit_ns = 0;
        uint32_t before = 0;   // interpolated outputs not yet seen
        bool replaced = false; // sr: the upscaled output stands for the application's frame
        bool app_done = false; // presented, replaced, or failed as a whole
        bool ended = false;    // its LAST completion arrived
    };
    void present_ready();
    void present_application(Pending& p);
    void output_row(const fgsr_output& out, uint64_t received_ns);

    client::Session& session_;
    FILE* csv_;
    std::string application_;
    uint32_t pid_;
    std::deque<Pending> pending_;
    std::vector<fgsr_present_report> reports_;
    uint64_t last_present_ns_ = 0; // 0: none yet
    size_t rows_ = 0;
    bool reports_supported_ = true;
};

} // namespace fgsr::cli
