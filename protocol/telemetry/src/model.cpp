#include <fgsr/telemetry/model.hpp>

#include <fgsr/core/frame_stats.hpp>

#include <cmath>
#include <limits>

namespace fgsr::telemetry {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// JSON has no NaN: unknown values are null.
nlohmann::json rounded(double v, double scale) {
    return std::isfinite(v) ? nlohmann::json(std::round(v * scale) / scale) : nlohmann::json(nullptr);
}

LatencyFigures latency(const std::vector<double>& v) {
    const Percentiles p = percentiles(v);
    return {p.p50, p.p90, p.p99, p.count};
}

nlohmann::json latency_json(const LatencyFigures& l) {
    if (l.count == 0) return nullptr;
    return {{"p50", rounded(l.p50, 1000)}, {"p90", rounded(l.p90, 1000)}, {"p99", rounded(l.p99, 1000)},
            {"count", l.count}};
}

} // namespace

FrameRecord::FrameRecord()
    : ft_ms(kNaN), lat_d_ms(kNaN), lat_c_ms(kNaN), disp_ms(kNaN), gpu_ms(kNaN), c2p_ms(kNaN) {}

Summary::Summary() : avg_fps(kNaN), low1_fps(kNaN), low01_fps(kNaN) {
    daemon = client = displayed = click_to_photon = {kNaN, kNaN, kNaN, 0};
}

const char* frame_type_label(uint32_t type) {
    switch (type) {
    case FGSR_FRAME_UPSCALED: return "Upscaled";
    case FGSR_FRAME_INTERPOLATED: return "Interpolated";
    case FGSR_FRAME_EXTRAPOLATED: return "Extrapolated";
    default: return "Application";
    }
}

std::string mode_label(uint32_t modes) {
    std::string s;
    auto add = [&](uint32_t bit, const char* name) {
        if (!(modes & bit)) return;
        if (!s.empty()) s += '+';
        s += name;
    };
    add(FGSR_MODE_INTERPOLATE, "interpolate");
    add(FGSR_MODE_EXTRAPOLATE, "extrapolate");
    add(FGSR_MODE_SR, "sr");
    return s.empty() ? "none" : s;
}

std::vector<std::string> pass_names() {
    return {
#define FGSR_TELEMETRY_NAME_(ID, name, value) #name,
        FGSR_PASSES(FGSR_TELEMETRY_NAME_)
#undef FGSR_TELEMETRY_NAME_
    };
}

Summary summarize(std::span<const FrameRecord> frames, std::span<const SessionInfo> sessions) {
    Summary s;
    std::vector<double> ft, d, c, disp, c2p;
    for (const FrameRecord& r : frames) {
        if (std::isfinite(r.ft_ms)) ft.push_back(r.ft_ms);
        if (std::isfinite(r.lat_d_ms)) d.push_back(r.lat_d_ms);
        if (std::isfinite(r.lat_c_ms)) c.push_back(r.lat_c_ms);
        if (std::isfinite(r.disp_ms)) disp.push_back(r.disp_ms);
        if (std::isfinite(r.c2p_ms)) c2p.push_back(r.c2p_ms);
    }
    const FrameRate fr = frame_rate(ft);
    s.frames = fr.frames;
    s.avg_fps = fr.avg_fps;
    s.low1_fps = fr.low1_fps;
    s.low01_fps = fr.low01_fps;
    s.daemon = latency(d);
    s.client = latency(c);
    s.displayed = latency(disp);
    s.click_to_photon = latency(c2p);
    for (const SessionInfo& i : sessions) {
        s.dropped += i.dropped;
        s.rejected += i.rejected;
        s.tiles_total += i.tiles_total;
        s.tiles_skipped += i.tiles_skipped;
        s.frames_total += i.frames;
    }
    return s;
}

nlohmann::json record_json(const FrameRecord& r) {
    nlohmann::json j = {{"s", r.session},
                        {"k", r.kind == Kind::present ? "present" : r.kind == Kind::output ? "output" : "probe"},
                        {"t", rounded(r.t_s, 1e6)},
                        {"type", frame_type_label(r.type)},
                        {"ft", rounded(r.ft_ms, 1000)},
                        {"lat_d", rounded(r.lat_d_ms, 1000)},
                        {"lat_c", rounded(r.lat_c_ms, 1000)},
                        {"disp", rounded(r.disp_ms, 1000)},
                        {"gpu", rounded(r.gpu_ms, 1000)},
                        {"c2p", rounded(r.c2p_ms, 1000)}};
    if (r.has_passes) {
        nlohmann::json p = nlohmann::json::array();
        for (float v : r.pass_ms) p.push_back(rounded(double(v), 1000));
        j["p"] = std::move(p);
    } else {
        j["p"] = nullptr;
    }
    return j;
}

nlohmann::json session_json(const SessionInfo& s) {
    return {{"id", s.id},
            {"application", s.application},
            {"client", s.client},
            {"pid", s.pid},
            {"mode", s.mode},
            {"width", s.width},
            {"height", s.height},
            {"output_width", s.output_width},
            {"output_height", s.output_height},
            {"colour_only", s.colour_only},
            {"fast_motion", s.fast_motion},
            {"active", s.active},
            {"frames", s.frames},
            {"generated", s.generated},
            {"dropped", s.dropped},
            {"rejected", s.rejected},
            {"tiles_total", s.tiles_total},
            {"tiles_skipped", s.tiles_skipped}};
}

nlohmann::json summary_json(const Summary& s) {
    return {{"frames", s.frames},
            {"avg_fps", rounded(s.avg_fps, 100)},
            {"low1_fps", rounded(s.low1_fps, 100)},
            {"low01_fps", rounded(s.low01_fps, 100)},
            {"latency_ms",
             {{"daemon", latency_json(s.daemon)},
              {"client", latency_json(s.client)},
              {"displayed", latency_json(s.displayed)},
              {"click_to_photon", latency_json(s.click_to_photon)}}},
            {"dropped", s.dropped},
            {"rejected", s.rejected},
            {"tiles_total", s.tiles_total},
            {"tiles_skipped", s.tiles_skipped},
            {"frames_total", s.frames_total}};
}

nlohmann::json state_json(const StateHeader& h, std::span<const SessionInfo> sessions, const Summary& summary,
                          std::optional<std::span<const FrameRecord>> frames) {
    nlohmann::json j = {{"source", h.source},
                        {"title", h.title},
                        {"passes", pass_names()},
                        {"now", rounded(h.now_s, 1e6)},
                        {"window_s", h.window_s},
                        {"summary", summary_json(summary)}};
    nlohmann::json ss = nlohmann::json::array();
    for (const SessionInfo& s : sessions) ss.push_back(session_json(s));
    j["sessions"] = std::move(ss);
    if (frames) {
        nlohmann::json fs = nlohmann::json::array();
        for (const FrameRecord& r : *frames) fs.push_back(record_json(r));
        j["frames"] = std::move(fs);
    }
    return j;
}

} // namespace fgsr::telemetry
