#include "telemetry_hub.hpp"

#include <fgsr/core/clock.hpp>

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace fgsrd {

using fgsr::monotonic_ns;
using fgsr::telemetry::FrameRecord;
using fgsr::telemetry::Kind;
using fgsr::telemetry::SessionInfo;

namespace {

constexpr uint64_t kMaxReportSpanNs = 60ull * 1000000000ull; // submit to present, at most
constexpr uint64_t kFutureSlackNs = 1000000000ull;           // a report may not lie in the future

const char* type_label(uint32_t t) {
    switch (t) {
    case FGSR_FRAME_UPSCALED: return "upscaled";
    case FGSR_FRAME_INTERPOLATED: return "interpolated";
    case FGSR_FRAME_EXTRAPOLATED: return "extrapolated";
    default: return "application";
    }
}

double ms(uint64_t from, uint64_t to) {
    if (from == 0 || to == 0 || to < from) return std::nan("");
    return double(to - from) * 1e-6;
}

prometheus::Histogram::BucketBoundaries latency_buckets() {
    return {0.001, 0.002, 0.004, 0.008, 0.016, 0.033, 0.05, 0.1, 0.2, 0.5, 1, 2, 5};
}

prometheus::Histogram::BucketBoundaries gpu_buckets() {
    return {0.0001, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1};
}

} // namespace

struct TelemetryHub::Metrics {
    prometheus::Family<prometheus::Counter>& outputs;
    prometheus::Family<prometheus::Counter>& presents;
    prometheus::Counter& dropped;
    prometheus::Counter& rejected;
    prometheus::Counter& reports_invalid;
    prometheus::Counter& tiles_total;
    prometheus::Counter& tiles_skipped;
    prometheus::Counter& sessions_created;
    prometheus::Gauge& sessions_active;
    prometheus::Family<prometheus::Histogram>& latency;
    prometheus::Family<prometheus::Histogram>& gpu;
    prometheus::Histogram& frame_time;
    prometheus::Family<prometheus::Histogram>& click_to_photon;

    explicit Metrics(prometheus::Registry& r)
        : outputs(prometheus::BuildCounter()
                      .Name("fgsr_outputs_total")
                      .Help("Frames fgsrd wrote, by frame type")
                      .Register(r)),
          presents(prometheus::BuildCounter()
                       .Name("fgsr_presents_total")
                       .Help("Frames clients reported presented, by frame type (application: their own)")
                       .Register(r)),
          dropped(prometheus::BuildCounter()
                      .Name("fgsr_frames_dropped_total")
                      .Help("Frames dropped: superseded in fgsrd's mailbox or not presented by the client")
                      .Register(r)
                      .Add({})),
          rejected(prometheus::BuildCounter()
                       .Name("fgsr_frames_rejected_total")
                       .Help("Submits fgsrd rejected (bad frame, device error, ...)")
                       .Register(r)
                       .Add({})),
          reports_invalid(prometheus::BuildCounter()
                              .Name("fgsr_reports_invalid_total")
                              .Help("Present reports dropped because their values were out of range")
                              .Register(r)
                              .Add({})),
          tiles_total(prometheus::BuildCounter()
                          .Name("fgsr_tiles_total")
                          .Help("Tiles classified by passes that skip work")
                          .Register(r)
                          .Add({})),
          tiles_skipped(prometheus::BuildCounter()
                            .Name("fgsr_tiles_skipped_total")
                            .Help("Tiles whose work was skipped")
                            .Register(r)
                            .Add({})),
          sessions_created(prometheus::BuildCounter()
                               .Name("fgsr_sessions_created_total")
                               .Help("Sessions created since start")
                               .Register(r)
                               .Add({})),
          sessions_active(
              prometheus::BuildGauge().Name("fgsr_sessions").Help("Sessions open now").Register(r).Add({})),
          latency(prometheus::BuildHistogram()
                      .Name("fgsr_latency_seconds")
                      .Help("Latency per frame: daemon (submit to output written), client (submit to the "
                            "client holding it), displayed (submit to present)")
                      .Register(r)),
          gpu(prometheus::BuildHistogram()
                  .Name("fgsr_gpu_seconds")
                  .Help("GPU time per pass and output frame")
                  .Register(r)),
          frame_time(prometheus::BuildHistogram()
                         .Name("fgsr_frame_time_seconds")
                         .Help("Time between consecutive frames of a session's timeline (presents when the "
                               "client reports them, else outputs)")
                         .Register(r)
                         .Add({}, latency_buckets())),
          click_to_photon(prometheus::BuildHistogram()
                              .Name("fgsr_click_to_photon_seconds")
                              .Help("Click-to-photon latency measured by a hardware probe (fgsr probe), by the "
                                    "measured application's frame-generation mode")
                              .Register(r)) {
        // Every labelled series made once, here: the server's thread then only increments and
        // observes (no label lookups, no bucket vectors per frame).
        for (uint32_t t = FGSR_FRAME_UPSCALED; t <= FGSR_FRAME_EXTRAPOLATED; ++t)
            outputs_by_type[t] = &outputs.Add({{"type", type_label(t)}});
        for (uint32_t t = FGSR_FRAME_NONE; t <= FGSR_FRAME_EXTRAPOLATED; ++t)
            presents_by_type[t] = &presents.Add({{"type", type_label(t)}});
        for (uint32_t p = 0; p < FGSR_PASS_COUNT_; ++p)
            gpu_by_pass[p] = &gpu.Add({{"pass", fgsr_pass_name(p)}}, gpu_buckets());
        latency_daemon = &latency.Add({{"kind", "daemon"}}, latency_buckets());
        latency_client = &latency.Add({{"kind", "client"}}, latency_buckets());
        latency_displayed = &latency.Add({{"kind", "displayed"}}, latency_buckets());
        static const char* const kModes[] = {"unknown", "off", "interpolate", "extrapolate"};
        for (uint32_t m = FGSR_PROBE_MODE_UNKNOWN; m <= FGSR_PROBE_MODE_EXTRAPOLATE; ++m)
            c2p_by_mode[m] = &click_to_photon.Add({{"mode", kModes[m]}}, latency_buckets());
    }
    std::array<prometheus::Counter*, 4> outputs_by_type{}, presents_by_type{}; // by fgsr_frame_type
    std::array<prometheus::Histogram*, FGSR_PASS_COUNT_> gpu_by_pass{};
    prometheus::Histogram *latency_daemon = nullptr, *latency_client = nullptr, *latency_displayed = nullptr;
    std::array<prometheus::Histogram*, 4> c2p_by_mode{}; // by FGSR_PROBE_MODE_*
};

TelemetryHub::TelemetryHub(HubOptions options)
    : opt_(std::move(options)), epoch_ns_(monotonic_ns()), registry_(std::make_shared<prometheus::Registry>()),
      metrics_(std::make_unique<Metrics>(*registry_)) {}

TelemetryHub::~TelemetryHub() = default;

void TelemetryHub::stop() {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    changed_.notify_all();
}

bool TelemetryHub::stopped() const {
    std::lock_guard lock(mutex_);
    return stopped_;
}

void TelemetryHub::session_opened(uint32_t id, const SessionMeta& meta, const fgsr_session_desc& desc,
                                  const fgsr_pool_layout& layout) {
    SessionState s;
    s.info.id = id;
    s.info.application = meta.application;
    s.info.client = meta.client;
    s.info.pid = meta.pid;
    s.info.mode = fgsr::telemetry::mode_label(desc.modes);
    s.info.width = desc.width;
    s.info.height = desc.height;
    s.info.output_width = layout.output_width;
    s.info.output_height = layout.output_height;
    s.info.colour_only = (desc.flags & FGSR_SESSION_NO_MVS) != 0;
    s.info.fast_motion = (desc.flags & FGSR_SESSION_FAST_MOTION) != 0;
    {
        std::lock_guard lock(mutex_);
        sessions_[id] = std::move(s);
        // Ended sessions stay on the page for a while: the newest closed_kept_ of them.
        size_t closed = 0;
        for (auto it = sessions_.rbegin(); it != sessions_.rend(); ++it) closed += it->second.info.active ? 0 : 1;
        for (auto it = sessions_.begin(); it != sessions_.end() && closed > closed_kept_;) {
            if (!it->second.info.active) {
                it = sessions_.erase(it);
                --closed;
            } else {
                ++it;
            }
        }
    }
    metrics_->sessions_created.Increment();
    metrics_->sessions_active.Increment();
}

void TelemetryHub::session_closed(uint32_t id) {
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(id);
    if (it == sessions_.end() || !it->second.info.active) return;
    it->second.info.active = false;
    metrics_->sessions_active.Decrement();
}

void TelemetryHub::completion(uint32_t session, const fgsr_completion_entry& c) {
    const fgsr_telemetry& t = c.telemetry;
    Entry e;
    FrameRecord& r = e.record;
    r.session = session;
    r.kind = Kind::output;
    r.type = t.frame_type;
    r.sequence = c.sequence;
    r.output_index = c.output_index;
    r.t_s = seconds(std::max(t.complete_ns, epoch_ns_));
    e.submit_ns = t.submit_ns;
    e.start_ns = t.start_ns;
    e.complete_ns = t.complete_ns;
    const bool wrote = c.status == FGSR_STATUS_OK && c.output_slot != FGSR_NO_SLOT;
    if (wrote) {
        r.lat_d_ms = ms(t.submit_ns, t.complete_ns);
        r.gpu_ms = double(t.gpu_ns) * 1e-6;
        r.has_passes = t.pass_count > 0;
        for (uint32_t i = 0; i < t.pass_count && i < FGSR_MAX_PASSES; ++i) {
            const fgsr_pass_record& p = t.passes[i];
            if (p.pass >= FGSR_PASS_COUNT_) continue;
            const uint64_t dur = p.gpu_end_ns > p.gpu_begin_ns ? p.gpu_end_ns - p.gpu_begin_ns : 0;
            r.pass_ms[p.pass] += float(double(dur) * 1e-6);
            r.tiles_total += p.tiles_total;
            r.tiles_skipped += p.tiles_skipped;
            e.passes.push_back(
                {p.pass, p.tiles_total, p.tiles_skipped, p.gpu_begin_ns, p.gpu_end_ns, std::max(p.runs, 1u)});
            metrics_->gpu_by_pass[p.pass]->Observe(double(dur) * 1e-9);
        }
        if (t.frame_type >= FGSR_FRAME_UPSCALED && t.frame_type <= FGSR_FRAME_EXTRAPOLATED)
            metrics_->outputs_by_type[t.frame_type]->Increment();
        if (std::isfinite(r.lat_d_ms)) metrics_->latency_daemon->Observe(r.lat_d_ms * 1e-3);
        metrics_->tiles_total.Increment(double(r.tiles_total));
        metrics_->tiles_skipped.Increment(double(r.tiles_skipped));
    } else if (c.status == FGSR_STATUS_DROPPED) {
        metrics_->dropped.Increment();
    } else if (c.status != FGSR_STATUS_OK) {
        metrics_->rejected.Increment();
    }
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(session);
    if (it == sessions_.end()) return;
    SessionState& s = it->second;
    if (c.status == FGSR_STATUS_DROPPED) ++s.info.dropped;
    else if (c.status != FGSR_STATUS_OK) ++s.info.rejected;
    if (!wrote) return;
    ++s.info.generated;
    s.info.tiles_total += r.tiles_total;
    s.info.tiles_skipped += r.tiles_skipped;
    if (!s.has_reports) { // no present reports (yet): the outputs are the session's timeline
        ++s.info.frames;
        if (s.last_timeline_ns != 0) {
            r.ft_ms = ms(s.last_timeline_ns, t.complete_ns);
            if (std::isfinite(r.ft_ms)) metrics_->frame_time.Observe(r.ft_ms * 1e-3);
        }
        s.last_timeline_ns = t.complete_ns;
    }
    add(std::move(e));
}

size_t TelemetryHub::reports(uint32_t session, std::span<const fgsr_present_report> reports) {
    const uint64_t now = monotonic_ns();
    size_t kept = 0;
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(session);
    if (it == sessions_.end()) return 0;
    SessionState& s = it->second;
    for (const fgsr_present_report& p : reports) {
        const bool dropped = (p.flags & FGSR_REPORT_DROPPED) != 0;
        auto within = [&](uint64_t t) {
            return t == 0 || (t <= now + kFutureSlackNs && (p.submit_ns == 0 || (t >= p.submit_ns &&
                                                                                   t - p.submit_ns <= kMaxReportSpanNs)));
        };
        const bool valid = p.frame_type <= FGSR_FRAME_EXTRAPOLATED && (p.flags & ~FGSR_REPORT_DROPPED) == 0 &&
                           p.submit_ns <= now + kFutureSlackNs && within(p.received_ns) &&
                           within(p.presented_ns) && (dropped || p.presented_ns != 0) &&
                           (dropped || p.presented_ns >= s.last_timeline_ns || !s.has_reports);
        if (!valid) {
            metrics_->reports_invalid.Increment();
            continue;
        }
        ++kept;
        if (dropped) {
            ++s.info.dropped;
            metrics_->dropped.Increment();
            continue;
        }
        if (!s.has_reports) { // from now on the presents are the timeline
            s.has_reports = true;
            s.last_timeline_ns = 0;
        }
        Entry e;
        FrameRecord& r = e.record;
        r.session = session;
        r.kind = Kind::present;
        r.type = p.frame_type;
        r.sequence = p.sequence;
        r.output_index = p.output_index;
        r.t_s = seconds(std::max(p.presented_ns, epoch_ns_));
        // Client-observed latency is the output's (submit to the client holding it); an application
        // frame is the client's own from the start.
        if (p.frame_type != FGSR_FRAME_NONE) r.lat_c_ms = ms(p.submit_ns, p.received_ns);
        r.disp_ms = ms(p.submit_ns, p.presented_ns);
        if (s.last_timeline_ns != 0) r.ft_ms = ms(s.last_timeline_ns, p.presented_ns);
        s.last_timeline_ns = p.presented_ns;
        ++s.info.frames;
        metrics_->presents_by_type[p.frame_type]->Increment(); // frame_type checked above
        if (std::isfinite(r.ft_ms)) metrics_->frame_time.Observe(r.ft_ms * 1e-3);
        if (std::isfinite(r.lat_c_ms))
            metrics_->latency_client->Observe(r.lat_c_ms * 1e-3);
        if (std::isfinite(r.disp_ms))
            metrics_->latency_displayed->Observe(r.disp_ms * 1e-3);
        add(std::move(e));
    }
    return kept;
}

size_t TelemetryHub::probe_samples(std::span<const fgsr_probe_sample> samples) {
    const uint64_t now = monotonic_ns();
    constexpr uint64_t kMaxLatencyNs = 10'000'000'000ull;
    size_t kept = 0;
    std::lock_guard lock(mutex_);
    for (const fgsr_probe_sample& p : samples) {
        const bool valid = p.mode <= FGSR_PROBE_MODE_EXTRAPOLATE && p.click_ns != 0 && p.photon_ns >= p.click_ns &&
                           p.photon_ns - p.click_ns <= kMaxLatencyNs && p.photon_ns <= now + kFutureSlackNs;
        if (!valid) {
            metrics_->reports_invalid.Increment();
            continue;
        }
        ++kept;
        Entry e;
        e.record.kind = Kind::probe;
        e.record.t_s = seconds(std::max(p.photon_ns, epoch_ns_));
        e.record.c2p_ms = double(p.photon_ns - p.click_ns) * 1e-6;
        metrics_->c2p_by_mode[p.mode]->Observe(e.record.c2p_ms * 1e-3); // mode checked above
        add(std::move(e));
    }
    return kept;
}

void TelemetryHub::add(Entry e) {
    entries_.push_back(std::move(e));
    trim(monotonic_ns());
    changed_.notify_all();
}

void TelemetryHub::trim(uint64_t now_ns) {
    const double oldest = seconds(now_ns) - opt_.window_s;
    while (!entries_.empty() && (entries_.size() > opt_.max_frames || entries_.front().record.t_s < oldest)) {
        entries_.pop_front();
        ++first_index_;
    }
}

std::vector<SessionInfo> TelemetryHub::sessions_copy() const {
    std::vector<SessionInfo> v;
    v.reserve(sessions_.size());
    for (const auto& [id, s] : sessions_) v.push_back(s.info);
    return v;
}

nlohmann::json TelemetryHub::state(bool with_frames, uint64_t* cursor) const {
    std::vector<FrameRecord> frames;
    std::vector<SessionInfo> sessions;
    {
        std::lock_guard lock(mutex_);
        if (cursor) *cursor = first_index_ + entries_.size();
        frames.reserve(entries_.size());
        for (const Entry& e : entries_) frames.push_back(e.record);
        sessions = sessions_copy();
    }
    // The headline figures cover the window (the page's charts show the same frames).
    const fgsr::telemetry::Summary summary = fgsr::telemetry::summarize(frames, sessions);
    fgsr::telemetry::StateHeader h{"live", opt_.title, seconds(monotonic_ns()), opt_.window_s};
    if (with_frames) return fgsr::telemetry::state_json(h, sessions, summary, std::span<const FrameRecord>(frames));
    return fgsr::telemetry::state_json(h, sessions, summary, std::nullopt);
}

uint64_t TelemetryHub::cursor() const {
    std::lock_guard lock(mutex_);
    return first_index_ + entries_.size();
}

nlohmann::json TelemetryHub::frames_since(uint64_t& cursor) const {
    std::vector<FrameRecord> frames;
    {
        std::lock_guard lock(mutex_);
        const uint64_t end = first_index_ + entries_.size();
        const uint64_t from = std::max(cursor, first_index_);
        for (uint64_t i = from; i < end; ++i) frames.push_back(entries_[size_t(i - first_index_)].record);
        cursor = end;
    }
    nlohmann::json a = nlohmann::json::array();
    for (const FrameRecord& r : frames) a.push_back(fgsr::telemetry::record_json(r));
    return {{"frames", std::move(a)}};
}

void TelemetryHub::wait_for(uint64_t cursor, int timeout_ms) const {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                      [&] { return stopped_ || first_index_ + entries_.size() > cursor; });
}

