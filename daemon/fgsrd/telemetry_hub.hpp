// fgsrd's telemetry hub (only with --http): every session's frames over the last few seconds, the
// session panels and the Prometheus metrics, fed by the server's thread and read by the HTTP
// server's threads (http_server.hpp). Docs: docs/TELEMETRY.md.
//
// Feeding it costs the server's thread a lock and a copy per completion and per reported present;
// readers copy what they need under the same lock and build JSON and text outside it, so that no
// page load, however many, holds up a frame. Values that come from clients (present reports) are
// checked before they are kept: a report with an unknown frame type or times out of order is
// counted as invalid and dropped.
#pragma once

#include <fgsr/telemetry/model.hpp>
#include <fgsr/wire.h>

#include <nlohmann/json.hpp>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace prometheus {
class Registry;
}

namespace fgsrd {

struct HubOptions {
    double window_s = 60;        // frames kept for the page and /trace.json
    size_t max_frames = 1 << 16; // and at most this many
    std::string title;           // the page's title ("fgsrd on <device>")
};

class TelemetryHub {
  public:
    explicit TelemetryHub(HubOptions options);
    ~TelemetryHub();
    TelemetryHub(const TelemetryHub&) = delete;
    TelemetryHub& operator=(const TelemetryHub&) = delete;

    // The server's thread.
    struct SessionMeta {
        std::string application; // /proc/<pid>/comm of the client
        std::string client;      // the client's HELLO name (escaped)
        uint32_t pid = 0;
    };
    void session_opened(uint32_t id, const SessionMeta& meta, const fgsr_session_desc& desc,
                        const fgsr_pool_layout& layout);
    void session_closed(uint32_t id);
    void completion(uint32_t session, const fgsr_completion_entry& c);
    // Returns the number of reports kept (the others were invalid).
    size_t reports(uint32_t session, std::span<const fgsr_present_report> reports);
    // Click-to-photon samples of a hardware probe; returns the number kept (photon before click,
    // more than 10 s apart, in the future or a mode out of range: counted as invalid).
    size_t probe_samples(std::span<const fgsr_probe_sample> samples);

    // The HTTP server's threads.
    // The page's State object; with the frames of the window when with_frames, and then
    // *cursor (if given) is set to the count of records ever added, to go on from with
    // frames_since().
    nlohmann::json state(bool with_frames, uint64_t* cursor = nullptr) const;
    // Records after `cursor` (a count of records ever added); cursor is moved to the newest.
    nlohmann::json frames_since(uint64_t& cursor) const;
    uint64_t cursor() const;
    // Waits until records past `cursor` exist, the hub stops, or timeout_ms passed.
    void wait_for(uint64_t cursor, int timeout_ms) const;
    // Prometheus text exposition format.
    std::string metrics_text() const;
    // Chrome trace (Perfetto opens it) of the last `seconds`: each pass of each output frame as a
    // complete event, latencies and frame times as counters.
    nlohmann::json trace(double seconds) const;
    // Wakes every waiter for good (shutdown).
    void stop();
    bool stopped() const;

  private:
    struct PassSpan {
        uint32_t pass;
        uint32_t tiles_total, tiles_skipped;
        uint64_t begin_ns, end_ns;
        uint32_t runs; // fgsr_pass_record.runs (1 from daemons before minor 7)
    };
    struct Entry {
        fgsr::telemetry::FrameRecord record;
        uint64_t submit_ns = 0, start_ns = 0, complete_ns = 0; // outputs
        std::vector<PassSpan> passes;                         // outputs
    };
    struct SessionState {
        fgsr::telemetry::SessionInfo info;
        bool has_reports = false;   // its timeline comes from present reports, not outputs
        uint64_t last_timeline_ns = 0;
    };
    double seconds(uint64_t ns) const { return double(ns - epoch_ns_) * 1e-9; }
    void add(Entry e); // under mutex_
    void trim(uint64_t now_ns);
    std::vector<fgsr::telemetry::SessionInfo> sessions_copy() const;

    HubOptions opt_;
    uint64_t epoch_ns_;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    bool stopped_ = false;
    std::deque<Entry> entries_;
    uint64_t first_index_ = 0; // index of entries_.front() among all records ever added
    std::map<uint32_t, SessionState> sessions_;
    size_t closed_kept_ = 16; // ended sessions shown in panels (the newest)

    struct Metrics;
    std::shared_ptr<prometheus::Registry> registry_;
    std::unique_ptr<Metrics> metrics_;
};

} // namespace fgsrd
