// fgsrd's telemetry hub and the dashboard's pure parts, in process: present reports (checked,
// counted, kept), the frame timeline (outputs until a client reports presents, presents after),
// headline figures against frame times computed here, the Prometheus text, the Chrome trace, the
// FGSR_MSG_REPORT parser and the --http address rule.
#include "http_server.hpp"
#include "messages.hpp"
#include "telemetry_hub.hpp"

#include <fgsr/core/clock.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <utility>

namespace {

using fgsrd::TelemetryHub;

fgsr_session_desc desc_of(uint32_t w, uint32_t h) {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = w;
    d.height = h;
    d.modes = FGSR_MODE_INTERPOLATE;
    d.flags = FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH;
    return d;
}

fgsr_pool_layout layout_of(uint32_t w, uint32_t h) {
    fgsr_pool_layout l{};
    l.output_width = w;
    l.output_height = h;
    return l;
}

// An interpolated output completed at `complete_ns`, with two passes.
fgsr_completion_entry output(uint64_t seq, uint64_t submit_ns, uint64_t complete_ns) {
    fgsr_completion_entry c{};
    c.sequence = seq;
    c.status = FGSR_STATUS_OK;
    c.output_slot = 0;
    c.telemetry.frame_type = FGSR_FRAME_INTERPOLATED;
    c.telemetry.submit_ns = submit_ns;
    c.telemetry.complete_ns = complete_ns;
    c.telemetry.pass_count = 2;
    c.telemetry.passes[0] = {FGSR_PASS_SPLAT, 64, 16, 0, complete_ns - 3000000, complete_ns - 2000000};
    c.telemetry.passes[1] = {FGSR_PASS_GENERATE, 64, 32, 0, complete_ns - 2000000, complete_ns - 500000};
    c.telemetry.gpu_ns = 2500000;
    return c;
}

fgsr_present_report present(uint32_t type, uint64_t submit_ns, uint64_t presented_ns) {
    fgsr_present_report r{};
    r.sequence = 1;
    r.output_index = type == FGSR_FRAME_NONE ? FGSR_REPORT_APPLICATION : 0;
    r.frame_type = type;
    r.submit_ns = submit_ns;
    r.received_ns = submit_ns + 1000000;
    r.presented_ns = presented_ns;
    return r;
}

std::unique_ptr<TelemetryHub> hub_with_session(uint32_t id) {
    auto hub = std::make_unique<TelemetryHub>(fgsrd::HubOptions{60, 1 << 16, "test"});
    hub->session_opened(id, {"vkcube", "fgsr-layer (pid 7)", 7}, desc_of(64, 32), layout_of(64, 32));
    return hub;
}

// The session list says how each session gets its motion: given, from colour, from colour fast.
TEST(DaemonTelemetry, SessionsSayHowTheirMotionIsEstimated) {
    auto hub = std::make_unique<TelemetryHub>(fgsrd::HubOptions{60, 1 << 16, "test"});
    fgsr_session_desc given = desc_of(64, 32), colour = desc_of(64, 32), fast = desc_of(64, 32);
    given.flags = 0;
    fast.flags |= FGSR_SESSION_FAST_MOTION;
    hub->session_opened(1, {"a", "c1", 1}, given, layout_of(64, 32));
    hub->session_opened(2, {"b", "c2", 2}, colour, layout_of(64, 32));
    hub->session_opened(3, {"c", "c3", 3}, fast, layout_of(64, 32));
    const nlohmann::json s = hub->state(true);
    ASSERT_EQ(s["sessions"].size(), 3u);
    std::map<uint32_t, std::pair<bool, bool>> got;
    for (const auto& j : s["sessions"])
        got[j["id"].get<uint32_t>()] = {j["colour_only"].get<bool>(), j["fast_motion"].get<bool>()};
    EXPECT_EQ(got[1], std::make_pair(false, false));
    EXPECT_EQ(got[2], std::make_pair(true, false));
    EXPECT_EQ(got[3], std::make_pair(true, true));
}

TEST(DaemonTelemetry, OutputsAreTheTimelineUntilPresentsAreReported) {
    auto hub = hub_with_session(3);
    const uint64_t t0 = fgsr::monotonic_ns() - 2000000000ull; // two seconds ago
    for (uint64_t i = 0; i < 4; ++i) hub->completion(3, output(i + 1, t0 + i * 20000000, t0 + i * 20000000 + 5000000));
    nlohmann::json s = hub->state(true);
    ASSERT_EQ(s["frames"].size(), 4u);
    EXPECT_TRUE(s["frames"][0]["ft"].is_null()); // the first frame has no predecessor
    for (size_t i = 1; i < 4; ++i) EXPECT_NEAR(s["frames"][i]["ft"].get<double>(), 20.0, 1e-6);
    EXPECT_NEAR(s["frames"][1]["lat_d"].get<double>(), 5.0, 1e-6);
    EXPECT_NEAR(s["frames"][1]["p"][size_t(FGSR_PASS_SPLAT)].get<double>(), 1.0, 1e-6);
    EXPECT_NEAR(s["frames"][1]["p"][size_t(FGSR_PASS_GENERATE)].get<double>(), 1.5, 1e-6);
    EXPECT_EQ(s["sessions"][0]["application"], "vkcube");
    EXPECT_EQ(s["sessions"][0]["tiles_total"], 4 * 128);
    EXPECT_EQ(s["sessions"][0]["tiles_skipped"], 4 * 48);
    EXPECT_EQ(s["sessions"][0]["colour_only"], true);
    EXPECT_EQ(s["sessions"][0]["fast_motion"], false);

    // Presents reported: they become the timeline; outputs keep their latencies but no frame time.
    const uint64_t t1 = t0 + 100000000;
    const fgsr_present_report r[] = {present(FGSR_FRAME_INTERPOLATED, t1, t1 + 8000000),
                                     present(FGSR_FRAME_NONE, t1 + 10000000, t1 + 16000000)};
    EXPECT_EQ(hub->reports(3, r), 2u);
    hub->completion(3, output(9, t1 + 20000000, t1 + 25000000));
    s = hub->state(true);
    ASSERT_EQ(s["frames"].size(), 7u);
    EXPECT_EQ(s["frames"][4]["k"], "present");
    EXPECT_TRUE(s["frames"][4]["ft"].is_null());
    EXPECT_NEAR(s["frames"][5]["ft"].get<double>(), 8.0, 1e-6);
    EXPECT_NEAR(s["frames"][5]["disp"].get<double>(), 6.0, 1e-6);
    EXPECT_TRUE(s["frames"][5]["lat_c"].is_null()); // the application's own frame
    EXPECT_NEAR(s["frames"][4]["lat_c"].get<double>(), 1.0, 1e-6);
    EXPECT_EQ(s["frames"][5]["type"], "Application");
    EXPECT_TRUE(s["frames"][6]["ft"].is_null());
    EXPECT_EQ(s["sessions"][0]["frames"], 4 + 2);
}

TEST(DaemonTelemetry, ReportsWithValuesOutOfRangeAreCountedAndDropped) {
    auto hub = hub_with_session(1);
    const uint64_t now = fgsr::monotonic_ns();
    fgsr_present_report bad_type = present(FGSR_FRAME_NONE, now - 5000000, now - 1000000);
    bad_type.frame_type = 9;
    const fgsr_present_report before_submit = present(FGSR_FRAME_NONE, now - 1000000, now - 5000000);
    const fgsr_present_report future = present(FGSR_FRAME_NONE, now, now + 60'000'000'000ull);
    fgsr_present_report bad_flags = present(FGSR_FRAME_NONE, now - 5000000, now - 1000000);
    bad_flags.flags = 0x80;
    const fgsr_present_report never_presented = present(FGSR_FRAME_NONE, now - 5000000, 0);
    const fgsr_present_report good = present(FGSR_FRAME_NONE, now - 5000000, now - 1000000);
    const fgsr_present_report all[] = {bad_type, before_submit, future, bad_flags, never_presented, good};
    EXPECT_EQ(hub->reports(1, all), 1u);
    EXPECT_EQ(hub->reports(2, all), 0u); // no such session
    EXPECT_NE(hub->metrics_text().find("fgsr_reports_invalid_total 5"), std::string::npos);
    EXPECT_EQ(hub->state(true)["frames"].size(), 1u);
    // A dropped frame counts as dropped, not on the timeline.
    fgsr_present_report dropped = present(FGSR_FRAME_INTERPOLATED, now - 5000000, 0);
    dropped.flags = FGSR_REPORT_DROPPED;
    EXPECT_EQ(hub->reports(1, std::span(&dropped, 1)), 1u);
    const nlohmann::json s = hub->state(true);
    EXPECT_EQ(s["sessions"][0]["dropped"], 1);
    EXPECT_EQ(s["summary"]["dropped"], 1);
    EXPECT_EQ(s["frames"].size(), 1u);
}

TEST(DaemonTelemetry, HeadlineFiguresMatchFrameTimesComputedHere) {
    auto hub = hub_with_session(5);
    // 100 presents 10 ms apart, then one 50 ms gap and one more: 101 frame times.
    const uint64_t t0 = fgsr::monotonic_ns() - 3000000000ull;
    std::vector<fgsr_present_report> r;
    uint64_t t = t0;
    for (int i = 0; i <= 100; ++i, t += 10000000) r.push_back(present(FGSR_FRAME_NONE, t - 2000000, t));
    t += 40000000;
    r.push_back(present(FGSR_FRAME_NONE, t - 2000000, t));
    for (size_t i = 0; i < r.size(); i += 16)
        hub->reports(5, std::span(r.data() + i, std::min<size_t>(16, r.size() - i)));
    const nlohmann::json s = hub->state(false)["summary"];
    // 100 intervals of 10 ms and one of 50 ms.
    const double avg = 1000.0 * 101 / (100 * 10.0 + 50.0);
    EXPECT_NEAR(s["avg_fps"].get<double>(), avg, 0.01);
    EXPECT_NEAR(s["low1_fps"].get<double>(), 1000.0 / ((50.0 + 10.0) / 2), 0.01); // ceil(1.01) = 2 frames
    EXPECT_NEAR(s["low01_fps"].get<double>(), 20.0, 0.01);                       // the 50 ms frame
    EXPECT_NEAR(s["latency_ms"]["displayed"]["p50"].get<double>(), 2.0, 1e-6);
    EXPECT_EQ(s["frames"], 101);
}

TEST(DaemonTelemetry, MetricsAndTraceHoldEveryOutputAndPass) {
    auto hub = hub_with_session(2);
    const uint64_t t0 = fgsr::monotonic_ns() - 1000000000ull;
    for (uint64_t i = 0; i < 5; ++i) hub->completion(2, output(i + 1, t0 + i * 10000000, t0 + i * 10000000 + 4000000));
    fgsr_completion_entry dropped{};
    dropped.status = FGSR_STATUS_DROPPED;
    dropped.output_slot = FGSR_NO_SLOT;
    hub->completion(2, dropped);
    const std::string m = hub->metrics_text();
    EXPECT_NE(m.find("fgsr_outputs_total{type=\"interpolated\"} 5"), std::string::npos) << m;
    EXPECT_NE(m.find("fgsr_frames_dropped_total 1"), std::string::npos);
    EXPECT_NE(m.find("fgsr_gpu_seconds_count{pass=\"splat\"} 5"), std::string::npos);
    EXPECT_NE(m.find("fgsr_latency_seconds_count{kind=\"daemon\"} 5"), std::string::npos);
    EXPECT_NE(m.find("fgsr_sessions 1"), std::string::npos);
    const nlohmann::json tr = hub->trace(10);
    size_t complete = 0;
    for (const auto& e : tr["traceEvents"]) {
        if (e["ph"] != "X") continue;
        ++complete;
        EXPECT_TRUE(e["name"] == "splat" || e["name"] == "generate");
        EXPECT_GT(e["dur"].get<double>(), 0);
    }
    EXPECT_EQ(complete, 5u * 2u);
    hub->session_closed(2);
    EXPECT_NE(hub->metrics_text().find("fgsr_sessions 0"), std::string::npos);
    EXPECT_EQ(hub->state(false)["sessions"][0]["active"], false);
}

TEST(DaemonTelemetry, FramesSinceACursorAreEachSentOnce) {
    auto hub = hub_with_session(4);
    uint64_t cursor = 0;
    (void)hub->state(true, &cursor);
    EXPECT_EQ(cursor, 0u);
    const uint64_t t0 = fgsr::monotonic_ns() - 1000000000ull;
    hub->completion(4, output(1, t0, t0 + 4000000));
    hub->completion(4, output(2, t0 + 10000000, t0 + 14000000));
    EXPECT_EQ(hub->frames_since(cursor)["frames"].size(), 2u);
    EXPECT_EQ(hub->frames_since(cursor)["frames"].size(), 0u);
    hub->completion(4, output(3, t0 + 20000000, t0 + 24000000));
    EXPECT_EQ(hub->frames_since(cursor)["frames"].size(), 1u);
}

TEST(DaemonTelemetry, ProbeSamplesAreClickToPhotonLatency) {
    auto hub = hub_with_session(1);
    const uint64_t now = fgsr::monotonic_ns();
    std::vector<fgsr_probe_sample> s;
    for (uint64_t i = 0; i < 10; ++i) // 20, 21, ... 29 ms
        s.push_back({now - 1000000000 + i * 50000000, now - 1000000000 + i * 50000000 + (20 + i) * 1000000,
                     FGSR_PROBE_MODE_INTERPOLATE, 42});
    s.push_back({now - 5000000, now - 6000000, FGSR_PROBE_MODE_OFF, 0});   // photon before click
    s.push_back({now - 5000000, now - 4000000, 9, 0});                      // mode out of range
    s.push_back({now - 20'000'000'000ull, now - 1000000, FGSR_PROBE_MODE_OFF, 0}); // 20 s apart
    EXPECT_EQ(hub->probe_samples(s), 10u);
    const nlohmann::json st = hub->state(true);
    const auto& c2p = st["summary"]["latency_ms"]["click_to_photon"];
    EXPECT_NEAR(c2p["p50"].get<double>(), 24.0, 1e-6); // nearest rank of 20..29
    EXPECT_NEAR(c2p["p99"].get<double>(), 29.0, 1e-6);
    EXPECT_EQ(st["frames"].back()["k"], "probe");
    const std::string m = hub->metrics_text();
    EXPECT_NE(m.find("fgsr_click_to_photon_seconds_count{mode=\"interpolate\"} 10"), std::string::npos) << m;
    EXPECT_NE(m.find("fgsr_reports_invalid_total 3"), std::string::npos);
    fgsr_probe msg{};
    msg.count = 1;
    msg.samples[0] = s[0];
    msg.header = fgsr_msg_header_for(FGSR_MSG_PROBE, FGSR_PROBE_MESSAGE_SIZE(1), 0);
    auto r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&msg), FGSR_PROBE_MESSAGE_SIZE(1), true);
    ASSERT_NE(std::get_if<fgsrd::ProbeRequest>(&r), nullptr);
    EXPECT_EQ(std::get<fgsrd::ProbeRequest>(r).samples[0].photon_ns, s[0].photon_ns);
    msg.count = 2; // more than the packet holds
    r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&msg), FGSR_PROBE_MESSAGE_SIZE(1), true);
    EXPECT_NE(std::get_if<fgsrd::Violation>(&r), nullptr);
}

