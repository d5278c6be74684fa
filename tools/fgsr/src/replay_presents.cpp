// `fgsr replay`'s presents (replay_presents.hpp): the display order, the PresentMon rows of
// --telemetry and the present reports sent to fgsrd.
#include "replay_presents.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/core/presentmon.hpp>

#include <cerrno>
#include <cmath>
#include <limits>
#include <unistd.h>

namespace fgsr::cli {

namespace {

constexpr double kNA = std::numeric_limits<double>::quiet_NaN();

// later - earlier in ms; NA when either is unknown (0).
double ms_between(uint64_t later, uint64_t earlier) {
    if (later == 0 || earlier == 0) return kNA;
    return double(int64_t(later - earlier)) * 1e-6;
}

double ns_to_ms(uint64_t ns) {
    return double(ns) * 1e-6;
}

// The executable's name, as PresentMon's Application column has it.
std::string executable_name() {
    const char* n = program_invocation_short_name;
    return n && *n ? n : "fgsr";
}

} // namespace

const char* status_code_name(int32_t status) {
    switch (fgsr_status(status)) {
    case FGSR_STATUS_OK:
        return "OK";
    case FGSR_STATUS_INVALID_ARGUMENT:
        return "INVALID_ARGUMENT";
    case FGSR_STATUS_DAEMON_UNAVAILABLE:
        return "DAEMON_UNAVAILABLE";
    case FGSR_STATUS_DISCONNECTED:
        return "DISCONNECTED";
    case FGSR_STATUS_VERSION_MISMATCH:
        return "VERSION_MISMATCH";
    case FGSR_STATUS_PROTOCOL_ERROR:
        return "PROTOCOL_ERROR";
    case FGSR_STATUS_PERMISSION_DENIED:
        return "PERMISSION_DENIED";
    case FGSR_STATUS_OUT_OF_MEMORY:
        return "OUT_OF_MEMORY";
    case FGSR_STATUS_UNSUPPORTED:
        return "UNSUPPORTED";
    case FGSR_STATUS_BAD_FRAME:
        return "BAD_FRAME";
    case FGSR_STATUS_NO_SLOT:
        return "NO_SLOT";
    case FGSR_STATUS_TIMEOUT:
        return "TIMEOUT";
    case FGSR_STATUS_DROPPED:
        return "DROPPED";
    case FGSR_STATUS_NOT_READY:
        return "NOT_READY";
    case FGSR_STATUS_DEVICE_ERROR:
        return "DEVICE_ERROR";
    case FGSR_STATUS_BUSY:
        return "BUSY";
    case FGSR_STATUS_INTERNAL:
        return "INTERNAL";
    case FGSR_STATUS_COUNT_:
        break;
    }
    return "UNKNOWN";
}

ReplayPresenter::ReplayPresenter(client::Session& session, FILE* csv)
    : session_(session), csv_(csv), application_(executable_name()), pid_(uint32_t(getpid())) {
    if (csv_) std::fprintf(csv_, "%s\n", presentmon_header().c_str());
}

void ReplayPresenter::submitted(uint64_t sequence, uint64_t submit_ns, uint32_t interp, bool upscaled) {
    Pending p;
    p.sequence = sequence;
    p.submit_ns = submit_ns;
    p.before = interp;
    p.replaced = upscaled;
    pending_.push_back(p);
    present_ready();
}

void ReplayPresenter::completed(const fgsr_output& out, uint64_t received_ns) {
    // Completions come in sequence order; an earlier submit still open lost its LAST (fgsrd never
    // does that): it ends here.
    while (!pending_.empty() && pending_.front().sequence < out.sequence) {
        pending_.front().ended = true;
        pending_.front().before = 0;
        present_ready();
    }
    Pending* p = !pending_.empty() && pending_.front().sequence == out.sequence ? &pending_.front() : nullptr;
    const uint32_t type = out.telemetry.frame_type;
    if (!p) { // a completion of no known submit: recorded, outside the display order
        if (type != FGSR_FRAME_NONE || out.status != FGSR_STATUS_OK) output_row(out, received_ns);
        return;
    }
    switch (type) {
    case FGSR_FRAME_INTERPOLATED:
        output_row(out, received_ns);
        if (p->before > 0) --p->before;
        break;
    case FGSR_FRAME_UPSCALED:
        output_row(out, received_ns);
        p->app_done = true;
        break;
    case FGSR_FRAME_EXTRAPOLATED:
        p->before = 0;
        if (!p->app_done && !p->replaced) present_application(*p);
        output_row(out, received_ns);
        break;
    default:
        // A submit without outputs (OK: nothing to show of fgsr's), or one dropped or rejected as a
        // whole: its row stands for the application's frame, which is not presented.
        if (out.status != FGSR_STATUS_OK) {
            output_row(out, received_ns);
            p->app_done = true;
        }
        break;
    }
    if (out.flags & FGSR_COMPLETION_LAST) {
        p->ended = true;
        p->before = 0;
    }
    present_ready();
}

void ReplayPresenter::present_ready() {
    while (!pending_.empty()) {
        Pending& p = pending_.front();
        if (!p.app_done && !p.replaced && p.before == 0) present_application(p);
        if (!p.ended) break;
        pending_.pop_front();
    }
}

void ReplayPresenter::present_application(Pending& p) {
    p.app_done = true;
    const uint64_t now = monotonic_ns();
    PresentRow r;
    r.application = application_;
    r.process_id = pid_;
    r.runtime = "fgsr-replay";
    r.frame_type = "Application";
    r.time_s = double(now) * 1e-9;
    r.ms_between_presents = ms_between(now, last_present_ns_);
    r.ms_until_displayed = ms_between(now, p.submit_ns);
    r.sequence = p.sequence;
    last_present_ns_ = now;
    if (csv_) std::fprintf(csv_, "%s\n", presentmon_row(r).c_str());
    ++rows_;
    fgsr_present_report rep{};
    rep.sequence = p.sequence;
    rep.output_index = FGSR_REPORT_APPLICATION;
    rep.frame_type = FGSR_FRAME_NONE;
    rep.submit_ns = p.submit_ns;
    rep.presented_ns = now;
    reports_.push_back(rep);
}

void ReplayPresenter::output_row(const fgsr_output& out, uint64_t received_ns) {
    const fgsr_telemetry& t = out.telemetry;
    const bool presented = out.status == FGSR_STATUS_OK && out.output_slot != FGSR_NO_SLOT;
    PresentRow r;
    r.application = application_;
    r.process_id = pid_;
    r.runtime = "fgsr-replay";
    r.frame_type = presentmon_frame_type(t.frame_type);
    r.time_s = double(received_ns) * 1e-9;
    if (presented) {
        r.ms_between_presents = ms_between(received_ns, last_present_ns_);
        r.ms_until_displayed = ms_between(received_ns, t.submit_ns);
        last_present_ns_ = received_ns;
    }
    r.ms_until_render_complete = ms_between(t.complete_ns, t.submit_ns);
    r.ms_gpu_time = ns_to_ms(t.gpu_ns);
    r.sequence = out.sequence;
    r.output_index = out.output_index;
    r.status = status_code_name(out.status);
    r.target_time = double(t.target_time);
    r.daemon_latency_ms = r.ms_until_render_complete;
    r.client_latency_ms = ms_between(received_ns, t.submit_ns);
    r.queue_wait_ms = ns_to_ms(t.queue_wait_ns);
    r.daemon_cpu_ms = ns_to_ms(t.daemon_cpu_ns);
    r.skipped_passes = t.skipped_passes;
    for (uint32_t i = 0; i < t.pass_count && i < FGSR_MAX_PASSES; ++i) {
        const fgsr_pass_record& pr = t.passes[i];
        r.tiles_total += pr.tiles_total;
        r.tiles_skipped += pr.tiles_skipped;
        if (pr.pass >= kPresentMonPasses) continue;
        double& ms = r.pass_ms[pr.pass];
        ms = (std::isnan(ms) ? 0.0 : ms) + ms_between(pr.gpu_end_ns, pr.gpu_begin_ns);
    }
    if (csv_) std::fprintf(csv_, "%s\n", presentmon_row(r).c_str());
    ++rows_;
    fgsr_present_report rep{};
    rep.sequence = out.sequence;
    rep.output_index = out.output_index;
    rep.frame_type = t.frame_type;
    rep.flags = presented ? 0u : FGSR_REPORT_DROPPED;
    rep.submit_ns = t.submit_ns;
    rep.received_ns = received_ns;
    rep.presented_ns = presented ? received_ns : 0;
    // The application's frame of a submit that failed as a whole.
    if (t.frame_type == FGSR_FRAME_NONE) rep.output_index = FGSR_REPORT_APPLICATION;
    reports_.push_back(rep);
}

Result<void> ReplayPresenter::flush() {
    if (!reports_.empty() && reports_supported_) {
        const fgsr_status s = session_.report_presents(reports_.data(), uint32_t(reports_.size()));
        if (s == FGSR_STATUS_UNSUPPORTED)
            reports_supported_ = false; // a daemon before protocol minor 3
        else if (s != FGSR_STATUS_OK)
            return make_error(Errc::io, std::string("reporting presents to fgsrd: ") + fgsr_status_string(s));
    }
    reports_.clear();
    if (csv_ && std::ferror(csv_)) return make_error(Errc::io, "cannot write the telemetry CSV");
    return {};
}

} // namespace fgsr::cli
