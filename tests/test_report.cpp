// Issue 13's recorded-run side: the frame statistics (fgsr/core/frame_stats.hpp) on analytic inputs,
// the PresentMon CSV (fgsr/core/presentmon.hpp: round trip, header, PresentMon 2.x's own files,
// errors that name the line), `fgsr report` on a CSV with known frame times (index.html with the
// data and Chart.js inlined, summary.json, the PNG plots), and `fgsr replay --telemetry` through a
// real fgsrd (display order, frame types, present times).
#include <fgsr/testing/fgsrd_process.hpp>

#include <fgsr/cli/replay.hpp>
#include <fgsr/cli/report.hpp>
#include <fgsr/core/frame_stats.hpp>
#include <fgsr/core/presentmon.hpp>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using fgsr::test::FgsrdProcess;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string read_text(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

struct TempDir {
    fs::path path;
    TempDir() {
        char tmpl[] = "/tmp/fgsr-report-test-XXXXXX";
        path = mkdtemp(tmpl);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

bool has_png_signature(const fs::path& p) {
    const std::string s = read_text(p);
    return s.size() > 8 && s.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0;
}

bool gnuplot_installed() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

// ---------------------------------------------------------------------------------------------
// frame_stats

TEST(ReportFrameStats, OneSlowFrameInAHundred) {
    std::vector<double> ft(99, 10.0);
    ft.push_back(100.0);
    const fgsr::FrameRate r = fgsr::frame_rate(ft);
    EXPECT_EQ(r.frames, 100u);
    EXPECT_NEAR(r.avg_fps, 1000.0 * 100 / 1090, 1e-9); // 100 frames in 1.09 s
    EXPECT_NEAR(r.low1_fps, 10.0, 1e-9);               // the slowest 1 % = one frame of 100 ms
    EXPECT_NEAR(r.low01_fps, 10.0, 1e-9);              // fewer than 1000 frames: the slowest frame alone
}

TEST(ReportFrameStats, LowsAverageTheSlowestShare) {
    // 1000 frames: 980 of 10 ms, 10 of 50 ms, 10 of 20 ms. 1 % = 10 frames: the ten of 50 ms;
    // 0.1 % = 1 frame of 50 ms.
    std::vector<double> ft(980, 10.0);
    ft.insert(ft.end(), 10, 50.0);
    ft.insert(ft.end(), 10, 20.0);
    const fgsr::FrameRate r = fgsr::frame_rate(ft);
    EXPECT_NEAR(r.avg_fps, 1000.0 * 1000 / (9800 + 500 + 200), 1e-9);
    EXPECT_NEAR(r.low1_fps, 20.0, 1e-9);
    EXPECT_NEAR(r.low01_fps, 20.0, 1e-9);
    // 2000 frames with 30 slow ones of 40 ms: 1 % = 20 frames of 40 ms (25 FPS).
    std::vector<double> ft2(1970, 10.0);
    ft2.insert(ft2.end(), 30, 40.0);
    EXPECT_NEAR(fgsr::frame_rate(ft2).low1_fps, 25.0, 1e-9);
}

TEST(ReportFrameStats, PercentilesAreNearestRank) {
    std::vector<double> v;
    for (int i = 100; i >= 1; --i) v.push_back(i); // order does not matter
    const fgsr::Percentiles p = fgsr::percentiles(v);
    EXPECT_EQ(p.p50, 50.0);
    EXPECT_EQ(p.p90, 90.0);
    EXPECT_EQ(p.p99, 99.0);
    EXPECT_EQ(p.count, 100u);
    EXPECT_EQ(fgsr::percentile(v, 1.0), 100.0);
    EXPECT_EQ(fgsr::percentile(v, 0.0), 1.0);
}

TEST(ReportFrameStats, EmptyIsNaNAndNaNSamplesAreIgnored) {
    const std::vector<double> none;
    EXPECT_TRUE(std::isnan(fgsr::percentile(none, 0.5)));
    const fgsr::FrameRate e = fgsr::frame_rate(none);
    EXPECT_TRUE(std::isnan(e.avg_fps));
    EXPECT_TRUE(std::isnan(e.low1_fps));
    EXPECT_TRUE(std::isnan(e.low01_fps));
    EXPECT_EQ(e.frames, 0u);
    const std::vector<double> only_nan = {kNaN, kNaN};
    EXPECT_TRUE(std::isnan(fgsr::percentiles(only_nan).p50));
    EXPECT_EQ(fgsr::percentiles(only_nan).count, 0u);

    const std::vector<double> with_nan = {kNaN, 3, 1, kNaN, 2};
    EXPECT_EQ(fgsr::percentile(with_nan, 0.5), 2.0); // of {1, 2, 3}
    EXPECT_EQ(fgsr::percentiles(with_nan).count, 3u);
    const std::vector<double> ft = {10, kNaN, 30};
    const fgsr::FrameRate r = fgsr::frame_rate(ft);
    EXPECT_EQ(r.frames, 2u);
    EXPECT_NEAR(r.avg_fps, 2000.0 / 40, 1e-9);
    EXPECT_NEAR(r.low1_fps, 1000.0 / 30, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// PresentMon CSV

TEST(ReportPresentMon, HeaderStartsWithPresentMonsColumnsInOrder) {
    const std::string h = fgsr::presentmon_header();
    const std::string expected_start =
        "Application,ProcessID,SwapChainAddress,PresentRuntime,PresentMode,FrameType,TimeInSeconds,"
        "MsBetweenPresents,MsBetweenDisplayChange,MsInPresentAPI,MsUntilRenderComplete,MsUntilDisplayed,"
        "MsGPUTime,MsClickToPhotonLatency,fgsr_";
    EXPECT_EQ(h.substr(0, expected_start.size()), expected_start) << h;
    EXPECT_NE(h.find(",fgsr_sequence,"), std::string::npos);
    EXPECT_NE(h.find(",fgsr_splat_ms"), std::string::npos);
    EXPECT_EQ(h.find('\n'), std::string::npos);
}

TEST(ReportPresentMon, RowRoundTrips) {
    fgsr::PresentRow r;
    r.application = "My \"Game\", Deluxe";
    r.process_id = 4242;
    r.swapchain = 0x1234abcdULL;
    r.runtime = "fgsr-replay";
    r.frame_type = "fgsr-interpolated";
    r.time_s = 12345.678901234;
    r.ms_between_presents = 8.25;
    r.ms_until_displayed = 21.5;
    r.ms_gpu_time = 1.75;
    r.sequence = 17;
    r.output_index = 2;
    r.status = "OK";
    r.target_time = 0.5;
    r.daemon_latency_ms = 3.125;
    r.client_latency_ms = 4.5;
    r.skipped_passes = 6;
    r.tiles_total = 100;
    r.tiles_skipped = 40;
    r.pass_ms[FGSR_PASS_SPLAT] = 0.25;
    const std::string csv = fgsr::presentmon_header() + "\n" + fgsr::presentmon_row(r) + "\n";
    auto rows = fgsr::parse_presentmon_csv(csv);
    ASSERT_TRUE(rows) << rows.error().message;
    ASSERT_EQ(rows->size(), 1u);
    const fgsr::PresentRow& b = (*rows)[0];
    EXPECT_EQ(b.application, r.application);
    EXPECT_EQ(b.process_id, r.process_id);
    EXPECT_EQ(b.swapchain, r.swapchain);
    EXPECT_EQ(b.runtime, r.runtime);
    EXPECT_EQ(b.present_mode, "NA");
    EXPECT_EQ(b.frame_type, r.frame_type);
    EXPECT_NEAR(b.time_s, r.time_s, 1e-9);
    EXPECT_DOUBLE_EQ(b.ms_between_presents, 8.25);
    EXPECT_DOUBLE_EQ(b.ms_until_displayed, 21.5);
    EXPECT_DOUBLE_EQ(b.ms_gpu_time, 1.75);
    EXPECT_EQ(b.sequence, 17u);
    EXPECT_EQ(b.output_index, 2u);
    EXPECT_EQ(b.status, "OK");
    EXPECT_DOUBLE_EQ(b.target_time, 0.5);
    EXPECT_DOUBLE_EQ(b.daemon_latency_ms, 3.125);
    EXPECT_DOUBLE_EQ(b.client_latency_ms, 4.5);
    EXPECT_EQ(b.skipped_passes, 6u);
    EXPECT_EQ(b.tiles_total, 100u);
    EXPECT_EQ(b.tiles_skipped, 40u);
    EXPECT_DOUBLE_EQ(b.pass_ms[FGSR_PASS_SPLAT], 0.25);
    // What was NA stays NaN.
    EXPECT_TRUE(std::isnan(b.ms_between_display_change));
    EXPECT_TRUE(std::isnan(b.ms_in_present_api));
    EXPECT_TRUE(std::isnan(b.ms_until_render_complete));
    EXPECT_TRUE(std::isnan(b.ms_click_to_photon));
    EXPECT_TRUE(std::isnan(b.queue_wait_ms));
    EXPECT_TRUE(std::isnan(b.intended_s));
    EXPECT_TRUE(std::isnan(b.pass_ms[FGSR_PASS_INGEST]));
    EXPECT_TRUE(std::isnan(b.pass_ms[FGSR_PASS_BLEND]));
}

// PresentMon 2.x's own column set (its console application's default CSV, abridged values).
const char* kPresentMon2Csv =
    "Application,ProcessID,SwapChainAddress,PresentRuntime,SyncInterval,PresentFlags,AllowsTearing,"
    "PresentMode,FrameType,TimeInSeconds,MsBetweenSimulationStart,MsBetweenPresents,"
    "MsBetweenDisplayChange,MsInPresentAPI,MsRenderPresentLatency,MsUntilDisplayed,MsPCLatency,"
    "CPUStartTime,MsBetweenAppStart,MsCPUBusy,MsCPUWait,MsGPULatency,MsGPUTime,MsGPUBusy,MsVideoBusy,"
    "MsGPUWait,MsAnimationError,AnimationTime,MsFlipDelay,MsAllInputToPhotonLatency,"
    "MsClickToPhotonLatency\r\n"
    "Game.exe,1234,0x0000021F5A3C8E10,DXGI,0,0,1,Hardware: Independent Flip,Application,1.000000,NA,"
    "16.6667,16.6667,0.1023,10.2500,20.5000,NA,0.9833,16.6667,12.1000,4.5667,1.2000,9.8000,9.8000,0.0000,"
    "0.0000,NA,0.983300,NA,NA,NA\r\n"
    "Game.exe,1234,0x0000021F5A3C8E10,DXGI,0,0,1,Hardware: Independent Flip,Repeated,1.008333,NA,"
    "8.3333,8.3333,0.0500,NA,12.2000,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA,NA\r\n"
    "Game.exe,1234,0x0000021F5A3C8E10,DXGI,0,0,1,Hardware: Independent Flip,Application,1.016667,NA,"
    "8.3333,8.3333,0.1100,10.0000,20.0000,NA,1.0000,16.6667,12.0000,4.6667,1.1000,9.5000,9.5000,0.0000,"
    "0.0000,NA,1.000000,NA,NA,45.5000\r\n"
    "Other.exe,99,0x0000000000000ABC,Vulkan,1,0,0,Composed: Flip,Application,1.020000,NA,"
    "33.3333,NA,0.2000,NA,NA,NA,NA,NA,NA,NA,NA,2.0000,2.0000,0.0000,0.0000,NA,NA,NA,NA,NA\r\n";

TEST(ReportPresentMon, ParsesPresentMon2Files) {
    auto rows = fgsr::parse_presentmon_csv(kPresentMon2Csv);
    ASSERT_TRUE(rows) << rows.error().message;
    ASSERT_EQ(rows->size(), 4u);
    const fgsr::PresentRow& a = (*rows)[0];
    EXPECT_EQ(a.application, "Game.exe");
    EXPECT_EQ(a.process_id, 1234u);
    EXPECT_EQ(a.swapchain, 0x0000021F5A3C8E10ULL);
    EXPECT_EQ(a.runtime, "DXGI");
    EXPECT_EQ(a.present_mode, "Hardware: Independent Flip");
    EXPECT_EQ(a.frame_type, "Application");
    EXPECT_DOUBLE_EQ(a.time_s, 1.0);
    EXPECT_DOUBLE_EQ(a.ms_between_presents, 16.6667);
    EXPECT_DOUBLE_EQ(a.ms_in_present_api, 0.1023);
    EXPECT_DOUBLE_EQ(a.ms_until_displayed, 20.5);
    EXPECT_DOUBLE_EQ(a.ms_gpu_time, 9.8);
    EXPECT_TRUE(std::isnan(a.ms_until_render_complete)); // not a PresentMon 2.x column
    EXPECT_TRUE(std::isnan(a.daemon_latency_ms));        // fgsr's columns are absent: NA
    EXPECT_EQ((*rows)[1].frame_type, "Repeated");
    EXPECT_TRUE(std::isnan((*rows)[1].ms_gpu_time));
    EXPECT_DOUBLE_EQ((*rows)[2].ms_click_to_photon, 45.5);
    EXPECT_EQ((*rows)[3].runtime, "Vulkan");

    // As the report reads it: two sessions; Repeated counts as a generated frame.
    const fgsr::cli::ReportData d = fgsr::cli::report_data(*rows);
    ASSERT_EQ(d.sessions.size(), 2u);
    EXPECT_EQ(d.sessions[0].application, "Game.exe");
    EXPECT_EQ(d.sessions[0].frames, 3u);
    EXPECT_EQ(d.sessions[0].generated, 1u);
    EXPECT_EQ(d.sessions[1].frames, 1u);
    ASSERT_EQ(d.frames.size(), 4u);
    EXPECT_EQ(d.frames[0].type, uint32_t(FGSR_FRAME_NONE));
    EXPECT_EQ(d.frames[1].type, uint32_t(FGSR_FRAME_INTERPOLATED));
    EXPECT_TRUE(std::isnan(d.frames[0].ft_ms)); // first of its session
    EXPECT_DOUBLE_EQ(d.frames[1].ft_ms, 8.3333);
    EXPECT_TRUE(std::isnan(d.frames[3].ft_ms)); // first of the second session
    EXPECT_NEAR(d.frames[3].t_s, 0.02, 1e-9);
    EXPECT_NEAR(d.duration_s, 0.02, 1e-9);
    // Frame times 8.3333 and 8.3333 ms.
    EXPECT_NEAR(d.summary.avg_fps, 1000.0 / 8.3333, 1e-6);
    EXPECT_EQ(d.summary.displayed.count, 3u);
    EXPECT_DOUBLE_EQ(d.summary.displayed.p50, 20.0); // of 12.2, 20.0, 20.5
    EXPECT_EQ(d.summary.click_to_photon.count, 1u);
}

TEST(ReportPresentMon, MalformedLinesAreNamed) {
    const std::string h = "Application,ProcessID,TimeInSeconds,MsBetweenPresents\n";
    auto wrong_count = fgsr::parse_presentmon_csv(h + "a,1,1.0,16.6\nb,1,1.1\n");
    ASSERT_FALSE(wrong_count);
    EXPECT_NE(wrong_count.error().message.find("line 3"), std::string::npos) << wrong_count.error().message;
    auto bad_number = fgsr::parse_presentmon_csv(h + "a,1,one,16.6\n");
    ASSERT_FALSE(bad_number);
    EXPECT_NE(bad_number.error().message.find("line 2"), std::string::npos) << bad_number.error().message;
    auto no_time = fgsr::parse_presentmon_csv("Application,ProcessID\na,1\n");
    ASSERT_FALSE(no_time);
    EXPECT_NE(no_time.error().message.find("line 1"), std::string::npos) << no_time.error().message;
    EXPECT_FALSE(fgsr::parse_presentmon_csv(""));
}

// ---------------------------------------------------------------------------------------------
// fgsr report on a CSV with known frame times

// Session A (pid 100): 200 displayed rows alternating Application / fgsr-interpolated, frame times
// 10 ms but two of 40 ms; the interpolated rows' daemon latencies are 1, 2, ..., 100 ms. Session B
// (pid 200, interleaved): 10 rows 20 ms apart, its first MsBetweenPresents a bogus 999 (the first
// row of a session has no frame time). Plus 3 DROPPED rows and 1 NOT_READY row.
std::string known_csv() {
    std::string csv = fgsr::presentmon_header() + "\n";
    double ta = 1000.0, tb = 1000.0005;
    int b_rows = 0;
    auto b_row = [&]() {
        fgsr::PresentRow r;
        r.application = "other";
        r.process_id = 200;
        r.runtime = "fgsr-replay";
        r.time_s = tb;
        r.ms_between_presents = b_rows == 0 ? 999.0 : 20.0;
        r.ms_until_displayed = 5.0;
        r.sequence = uint64_t(b_rows + 1);
        csv += fgsr::presentmon_row(r) + "\n";
        tb += 0.020;
        ++b_rows;
    };
    for (int k = 0; k < 200; ++k) {
        const double ft = (k == 50 || k == 150) ? 40.0 : 10.0;
        if (k > 0) ta += ft / 1000;
        fgsr::PresentRow r;
        r.application = "game</script><!--x";
        r.process_id = 100;
        r.swapchain = 7;
        r.runtime = "fgsr-replay";
        r.time_s = ta;
        r.ms_between_presents = k == 0 ? kNaN : ft;
        r.ms_until_displayed = 30.0;
        r.sequence = uint64_t(k / 2 + 1);
        if (k % 2 == 1) {
            r.frame_type = "fgsr-interpolated";
            r.output_index = 0;
            r.daemon_latency_ms = double(k / 2 + 1); // 1 .. 100
            r.client_latency_ms = 12.0;
            r.ms_gpu_time = 2.0;
            r.target_time = 0.5;
            r.tiles_total = 10;
            r.tiles_skipped = 4;
            r.pass_ms[FGSR_PASS_INGEST] = 0.25;
            r.pass_ms[FGSR_PASS_SPLAT] = 0.5;
            r.pass_ms[FGSR_PASS_GENERATE] = 1.25;
        }
        csv += fgsr::presentmon_row(r) + "\n";
        if (k % 20 == 5 && b_rows < 10) b_row();
        if (k == 60 || k == 61 || k == 62 || k == 90) {
            fgsr::PresentRow f = r;
            f.frame_type = "fgsr-interpolated";
            f.status = k == 90 ? "NOT_READY" : "DROPPED";
            f.ms_between_presents = kNaN;
            f.ms_until_displayed = kNaN;
            f.daemon_latency_ms = 1000.0; // not displayed: in no figure
            f.tiles_total = 10;           // but their tiles count
            f.tiles_skipped = 4;
            csv += fgsr::presentmon_row(f) + "\n";
        }
    }
    while (b_rows < 10) b_row();
    return csv;
}

TEST(Report, WritesTheDashboardSummaryAndPlots) {
    TempDir dir;
    {
        std::ofstream f(dir.path / "run.csv", std::ios::binary);
        f << known_csv();
    }
    fgsr::cli::ReportOptions o;
    o.csv = dir.path / "run.csv";
    o.out = dir.path / "report";
    o.progress = false;
    auto r = fgsr::cli::run_report(o);
    ASSERT_TRUE(r) << r.error().message;

    // Independent expectations. Frame times of both sessions (the first row of each has none):
    // A: 197 x 10 ms + 2 x 40 ms, B: 9 x 20 ms.
    const double n = 197 + 2 + 9, sum = 197 * 10.0 + 2 * 40.0 + 9 * 20.0;
    const double avg = 1000 * n / sum;
    const double low1 = 1000.0 / ((40.0 + 40.0 + 20.0) / 3); // ceil(1 % of 208) = 3 slowest
    const double low01 = 1000.0 / 40.0;                      // ceil(0.1 % of 208) = 1 slowest

    const nlohmann::json s = nlohmann::json::parse(read_text(o.out / "summary.json"));
    const nlohmann::json& sum_j = s["summary"];
    EXPECT_NEAR(sum_j["avg_fps"].get<double>(), avg, 0.006) << s.dump(2);
    EXPECT_NEAR(sum_j["low1_fps"].get<double>(), low1, 0.006);
    EXPECT_NEAR(sum_j["low01_fps"].get<double>(), low01, 0.006);
    EXPECT_EQ(sum_j["frames"].get<int>(), 208);
    EXPECT_EQ(sum_j["dropped"].get<int>(), 3);
    EXPECT_EQ(sum_j["rejected"].get<int>(), 1);
    EXPECT_EQ(sum_j["tiles_total"].get<int>(), 100 * 10 + 4 * 10);
    EXPECT_EQ(sum_j["tiles_skipped"].get<int>(), 100 * 4 + 4 * 4);
    EXPECT_DOUBLE_EQ(sum_j["latency_ms"]["daemon"]["p50"].get<double>(), 50.0);
    EXPECT_DOUBLE_EQ(sum_j["latency_ms"]["daemon"]["p90"].get<double>(), 90.0);
    EXPECT_DOUBLE_EQ(sum_j["latency_ms"]["daemon"]["p99"].get<double>(), 99.0);
    EXPECT_DOUBLE_EQ(sum_j["latency_ms"]["client"]["p99"].get<double>(), 12.0);
    EXPECT_DOUBLE_EQ(sum_j["latency_ms"]["displayed"]["p50"].get<double>(), 30.0); // 200 of 30, 10 of 5
    EXPECT_TRUE(sum_j["latency_ms"]["click_to_photon"].is_null());
    ASSERT_EQ(s["sessions"].size(), 2u);
    const nlohmann::json& a = s["sessions"][0];
    EXPECT_EQ(a["pid"].get<int>(), 100);
    EXPECT_EQ(a["frames"].get<int>(), 200);
    EXPECT_EQ(a["generated"].get<int>(), 100);
    EXPECT_EQ(a["dropped"].get<int>(), 3);
    EXPECT_EQ(a["mode"].get<std::string>(), "interpolate");
    EXPECT_NEAR(a["summary"]["avg_fps"].get<double>(), 1000.0 * 199 / (197 * 10.0 + 80), 0.006);
    EXPECT_NEAR(a["summary"]["low1_fps"].get<double>(), 25.0, 1e-9); // ceil(1.99) = 2 of 40 ms
    const nlohmann::json& b = s["sessions"][1];
    EXPECT_EQ(b["pid"].get<int>(), 200);
    EXPECT_EQ(b["frames"].get<int>(), 10);
    EXPECT_NEAR(b["summary"]["avg_fps"].get<double>(), 50.0, 1e-9); // 999 ignored

    // The page: the data and Chart.js inlined, nothing in the data that ends the script element.
    const std::string html = read_text(o.out / "index.html");
    EXPECT_NE(html.find("<script>window.FGSR_DATA = {"), std::string::npos);
    EXPECT_NE(html.find("Chart.js v"), std::string::npos); // the library's banner
    EXPECT_EQ(html.find("<script src=\"chart.min.js\"></script>"), std::string::npos);
    EXPECT_NE(html.find("game<\\/script>"), std::string::npos);
    EXPECT_EQ(html.find("game</script>"), std::string::npos);
    EXPECT_EQ(html.find("<!--x"), std::string::npos);
    EXPECT_NE(html.find("\"source\":\"recorded\""), std::string::npos);
    EXPECT_NE(html.find("fgsr report: run.csv"), std::string::npos);
    // Every displayed frame is in the data: 210 records.
    const std::string marker = "<script>window.FGSR_DATA = ";
    const size_t script_at = html.find(marker);
    ASSERT_NE(script_at, std::string::npos);
    const size_t at = script_at + marker.size();
    const size_t end = html.find(";</script>", at);
    ASSERT_NE(end, std::string::npos);
    const std::string js = html.substr(at, end - at); // JSON: "<\/" is JSON's escape of "</"
    const nlohmann::json state = nlohmann::json::parse(js, nullptr, false);
    ASSERT_FALSE(state.is_discarded());
    EXPECT_EQ(state["frames"].size(), 210u);
    EXPECT_NEAR(state["window_s"].get<double>(), state["now"].get<double>(), 1e-6);

    // The printed table has the figures.
    const std::string text = fgsr::cli::report_text(*r);
    EXPECT_NE(text.find("dropped 3, rejected 1"), std::string::npos) << text;

    EXPECT_TRUE(fs::exists(o.out / "report.gp"));
    EXPECT_TRUE(fs::exists(o.out / "frames.dat"));
    const std::string passes = read_text(o.out / "passes.dat");
    EXPECT_NE(passes.find("\"splat\" 0.5 100"), std::string::npos) << passes;
    EXPECT_NE(passes.find("\"generate\" 1.25 100"), std::string::npos) << passes;
    if (!gnuplot_installed()) GTEST_SKIP() << "gnuplot not installed: PNGs not checked";
    for (const char* png : {"frametime.png", "latency.png", "passes.png"})
        EXPECT_TRUE(has_png_signature(o.out / png)) << png;
}

TEST(Report, MissingOrMalformedFilesAreClearErrors) {
    TempDir dir;
    fgsr::cli::ReportOptions o;
    o.csv = dir.path / "absent.csv";
    o.out = dir.path / "out";
    o.progress = false;
    auto missing = fgsr::cli::run_report(o);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("absent.csv"), std::string::npos) << missing.error().message;
    {
        std::ofstream f(dir.path / "bad.csv");
        f << fgsr::presentmon_header() << "\nfgsr,1,0x0,Vulkan\n";
    }
    o.csv = dir.path / "bad.csv";
    auto bad = fgsr::cli::run_report(o);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("bad.csv: line 2"), std::string::npos) << bad.error().message;
}

// ---------------------------------------------------------------------------------------------
// A recorded run: fgsr replay --telemetry through a real fgsrd

class ReportRecorded : public ::testing::Test {
  protected:
    void SetUp() override {
        setenv("FGSR_CLIENT_QUIET", "1", 1);
        daemon_ = FgsrdProcess::start({"--log-level", "warn"});
        ASSERT_TRUE(daemon_) << FgsrdProcess::last_error();
    }
    void TearDown() override { unsetenv("FGSR_CLIENT_QUIET"); }

    // Replays the builtin capture in `mode`; returns the CSV's rows and the replay's summary.
    void replay(fgsr::cli::EvalMode mode, const fs::path& csv, std::vector<fgsr::PresentRow>& rows,
                fgsr::cli::ReplaySummary& summary) {
        fgsr::cli::ReplayOptions o;
        o.capture = "builtin";
        o.mode = mode;
        o.socket = daemon_->socket_path();
        o.telemetry = csv;
        o.progress = false;
        auto r = fgsr::cli::run_replay(o);
        ASSERT_TRUE(r) << r.error().message;
        summary = *r;
        const std::string text = read_text(csv);
        ASSERT_EQ(text.substr(0, text.find('\n')), fgsr::presentmon_header());
        auto parsed = fgsr::parse_presentmon_csv(text);
        ASSERT_TRUE(parsed) << parsed.error().message;
        rows = std::move(*parsed);
    }

    std::unique_ptr<FgsrdProcess> daemon_;
};

// Checks what holds in every mode: present times, MsBetweenPresents, sequence order, the ids.
void expect_presents_consistent(const std::vector<fgsr::PresentRow>& rows) {
    const fgsr::PresentRow* prev = nullptr;
    for (size_t i = 0; i < rows.size(); ++i) {
        const fgsr::PresentRow& r = rows[i];
        EXPECT_EQ(r.runtime, "fgsr-replay");
        EXPECT_EQ(r.process_id, uint32_t(getpid()));
        EXPECT_EQ(r.status, "OK") << "row " << i;
        ASSERT_TRUE(std::isfinite(r.time_s));
        EXPECT_TRUE(std::isfinite(r.ms_until_displayed)) << "row " << i;
        EXPECT_GE(r.ms_until_displayed, 0.0) << "row " << i;
        if (prev) {
            EXPECT_GE(r.time_s, prev->time_s) << "row " << i;
            EXPECT_GE(r.sequence, prev->sequence) << "row " << i;
            EXPECT_NEAR(r.ms_between_presents, (r.time_s - prev->time_s) * 1000.0, 2e-4) << "row " << i;
        } else {
            EXPECT_TRUE(std::isnan(r.ms_between_presents));
        }
        if (r.frame_type == "Application") {
            EXPECT_TRUE(std::isnan(r.daemon_latency_ms));
        } else {
            EXPECT_TRUE(std::isfinite(r.daemon_latency_ms)) << "row " << i;
            EXPECT_TRUE(std::isfinite(r.client_latency_ms)) << "row " << i;
            EXPECT_GE(r.client_latency_ms, r.daemon_latency_ms - 1e-3) << "row " << i;
            EXPECT_TRUE(std::isfinite(r.pass_ms[FGSR_PASS_INGEST])) << "row " << i;
            EXPECT_TRUE(std::isfinite(r.ms_gpu_time)) << "row " << i;
        }
        prev = &r;
    }
}

TEST_F(ReportRecorded, InterpolationRowsAreInDisplayOrder) {
    TempDir dir;
    std::vector<fgsr::PresentRow> rows;
    fgsr::cli::ReplaySummary s;
    ASSERT_NO_FATAL_FAILURE(replay(fgsr::cli::EvalMode::interp, dir.path / "t.csv", rows, s));
    ASSERT_GT(s.outputs, 0u);
    EXPECT_EQ(s.dropped + s.rejected, 0u);
    EXPECT_EQ(rows.size(), s.outputs + s.submitted); // every output and every application frame
    size_t app = 0, interp = 0;
    std::map<uint64_t, size_t> app_row; // sequence -> row of its Application frame
    for (size_t i = 0; i < rows.size(); ++i) {
        if (rows[i].frame_type == "Application") {
            ++app;
            EXPECT_EQ(app_row.count(rows[i].sequence), 0u) << "two application frames of one submit";
            app_row[rows[i].sequence] = i;
        } else {
            EXPECT_EQ(rows[i].frame_type, "fgsr-interpolated") << "row " << i;
            EXPECT_DOUBLE_EQ(rows[i].target_time, 0.5);
            ++interp;
        }
    }
    EXPECT_EQ(app, s.submitted);
    EXPECT_EQ(interp, s.outputs);
    // An interpolated frame comes right before the application frame of its submit.
    for (size_t i = 0; i < rows.size(); ++i)
        if (rows[i].frame_type == "fgsr-interpolated") {
            ASSERT_EQ(app_row.count(rows[i].sequence), 1u);
            EXPECT_EQ(app_row[rows[i].sequence], i + 1) << "row " << i;
        }
    EXPECT_EQ(rows.front().frame_type, "Application"); // the first submit has nothing to interpolate
    expect_presents_consistent(rows);

    // And the report reads it back.
    fgsr::cli::ReportOptions o;
    o.csv = dir.path / "t.csv";
    o.out = dir.path / "report";
    o.progress = false;
    o.plots = false;
    auto r = fgsr::cli::run_report(o);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->data.sessions.size(), 1u);
    EXPECT_EQ(r->data.sessions[0].frames, rows.size());
    EXPECT_EQ(r->data.sessions[0].generated, s.outputs);
    // Frame times of every row but the first (an application frame presented within the same 0.1 µs
    // as the interpolated one before it would have 0, which no frame rate counts).
    EXPECT_LE(r->data.summary.frames, rows.size() - 1);
    EXPECT_GE(r->data.summary.frames, rows.size() / 2);
    EXPECT_EQ(r->data.summary.daemon.count, s.outputs);
    EXPECT_GT(r->data.summary.avg_fps, 0.0);
}

TEST_F(ReportRecorded, ExtrapolatedFramesFollowTheirApplicationFrame) {
    TempDir dir;
    std::vector<fgsr::PresentRow> rows;
    fgsr::cli::ReplaySummary s;
    ASSERT_NO_FATAL_FAILURE(replay(fgsr::cli::EvalMode::extrap, dir.path / "t.csv", rows, s));
    ASSERT_GT(s.outputs, 0u);
    EXPECT_EQ(rows.size(), s.outputs + s.submitted);
    std::map<uint64_t, size_t> app_row;
    size_t extrap = 0;
    for (size_t i = 0; i < rows.size(); ++i)
        if (rows[i].frame_type == "Application")
            app_row[rows[i].sequence] = i;
        else {
            EXPECT_EQ(rows[i].frame_type, "fgsr-extrapolated") << "row " << i;
            EXPECT_DOUBLE_EQ(rows[i].target_time, 1.5);
            ASSERT_EQ(app_row.count(rows[i].sequence), 1u) << "row " << i << ": before its application frame";
            EXPECT_EQ(app_row[rows[i].sequence], i - 1) << "row " << i;
            ++extrap;
        }
    EXPECT_EQ(app_row.size(), s.submitted);
    EXPECT_EQ(extrap, s.outputs);
    expect_presents_consistent(rows);
}

} // namespace