std::string TelemetryHub::metrics_text() const {
    std::ostringstream out;
    prometheus::TextSerializer().Serialize(out, registry_->Collect());
    return out.str();
}

nlohmann::json TelemetryHub::trace(double window) const {
    std::vector<Entry> entries;
    std::vector<SessionInfo> sessions;
    {
        std::lock_guard lock(mutex_);
        const double oldest = seconds(monotonic_ns()) - window;
        for (const Entry& e : entries_)
            if (e.record.t_s >= oldest) entries.push_back(e);
        sessions = sessions_copy();
    }
    nlohmann::json ev = nlohmann::json::array();
    auto us = [](uint64_t ns) { return double(ns) * 1e-3; };
    std::map<uint32_t, uint32_t> pid_of; // session -> the trace's process id
    for (const SessionInfo& s : sessions) {
        const uint32_t pid = s.pid != 0 ? s.pid : s.id;
        pid_of[s.id] = pid;
        ev.push_back({{"name", "process_name"}, {"ph", "M"}, {"pid", pid},
                      {"args", {{"name", s.application + " (pid " + std::to_string(s.pid) + ")"}}}});
        ev.push_back({{"name", "thread_name"}, {"ph", "M"}, {"pid", pid}, {"tid", s.id},
                      {"args", {{"name", "session " + std::to_string(s.id) + " (" + s.mode + ")"}}}});
    }
    for (const Entry& e : entries) {
        const FrameRecord& r = e.record;
        const auto pit = pid_of.find(r.session);
        const uint32_t pid = pit != pid_of.end() ? pit->second : r.session;
        const char* type = fgsr::telemetry::frame_type_label(r.type);
        for (const PassSpan& p : e.passes)
            ev.push_back({{"name", fgsr_pass_name(p.pass)},
                          {"cat", "gpu"},
                          {"ph", "X"},
                          {"ts", us(p.begin_ns)},
                          {"dur", us(p.end_ns - std::min(p.end_ns, p.begin_ns))},
                          {"pid", pid},
                          {"tid", r.session},
                          {"args",
                           {{"sequence", r.sequence},
                            {"output_index", r.output_index},
                            {"frame_type", type},
                            {"tiles_total", p.tiles_total},
                            {"tiles_skipped", p.tiles_skipped},
                            {"runs", p.runs}}}});
        const uint64_t at = r.kind == Kind::output ? e.complete_ns : epoch_ns_ + uint64_t(r.t_s * 1e9);
        if (std::isfinite(r.c2p_ms))
            ev.push_back({{"name", "click to photon"},
                          {"ph", "C"},
                          {"ts", us(at)},
                          {"pid", pid},
                          {"args", {{"ms", r.c2p_ms}}}});
        nlohmann::json lat = nlohmann::json::object();
        if (std::isfinite(r.lat_d_ms)) lat["daemon_ms"] = r.lat_d_ms;
        if (std::isfinite(r.lat_c_ms)) lat["client_ms"] = r.lat_c_ms;
        if (std::isfinite(r.disp_ms)) lat["displayed_ms"] = r.disp_ms;
        if (!lat.empty())
            ev.push_back({{"name", "latency"}, {"ph", "C"}, {"ts", us(at)}, {"pid", pid}, {"args", std::move(lat)}});
        if (std::isfinite(r.ft_ms))
            ev.push_back({{"name", "frame time"},
                          {"ph", "C"},
                          {"ts", us(at)},
                          {"pid", pid},
                          {"args", {{"ms", r.ft_ms}}}});
    }
    return {{"traceEvents", std::move(ev)}, {"displayTimeUnit", "ms"}, {"otherData", {{"source", opt_.title}}}};
}

} // namespace fgsrd
