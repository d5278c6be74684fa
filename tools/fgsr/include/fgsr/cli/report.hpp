// `fgsr report FILE.csv --out DIR`: the dashboard of a recorded run. Reads a CSV in PresentMon's
// columns (fgsr/core/presentmon.hpp: `fgsr replay --telemetry`, the layer's FGSR_LAYER_PRESENTS,
// or PresentMon's own files), turns its rows into the dashboard's model (fgsr/telemetry/model.hpp)
// and writes into DIR:
//   index.html    the dashboard page, self-contained (Chart.js and the data inlined: window.FGSR_DATA
//                 holds the State object, source "recorded", every frame included);
//   summary.json  {"source", "title", "rows", "duration_s", "summary", "sessions"}: the headline
//                 figures (telemetry::summary_json) and per session its panel (session_json) with
//                 its own figures under "summary";
//   frametime.png, latency.png, passes.png with report.gp, frames.dat and passes.dat next to them
//                 (`gnuplot report.gp` in DIR redraws them); without gnuplot, only the script and
//                 data (one line on stderr says so).
// The same headline figures are printed as a small table (report_text).
//
// Rows to records (report_data): sessions are the distinct (ProcessID, SwapChainAddress) pairs,
// numbered from 1 in order of first appearance. Only displayed rows (fgsr_status OK; PresentMon's
// own files have no status: every row) become frame records, kind present: t_s = TimeInSeconds
// minus the first row's, ft_ms = MsBetweenPresents (NaN for a session's first row), lat_d_ms =
// fgsr_daemon_latency_ms, lat_c_ms = fgsr_client_latency_ms, disp_ms = MsUntilDisplayed, gpu_ms =
// MsGPUTime, c2p_ms = MsClickToPhotonLatency, passes from fgsr_<pass>_ms where any is not NA.
// FrameType: Application -> FGSR_FRAME_NONE, fgsr-interpolated / -extrapolated / -upscaled -> their
// types, anything else (PresentMon's "Repeated", vendors' generated frames) -> INTERPOLATED.
// Session counters: frames = displayed rows, generated = displayed rows that are not Application,
// dropped = rows whose fgsr_status is DROPPED, rejected = other statuses that are not OK, tiles
// summed over every row; mode from the generated types seen.
#pragma once

#include <fgsr/core/presentmon.hpp>
#include <fgsr/core/result.hpp>
#include <fgsr/telemetry/model.hpp>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace fgsr::cli {

struct ReportData {
    std::vector<telemetry::FrameRecord> frames; // displayed rows, in file order
    std::vector<telemetry::SessionInfo> sessions;
    std::vector<telemetry::Summary> session_summaries; // one per session
    telemetry::Summary summary;
    size_t rows = 0;
    double duration_s = 0; // last TimeInSeconds minus the first
};

ReportData report_data(std::span<const PresentRow> rows);

struct ReportOptions {
    std::filesystem::path csv;
    std::filesystem::path out;
    bool plots = true;    // write and run the gnuplot script
    bool progress = true; // status lines on stderr
};

struct ReportResult {
    ReportData data;
    std::string source;               // the CSV's path as given
    std::vector<std::string> written; // file names written into out
    std::string note;                 // why plots are missing, when they are
};

Result<ReportResult> run_report(const ReportOptions& options);

// The headline figures as a small table (what `fgsr report` prints).
std::string report_text(const ReportResult& r);

struct ReportCli {
    ReportOptions options;
    std::string csv, out;
    bool quiet = false, no_plots = false;
};
CLI::App* add_report_command(CLI::App& app, ReportCli& c);
int report_main(ReportCli& c);

} // namespace fgsr::cli
