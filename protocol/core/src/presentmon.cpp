#include <fgsr/core/presentmon.hpp>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>

namespace fgsr {

namespace {

constexpr double kNA = std::numeric_limits<double>::quiet_NaN();

constexpr const char* kPassNames[] = {
#define FGSR_PM_NAME_(ID, name, value) #name,
    FGSR_PASSES(FGSR_PM_NAME_)
#undef FGSR_PM_NAME_
};

// Column ids, in file order.
enum Col : int {
    kApplication,
    kProcessId,
    kSwapChain,
    kRuntime,
    kPresentMode,
    kFrameType,
    kTime,
    kBetweenPresents,
    kBetweenDisplayChange,
    kInPresentApi,
    kUntilRenderComplete,
    kUntilDisplayed,
    kGpuTime,
    kClickToPhoton,
    kSequence,
    kOutputIndex,
    kStatus,
    kTargetTime,
    kIntended,
    kCall,
    kDaemonLatency,
    kClientLatency,
    kQueueWait,
    kDaemonCpu,
    kSkippedPasses,
    kTilesTotal,
    kTilesSkipped,
    kFirstPass
};

constexpr const char* kColumns[kFirstPass] = {
    "Application",       "ProcessID",          "SwapChainAddress",       "PresentRuntime",
    "PresentMode",       "FrameType",          "TimeInSeconds",          "MsBetweenPresents",
    "MsBetweenDisplayChange", "MsInPresentAPI", "MsUntilRenderComplete", "MsUntilDisplayed",
    "MsGPUTime",         "MsClickToPhotonLatency", "fgsr_sequence",      "fgsr_output_index",
    "fgsr_status",       "fgsr_target_time",   "fgsr_intended_s",        "fgsr_call_s",
    "fgsr_daemon_latency_ms",
    "fgsr_client_latency_ms", "fgsr_queue_wait_ms", "fgsr_daemon_cpu_ms", "fgsr_skipped_passes",
    "fgsr_tiles_total",  "fgsr_tiles_skipped"};

std::string pass_column(size_t p) {
    return std::string("fgsr_") + kPassNames[p] + "_ms";
}

void put_text(std::string& out, std::string_view s) {
    if (s.find_first_of(",\"\n\r") == std::string_view::npos) {
        out += s;
        return;
    }
    out += '"';
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    out += '"';
}

void put_number(std::string& out, double v, const char* format) {
    if (!std::isfinite(v)) {
        out += "NA";
        return;
    }
    char buf[64];
    std::snprintf(buf, sizeof(buf), format, v);
    out += buf;
}

// Splits one CSV line (quotes as RFC 4180; no line breaks inside fields).
std::vector<std::string> split(std::string_view line) {
    std::vector<std::string> f(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                f.back() += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                f.back() += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            f.emplace_back();
        } else if (c != '\r') {
            f.back() += c;
        }
    }
    return f;
}

bool parse_double(const std::string& s, double& out) {
    if (s.empty() || s == "NA") {
        out = kNA;
        return true;
    }
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return end && *end == '\0';
}

bool parse_u64(const std::string& s, uint64_t& out) {
    if (s.empty() || s == "NA") {
        out = 0;
        return true;
    }
    char* end = nullptr;
    out = std::strtoull(s.c_str(), &end, 0);
    return end && *end == '\0' && s[0] != '-';
}

} // namespace

PresentRow::PresentRow()
    : time_s(kNA), ms_between_presents(kNA), ms_between_display_change(kNA), ms_in_present_api(kNA),
      ms_until_render_complete(kNA), ms_until_displayed(kNA), ms_gpu_time(kNA), ms_click_to_photon(kNA),
      target_time(kNA), daemon_latency_ms(kNA), client_latency_ms(kNA), queue_wait_ms(kNA), daemon_cpu_ms(kNA),
      intended_s(kNA), call_s(kNA) {
    pass_ms.fill(kNA);
}

const char* presentmon_frame_type(uint32_t t) {
    switch (t) {
    case 1: return "fgsr-upscaled";
    case 2: return "fgsr-interpolated";
    case 3: return "fgsr-extrapolated";
    default: return "Application";
    }
}

std::string presentmon_header() {
    std::string h;
    for (int c = 0; c < kFirstPass; ++c) {
        if (c) h += ',';
        h += kColumns[c];
    }
    for (size_t p = 0; p < kPresentMonPasses; ++p) h += ',' + pass_column(p);
    return h;
}