TEST(DaemonTelemetry, ReportMessagesAreParsedAndCheckedAgainstThePacket) {
    fgsr_hello hello{};
    (void)hello;
    fgsr_report m{};
    m.session_id = 7;
    m.count = 2;
    m.reports[1].presented_ns = 42;
    m.header = fgsr_msg_header_for(FGSR_MSG_REPORT, FGSR_REPORT_MESSAGE_SIZE(2), 0);
    auto r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&m), FGSR_REPORT_MESSAGE_SIZE(2), true);
    const auto* ok = std::get_if<fgsrd::ReportRequest>(&r);
    ASSERT_NE(ok, nullptr);
    EXPECT_EQ(ok->session_id, 7u);
    EXPECT_EQ(ok->count, 2u);
    EXPECT_EQ(ok->reports[1].presented_ns, 42u);
    // Fewer bytes than count reports.
    m.header.size = FGSR_REPORT_MESSAGE_SIZE(1);
    r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&m), FGSR_REPORT_MESSAGE_SIZE(1), true);
    ASSERT_NE(std::get_if<fgsrd::Violation>(&r), nullptr);
    EXPECT_NE(std::get<fgsrd::Violation>(r).reason.find("truncated"), std::string::npos);
    for (uint32_t count : {0u, FGSR_MAX_REPORTS_PER_MESSAGE + 1}) {
        m.count = count;
        m.header.size = sizeof(m);
        r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&m), sizeof(m), true);
        ASSERT_NE(std::get_if<fgsrd::Violation>(&r), nullptr);
        EXPECT_NE(std::get<fgsrd::Violation>(r).reason.find("report count"), std::string::npos);
    }
    // Before HELLO: a violation like any other message.
    m.count = 1;
    m.header.size = FGSR_REPORT_MESSAGE_SIZE(1);
    r = fgsrd::parse_request(reinterpret_cast<const std::byte*>(&m), FGSR_REPORT_MESSAGE_SIZE(1), false);
    ASSERT_NE(std::get_if<fgsrd::Violation>(&r), nullptr);
}

TEST(DaemonTelemetry, HttpAddressesAreLoopbackUnlessRemoteIsAllowed) {
    for (const char* a : {"127.0.0.1:0", "127.1.2.3:8080", "[::1]:9000", "localhost:80"})
        EXPECT_TRUE(fgsrd::parse_http_address(a, false)) << a;
    for (const char* a : {"0.0.0.0:8080", "192.168.1.5:80", "[::]:80", "example.org:80"}) {
        auto r = fgsrd::parse_http_address(a, false);
        ASSERT_FALSE(r) << a;
        EXPECT_NE(r.error().message.find("--http-allow-remote"), std::string::npos);
        EXPECT_TRUE(fgsrd::parse_http_address(a, true)) << a;
    }
    for (const char* a : {"127.0.0.1", "127.0.0.1:99999", ":80", "127.0.0.1:x", "[::1]80"})
        EXPECT_FALSE(fgsrd::parse_http_address(a, true)) << a;
    auto ep = fgsrd::parse_http_address("[::1]:9000", false);
    ASSERT_TRUE(ep);
    EXPECT_EQ(ep->host, "::1");
    EXPECT_EQ(ep->port, 9000);
}

} // namespace
