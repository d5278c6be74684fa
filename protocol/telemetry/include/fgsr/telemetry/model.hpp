// The dashboard's data model: what fgsrd's telemetry hub keeps per frame and per session, the
// headline figures over a window of frames, and the JSON that the dashboard page reads (live from
// fgsrd's /events and /api/state, or inlined by `fgsr report` for a recorded run). One model for
// both, so that a recorded run and a live one show the same figures. docs/TELEMETRY.md describes
// the JSON.
#pragma once

#include <fgsr/protocol.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace fgsr::telemetry {

// A frame the hub heard of: a present the client reported (kind present: displayed, real or
// generated), an output the daemon wrote (kind output), or a hardware probe's click-to-photon
// sample (kind probe: session 0, c2p_ms set). Milliseconds; NaN where unknown.
enum class Kind : uint8_t { present, output, probe };

struct FrameRecord {
    uint32_t session = 0;
    Kind kind = Kind::output;
    uint32_t type = FGSR_FRAME_NONE; // fgsr_frame_type; FGSR_FRAME_NONE = the application's own frame
    double t_s = 0;                  // when it was displayed (present) or written (output), seconds
    double ft_ms;     // since the previous frame of the session's timeline (NaN: not on it / first)
    double lat_d_ms;  // daemon: submit to output written
    double lat_c_ms;  // client-observed: submit to the client holding the output
    double disp_ms;   // submit to displayed
    double gpu_ms;    // GPU time of the frame
    double c2p_ms;    // click to photon (hardware probe)
    bool has_passes = false;
    std::array<float, FGSR_PASS_COUNT_> pass_ms{}; // per pass id, 0 where it did not run
    uint32_t tiles_total = 0, tiles_skipped = 0;
    uint64_t sequence = 0;
    uint32_t output_index = 0;
    FrameRecord();
};

struct SessionInfo {
    uint32_t id = 0;
    std::string application; // executable name
    std::string client;      // the name the client gave (HELLO)
    uint32_t pid = 0;
    std::string mode; // "interpolate", "extrapolate", "sr", joined with '+'
    uint32_t width = 0, height = 0, output_width = 0, output_height = 0;
    bool colour_only = false;
    bool fast_motion = false; // colour only, motion estimated without refinement (FGSR_SESSION_FAST_MOTION)
    bool active = true;
    uint64_t frames = 0;    // frames on the session's timeline (displayed, or outputs without reports)
    uint64_t generated = 0; // generated frames (outputs the daemon wrote)
    uint64_t dropped = 0, rejected = 0;
    uint64_t tiles_total = 0, tiles_skipped = 0;
};

struct LatencyFigures {
    double p50, p90, p99;
    size_t count;
};

struct Summary {
    size_t frames = 0; // timeline frames in the window
    double avg_fps, low1_fps, low01_fps;
    LatencyFigures daemon, client, displayed, click_to_photon;
    uint64_t dropped = 0, rejected = 0, tiles_total = 0, tiles_skipped = 0; // over the sessions
    uint64_t frames_total = 0;                                            // over the sessions' lives
    Summary();
};

// Headline figures over `frames` (the window) and `sessions` (their counters).
Summary summarize(std::span<const FrameRecord> frames, std::span<const SessionInfo> sessions);

// Pass names in pass-id order (the "passes" array every record's "p" is aligned to).
std::vector<std::string> pass_names();

nlohmann::json record_json(const FrameRecord& r);
nlohmann::json session_json(const SessionInfo& s);
nlohmann::json summary_json(const Summary& s);

struct StateHeader {
    std::string source; // "live" or "recorded"
    std::string title;
    double now_s = 0;
    double window_s = 0;
};
// The State object of the page (docs/TELEMETRY.md); frames included when given.
nlohmann::json state_json(const StateHeader& h, std::span<const SessionInfo> sessions, const Summary& summary,
                          std::optional<std::span<const FrameRecord>> frames);

// "Application", "Interpolated", "Extrapolated", "Upscaled" (the page's type names).
const char* frame_type_label(uint32_t type);
// fgsr_session_desc.modes as "interpolate+sr" etc.
std::string mode_label(uint32_t modes);

} // namespace fgsr::telemetry