std::string presentmon_row(const PresentRow& r) {
    const bool app = r.frame_type == "Application";
    std::string o;
    o.reserve(400);
    put_text(o, r.application);
    char buf[64];
    std::snprintf(buf, sizeof(buf), ",%" PRIu32 ",0x%016" PRIX64 ",", r.process_id, r.swapchain);
    o += buf;
    put_text(o, r.runtime);
    o += ',';
    put_text(o, r.present_mode);
    o += ',';
    put_text(o, r.frame_type);
    o += ',';
    put_number(o, r.time_s, "%.9f");
    for (double v : {r.ms_between_presents, r.ms_between_display_change, r.ms_in_present_api,
                     r.ms_until_render_complete, r.ms_until_displayed, r.ms_gpu_time, r.ms_click_to_photon}) {
        o += ',';
        put_number(o, v, "%.4f");
    }
    std::snprintf(buf, sizeof(buf), ",%" PRIu64 ",", r.sequence);
    o += buf;
    if (app)
        o += "NA";
    else
        o += std::to_string(r.output_index);
    o += ',';
    put_text(o, r.status);
    o += ',';
    put_number(o, app ? kNA : r.target_time, "%.6g");
    o += ',';
    put_number(o, r.intended_s, "%.9f");
    o += ',';
    put_number(o, r.call_s, "%.9f");
    for (double v : {r.daemon_latency_ms, r.client_latency_ms, r.queue_wait_ms, r.daemon_cpu_ms}) {
        o += ',';
        put_number(o, v, "%.4f");
    }
    std::snprintf(buf, sizeof(buf), ",%" PRIu32 ",%" PRIu32 ",%" PRIu32, r.skipped_passes, r.tiles_total,
                  r.tiles_skipped);
    o += buf;
    for (double v : r.pass_ms) {
        o += ',';
        put_number(o, v, "%.4f");
    }
    return o;
}

Result<std::vector<PresentRow>> parse_presentmon_csv(std::string_view text) {
    std::vector<PresentRow> rows;
    std::map<std::string, int> known;
    for (int c = 0; c < kFirstPass; ++c) known[kColumns[c]] = c;
    for (size_t p = 0; p < kPresentMonPasses; ++p) known[pass_column(p)] = kFirstPass + int(p);
    known["Runtime"] = kRuntime; // PresentMon 1.x
    std::vector<int> cols;       // column id per field (-1: ignored)
    size_t line_no = 0, pos = 0;
    bool have_time = false, have_type = false;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        const std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        if (line.empty() || line == "\r") continue;
        std::vector<std::string> f = split(line);
        if (cols.empty()) {
            for (const std::string& name : f) {
                auto it = known.find(name);
                cols.push_back(it == known.end() ? -1 : it->second);
                have_time |= it != known.end() && it->second == kTime;
                have_type |= it != known.end() && (it->second == kFrameType || it->second == kBetweenPresents);
            }
            if (!have_time || !have_type)
                return make_error(Errc::io, "line 1: not a PresentMon CSV (needs TimeInSeconds and FrameType "
                                            "or MsBetweenPresents)");
            continue;
        }
        if (f.size() != cols.size())
            return make_error(Errc::io, "line " + std::to_string(line_no) + ": " + std::to_string(f.size()) +
                                            " fields, the header has " + std::to_string(cols.size()));
        PresentRow r;
        for (size_t i = 0; i < f.size(); ++i) {
            const int c = cols[i];
            const std::string& v = f[i];
            bool ok = true;
            uint64_t u = 0;
            switch (c) {
            case -1: break;
            case kApplication: r.application = v; break;
            case kProcessId: ok = parse_u64(v, u) && u <= UINT32_MAX; r.process_id = uint32_t(u); break;
            case kSwapChain: ok = parse_u64(v, r.swapchain); break;
            case kRuntime: r.runtime = v; break;
            case kPresentMode: r.present_mode = v; break;
            case kFrameType: r.frame_type = v.empty() || v == "NA" ? "Application" : v; break;
            case kTime: ok = parse_double(v, r.time_s); break;
            case kBetweenPresents: ok = parse_double(v, r.ms_between_presents); break;
            case kBetweenDisplayChange: ok = parse_double(v, r.ms_between_display_change); break;
            case kInPresentApi: ok = parse_double(v, r.ms_in_present_api); break;
            case kUntilRenderComplete: ok = parse_double(v, r.ms_until_render_complete); break;
            case kUntilDisplayed: ok = parse_double(v, r.ms_until_displayed); break;
            case kGpuTime: ok = parse_double(v, r.ms_gpu_time); break;
            case kClickToPhoton: ok = parse_double(v, r.ms_click_to_photon); break;
            case kSequence: ok = parse_u64(v, r.sequence); break;
            case kOutputIndex: ok = parse_u64(v, u) && u <= UINT32_MAX; r.output_index = uint32_t(u); break;
            case kStatus: r.status = v; break;
            case kTargetTime: ok = parse_double(v, r.target_time); break;
            case kIntended: ok = parse_double(v, r.intended_s); break;
            case kCall: ok = parse_double(v, r.call_s); break;
            case kDaemonLatency: ok = parse_double(v, r.daemon_latency_ms); break;
            case kClientLatency: ok = parse_double(v, r.client_latency_ms); break;
            case kQueueWait: ok = parse_double(v, r.queue_wait_ms); break;
            case kDaemonCpu: ok = parse_double(v, r.daemon_cpu_ms); break;
            case kSkippedPasses: ok = parse_u64(v, u) && u <= UINT32_MAX; r.skipped_passes = uint32_t(u); break;
            case kTilesTotal: ok = parse_u64(v, u) && u <= UINT32_MAX; r.tiles_total = uint32_t(u); break;
            case kTilesSkipped: ok = parse_u64(v, u) && u <= UINT32_MAX; r.tiles_skipped = uint32_t(u); break;
            default: ok = parse_double(v, r.pass_ms[size_t(c - kFirstPass)]); break;
            }
            if (!ok)
                return make_error(Errc::io, "line " + std::to_string(line_no) + ": bad value '" + v + "'");
        }
        rows.push_back(std::move(r));
    }
    if (cols.empty()) return make_error(Errc::io, "empty file: no header line");
    return rows;
}

} // namespace fgsr
