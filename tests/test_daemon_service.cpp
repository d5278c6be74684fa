// Multi-process tests of fgsrd: a real daemon (tests/fgsrd_process.hpp) and raw clients that speak
// protocol.h directly (not the client library), so they can be hostile: malformed messages,
// corrupted ring entries, clients killed at each protocol state. Frames are 64x64 and few.
#include "raw_client.hpp"

#include <fgsr/testing/fgsrd_process.hpp>

#include <fgsr/core/clock.hpp>
#include <fgsr/engine/defaults.hpp>
#include <fgsr/protocol.h>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <map>
#include <optional>
#include <poll.h>
#include <set>
#include <sstream>
#include <string>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <time.h>
#include <unistd.h>
#include <utility>
#include <vector>

namespace fgsr::test {
namespace {

// One daemon for the tests that do not need their own.
class Daemon : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        daemon_ = FgsrdProcess::start({"--log-level", "debug"}).release();
        ASSERT_NE(daemon_, nullptr) << FgsrdProcess::last_error();
    }
    static void TearDownTestSuite() {
        if (daemon_) {
            const std::string err = daemon_->stderr_text();
            EXPECT_EQ(err.find("validation error"), std::string::npos) << err;
            EXPECT_EQ(daemon_->terminate(), 0) << err;
        }
        delete daemon_;
        daemon_ = nullptr;
    }
    void SetUp() override {
        ASSERT_NE(daemon_, nullptr);
        ASSERT_TRUE(daemon_->running()) << daemon_->stderr_text();
    }
    static const std::string& path() { return daemon_->socket_path(); }
    // The other client still works: stats answer and a frame round-trips.
    static void expect_alive(Conn& c, float shift) {
        fgsr_session_ref ref{};
        ref.header = header(FGSR_MSG_STATS, sizeof(ref), 77);
        ref.session_id = c.s->reply.session_id;
        ASSERT_TRUE(c.raw.send(&ref, sizeof(ref)));
        auto st = as<fgsr_stats_reply>(c.raw.recv());
        EXPECT_EQ(st.header.type, FGSR_MSG_STATS_REPLY);
        EXPECT_EQ(st.header.sequence, 77u);
        EXPECT_EQ(st.status, FGSR_STATUS_OK);
        auto v = roundtrip(*c.s, shift);
        ASSERT_EQ(v.size(), 1u);
        EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
    }
    static FgsrdProcess* daemon_;
};
FgsrdProcess* Daemon::daemon_ = nullptr;

TEST_F(Daemon, HandshakeReportsVersionCapabilitiesAndDevice) {
    auto raw = Raw::connect(path());
    ASSERT_TRUE(raw);
    const fgsr_hello_reply r = raw->hello();
    EXPECT_EQ(r.header.magic, FGSR_PROTOCOL_MAGIC);
    EXPECT_EQ(r.header.type, FGSR_MSG_HELLO_REPLY);
    EXPECT_EQ(r.status, FGSR_STATUS_OK);
    EXPECT_EQ(r.major, FGSR_PROTOCOL_MAJOR);
    EXPECT_NE(r.epoch, 0u);
    EXPECT_GT(std::strlen(r.device), 0u);
    const uint32_t need = FGSR_CAP_SR | FGSR_CAP_INTERPOLATE | FGSR_CAP_EXTRAPOLATE;
    EXPECT_EQ(r.capabilities & need, need);
    // The epoch stays the same for this daemon instance.
    auto raw2 = Raw::connect(path());
    ASSERT_TRUE(raw2);
    EXPECT_EQ(raw2->hello().epoch, r.epoch);
}

TEST_F(Daemon, VersionMismatchIsRefusedThenClosed) {
    auto raw = Raw::connect(path());
    ASSERT_TRUE(raw);
    const fgsr_hello_reply r = raw->hello(FGSR_PROTOCOL_MAJOR + 1);
    EXPECT_EQ(r.status, FGSR_STATUS_VERSION_MISMATCH);
    EXPECT_EQ(r.major, FGSR_PROTOCOL_MAJOR);
    EXPECT_TRUE(raw->closed_by_daemon());
}

TEST_F(Daemon, CreateSessionValidatesTheDescription) {
    auto raw = Raw::connect(path());
    ASSERT_TRUE(raw);
    ASSERT_EQ(raw->hello().status, FGSR_STATUS_OK);
    std::vector<std::pair<const char*, fgsr_session_desc>> bad;
    auto add = [&](const char* what, auto change) {
        fgsr_session_desc d = default_desc();
        change(d);
        bad.emplace_back(what, d);
    };
    add("width 0", [](fgsr_session_desc& d) { d.width = 0; });
    add("height too large", [](fgsr_session_desc& d) { d.height = 20000; });
    add("colour format", [](fgsr_session_desc& d) { d.color_format = 7; });
    add("scale 2.5", [](fgsr_session_desc& d) { d.scale = 2.5f; });
    add("SR at scale 1", [](fgsr_session_desc& d) { d.scale = 1.f; });
    add("too many slots", [](fgsr_session_desc& d) { d.input_slots = FGSR_MAX_SLOTS + 1; });
    add("ring not a power of two", [](fgsr_session_desc& d) { d.ring_capacity = 48; });
    add("ring smaller than the slots", [](fgsr_session_desc& d) { d.ring_capacity = 2; });
    add("no modes", [](fgsr_session_desc& d) { d.modes = 0; });
    add("reserved nonzero", [](fgsr_session_desc& d) { d.reserved[3] = 1; });
    uint32_t seq = 10;
    for (auto& [what, d] : bad) {
        fgsr_create_session m{};
        m.header = header(FGSR_MSG_CREATE_SESSION, sizeof(m), ++seq);
        m.desc = d;
        ASSERT_TRUE(raw->send(&m, sizeof(m)));
        std::vector<Fd> fds;
        auto r = as<fgsr_create_session_reply>(raw->recv(&fds));
        EXPECT_EQ(r.header.sequence, seq) << what;
        EXPECT_EQ(r.status, FGSR_STATUS_INVALID_ARGUMENT) << what;
        EXPECT_GT(std::strlen(r.reason), 0u) << what;
        EXPECT_TRUE(fds.empty()) << what;
    }
}

TEST_F(Daemon, SessionMemoryIsSealedAndTheOutputPoolReadOnly) {
    auto c = open_session(path());
    ASSERT_TRUE(c);
    const int in = c->s->fds[FGSR_FD_INPUT_POOL].fd, out = c->s->fds[FGSR_FD_OUTPUT_POOL].fd;
    const int rings = c->s->fds[FGSR_FD_RINGS].fd;
    EXPECT_EQ(fcntl(in, F_GET_SEALS), F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL);
    EXPECT_EQ(fcntl(rings, F_GET_SEALS), F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL);
    EXPECT_EQ(fcntl(out, F_GET_SEALS), F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_FUTURE_WRITE | F_SEAL_SEAL);
    EXPECT_EQ(mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, out, 0), MAP_FAILED);
    EXPECT_NE(ftruncate(in, 4096), 0);
    const fgsr_pool_layout& l = c->s->layout();
    EXPECT_EQ(l.output_width, 2 * kW);
    EXPECT_EQ(l.input_slot_stride % FGSR_PLANE_ALIGNMENT, 0u);
    EXPECT_EQ(l.depth.offset % FGSR_PLANE_ALIGNMENT, 0u);
    EXPECT_EQ(l.mv.offset % FGSR_PLANE_ALIGNMENT, 0u);
    EXPECT_EQ(l.rings_size, fgsr_rings_layout_for(64).total_size);
}

TEST_F(Daemon, OutputsTelemetryAndNotReadyOnTheFirstFrame) {
    auto c = open_session(path());
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    const float ia[2] = {0.25f, 0.5f}, ea[1] = {0.5f};
    for (int frame = 0; frame < 2; ++frame) {
        s.fill(uint32_t(frame), float(frame));
        fgsr_submit_entry e = s.entry(uint32_t(frame), FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR);
        e.interp_count = 2;
        std::memcpy(e.interp_alphas, ia, sizeof(ia));
        e.extrap_count = 1;
        std::memcpy(e.extrap_alphas, ea, sizeof(ea));
        e.present_time_ns = 1000000000ull * uint64_t(frame + 1);
        const uint64_t before = monotonic_ns();
        s.push(e);
        auto v = s.wait_submit();
        const uint64_t after = monotonic_ns();
        ASSERT_EQ(v.size(), 4u);
        const int32_t gen_status = frame == 0 ? FGSR_STATUS_NOT_READY : FGSR_STATUS_OK;
        // Presentation order: interpolated, upscaled, extrapolated.
        const uint32_t types[4] = {FGSR_FRAME_INTERPOLATED, FGSR_FRAME_INTERPOLATED, FGSR_FRAME_UPSCALED,
                                   FGSR_FRAME_EXTRAPOLATED};
        const float times[4] = {0.25f, 0.5f, 1.f, 1.5f};
        for (uint32_t k = 0; k < 4; ++k) {
            const fgsr_completion_entry& ce = v[k];
            SCOPED_TRACE("frame " + std::to_string(frame) + " output " + std::to_string(k));
            EXPECT_EQ(ce.sequence, e.sequence);
            EXPECT_EQ(ce.user_data, e.user_data);
            EXPECT_EQ(ce.output_index, k);
            EXPECT_EQ(ce.status, k == 2 ? FGSR_STATUS_OK : gen_status);
            EXPECT_EQ(ce.flags, k == 3 ? FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST : 0u);
            const fgsr_telemetry& t = ce.telemetry;
            EXPECT_EQ(t.frame_type, types[k]);
            EXPECT_FLOAT_EQ(t.target_time, times[k]);
            EXPECT_EQ(t.submit_ns, e.submit_time_ns);
            EXPECT_LE(e.submit_time_ns, t.dequeue_ns);
            EXPECT_LE(t.dequeue_ns, t.start_ns);
            EXPECT_LE(t.start_ns, t.complete_ns);
            EXPECT_LE(t.complete_ns, after);
            EXPECT_EQ(t.queue_wait_ns, t.start_ns - t.dequeue_ns);
            ASSERT_GE(t.pass_count, 1u);
            EXPECT_EQ(t.passes[0].pass, uint32_t(FGSR_PASS_INGEST));
            uint64_t sum = 0;
            for (uint32_t p = 0; p < t.pass_count; ++p) {
                EXPECT_LE(t.passes[p].gpu_begin_ns, t.passes[p].gpu_end_ns);
                EXPECT_GT(t.passes[p].gpu_begin_ns + 100'000'000ull, before);
                EXPECT_LT(t.passes[p].gpu_end_ns, after + 100'000'000ull);
                sum += t.passes[p].gpu_end_ns - t.passes[p].gpu_begin_ns;
            }
            if (ce.status == FGSR_STATUS_OK) {
                ASSERT_LT(ce.output_slot, s.layout().output_slot_count);
                EXPECT_GE(t.pass_count, 2u);
                // Pixels are finite and not all zero.
                const auto* px = reinterpret_cast<const float*>(s.out_slot(ce.output_slot));
                double total = 0;
                bool finite = true;
                for (size_t i = 0; i < size_t(2 * kW) * (2 * kH) * 4; ++i) {
                    finite &= std::isfinite(px[i]);
                    total += px[i];
                }
                EXPECT_TRUE(finite);
                EXPECT_GT(total, 0.0);
                if (frame == 1 && k != 2) {
                    EXPECT_EQ(t.target_present_ns, 1000000000ull + uint64_t(double(times[k]) * 1e9));
                }
            } else {
                EXPECT_EQ(ce.output_slot, FGSR_NO_SLOT);
                EXPECT_NE(t.skipped_passes, 0u);
            }
        }
        for (const auto& ce : v)
            if (ce.output_slot != FGSR_NO_SLOT) s.release(ce.output_slot);
    }
    // Stats aggregate what happened.
    fgsr_session_ref ref{};
    ref.header = header(FGSR_MSG_STATS, sizeof(ref), 9);
    ref.session_id = s.reply.session_id;
    ASSERT_TRUE(c->raw.send(&ref, sizeof(ref)));
    auto st = as<fgsr_stats_reply>(c->raw.recv());
    EXPECT_EQ(st.status, FGSR_STATUS_OK);
    EXPECT_EQ(st.stats.frames_submitted, 2u);
    EXPECT_EQ(st.stats.outputs_written, 5u); // 1 + 4
    EXPECT_EQ(st.stats.frames_dropped, 0u);
    EXPECT_GT(st.stats.latency_p50_ns, 0u);
    EXPECT_LE(st.stats.latency_p50_ns, st.stats.latency_p99_ns);
    EXPECT_LE(st.stats.gpu_p50_ns, st.stats.gpu_p99_ns);
    // Destroy answers OK, a second destroy INVALID_ARGUMENT.
    for (int32_t want : {FGSR_STATUS_OK, FGSR_STATUS_INVALID_ARGUMENT}) {
        ref.header = header(FGSR_MSG_DESTROY_SESSION, sizeof(ref), 10);
        ASSERT_TRUE(c->raw.send(&ref, sizeof(ref)));
        auto r = as<fgsr_reply>(c->raw.recv());
        EXPECT_EQ(r.header.type, FGSR_MSG_DESTROY_SESSION_REPLY);
        EXPECT_EQ(r.status, want);
    }
}

// Submits input slot `slot` (FGSR_SUBMIT_* `flags`) asking for one interpolated frame at alpha
// 0.5, waits for its single completion and returns it with the passes its records name.
std::pair<fgsr_completion_entry, std::set<uint32_t>> submit_interpolating(RawSession& s, uint32_t slot,
                                                                          uint32_t flags) {
    const float alpha = 0.5f;
    fgsr_submit_entry e = s.entry(slot, flags);
    e.interp_count = 1;
    std::memcpy(e.interp_alphas, &alpha, sizeof(alpha));
    s.push(e);
    auto v = s.wait_submit();
    EXPECT_EQ(v.size(), 1u);
    if (v.empty()) return {};
    std::set<uint32_t> passes;
    for (uint32_t p = 0; p < v[0].telemetry.pass_count; ++p) passes.insert(v[0].telemetry.passes[p].pass);
    return {v[0], passes};
}

// A frame-generation session (scale 1) of the default description with session `flags` and `modes`.
fgsr_session_desc frame_generation_desc(uint32_t flags, uint32_t modes) {
    fgsr_session_desc d = default_desc();
    d.flags = flags;
    d.modes = modes;
    d.scale = 1.f;
    return d;
}

// The motion estimation's passes (luma, match, flow) are among a completion's records, once each.
void expect_motion_passes(const std::set<uint32_t>& passes) {
    for (uint32_t want : {uint32_t(FGSR_PASS_LUMA), uint32_t(FGSR_PASS_MATCH), uint32_t(FGSR_PASS_FLOW)})
        EXPECT_EQ(passes.count(want), 1u) << "pass " << want;
}

// FGSR_SESSION_CORRECT_MVS (minor 4): the session has vectors and the daemon also runs the motion
// passes on every submit after the first; their records come with the interpolated output.
TEST_F(Daemon, CorrectedVectorSessionsRunAndReportTheMotionPasses) {
    auto c = open_session(path(), frame_generation_desc(FGSR_SESSION_CORRECT_MVS, FGSR_MODE_INTERPOLATE));
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    for (uint32_t frame = 0; frame < 2; ++frame) {
        s.fill(frame, float(frame));
        const auto [done, passes] = submit_interpolating(s, frame, FGSR_SUBMIT_HAS_MV);
        if (frame == 0) {
            EXPECT_EQ(done.status, FGSR_STATUS_NOT_READY);
            continue;
        }
        EXPECT_EQ(done.status, FGSR_STATUS_OK);
        expect_motion_passes(passes);
        if (done.output_slot != FGSR_NO_SLOT) s.release(done.output_slot);
    }
}

// FGSR_SESSION_COLOUR_AGREE (minor 7): the daemon estimates motion from colour beside the given
// vectors and generates each interpolated and extrapolated frame from both fields; with super
// resolution too (minor 8: ISR and ESR, change 45). The completion names every pass once
// (fgsr_pass_record.runs counts the runs: the frame's ingest and the colour twin's, each field's
// generation passes), agree among them, within FGSR_MAX_PASSES; the records' times stay within the
// output's GPU time; at scale 2 the twin's sr pass (the history its frames warp) is among them.
// Vectors that explain the colour leave the frames (of the output's size) as without the flag but
// for the colour-only frame's least share (agree.h stage 3, change 43: 1 / (1 + exp(centre /
// softness)), where both fields agree), and the twin's frame differs little.
TEST_F(Daemon, AgreeingSessionsReportEachPassOnceWithItsRuns) {
    for (const float scale : {1.f, 2.f}) {
        SCOPED_TRACE("scale " + std::to_string(scale));
        const size_t out_px = size_t(float(kW) * scale) * size_t(float(kH) * scale);
        std::vector<std::vector<float>> frames[2]; // [flag] interp, extrap outputs
        for (const bool agree : {false, true}) {
            SCOPED_TRACE(agree ? "colour agree" : "given vectors only");
            fgsr_session_desc d = frame_generation_desc(agree ? FGSR_SESSION_COLOUR_AGREE : 0u,
                                                        FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE);
            d.scale = scale;
            auto c = open_session(path(), d);
            ASSERT_TRUE(c);
            RawSession& s = *c->s;
            for (uint32_t frame = 0; frame < 2; ++frame) {
                s.fill(frame, float(frame));
                fgsr_submit_entry e = s.entry(frame, FGSR_SUBMIT_HAS_MV);
                const float alpha = 0.5f;
                e.interp_count = 1;
                e.extrap_count = 1;
                std::memcpy(e.interp_alphas, &alpha, sizeof(alpha));
                std::memcpy(e.extrap_alphas, &alpha, sizeof(alpha));
                s.push(e);
                const auto done = s.wait_submit();
                ASSERT_EQ(done.size(), 2u);
                if (frame == 0) continue;
                for (const fgsr_completion_entry& o : done) {
                    ASSERT_EQ(o.status, FGSR_STATUS_OK);
                    const fgsr_telemetry& t = o.telemetry;
                    ASSERT_LE(t.pass_count, FGSR_MAX_PASSES);
                    std::map<uint32_t, uint32_t> runs;
                    uint64_t summed = 0;
                    for (uint32_t i = 0; i < t.pass_count; ++i) {
                        const fgsr_pass_record& r = t.passes[i];
                        EXPECT_EQ(runs.count(r.pass), 0u) << "pass " << r.pass << " has two records";
                        runs[r.pass] = r.runs;
                        EXPECT_GE(r.gpu_end_ns, r.gpu_begin_ns);
                        summed += r.gpu_end_ns - r.gpu_begin_ns;
                    }
                    // gpu_ns sums each run's time; a record's span is its runs' (the ingest's cut
                    // stage and polish's coarse levels count in gpu_ns only), each rounded to the ns.
                    EXPECT_GT(summed, 0u);
                    EXPECT_LE(summed, t.gpu_ns + 1000u * t.pass_count);
                    const bool interp = t.frame_type == FGSR_FRAME_INTERPOLATED;
                    EXPECT_EQ(runs[FGSR_PASS_INGEST], agree ? 2u : 1u);
                    EXPECT_EQ(runs.count(FGSR_PASS_AGREE), agree ? 1u : 0u);
                    EXPECT_EQ(runs.count(FGSR_PASS_MATCH), agree ? 1u : 0u) << "the twin's motion passes";
                    EXPECT_EQ(runs.count(FGSR_PASS_SR), agree && scale != 1.f ? 1u : 0u)
                        << "the twin's upscale";
                    if (agree && interp && scale == 1.f) {
                        EXPECT_EQ(runs[FGSR_PASS_BLEND], 2u) << "both fields blend";
                    }
                    ASSERT_NE(o.output_slot, FGSR_NO_SLOT);
                    const auto* px = reinterpret_cast<const float*>(s.out_slot(o.output_slot));
                    frames[agree].emplace_back(px, px + out_px * 4);
                    s.release(o.output_slot);
                }
            }
        }
        ASSERT_EQ(frames[0].size(), 2u);
        ASSERT_EQ(frames[1].size(), 2u);
        // The given vectors explain the colour: the given frames, but for that share of the twin's.
        const float least =
            1.f / (1.f + std::exp(fgsr::defaults::agree_centre / fgsr::defaults::agree_softness));
        for (size_t k = 0; k < 2; ++k) {
            SCOPED_TRACE(k == 0 ? "interpolated" : "extrapolated");
            ASSERT_EQ(frames[0][k].size(), frames[1][k].size());
            float largest = 0.f;
            double sum = 0.0;
            for (size_t i = 0; i < frames[0][k].size(); ++i) {
                const float dd = std::abs(frames[0][k][i] - frames[1][k][i]);
                largest = std::max(largest, dd);
                sum += dd;
            }
            EXPECT_LE(largest, least + 1e-3f);
            EXPECT_LT(sum / double(frames[0][k].size()), 0.01);
        }
    }
}

// Colour-only sessions (FGSR_SESSION_NO_MVS | NO_DEPTH, minor 2) estimate motion from colour at
// every submit after the first, and refine the estimate at this size unless the session asked for
// fast motion estimation (FGSR_SESSION_FAST_MOTION, minor 5): its completions then carry no polish
// record, and it still generates frames.
TEST_F(Daemon, FastMotionSessionsSkipTheRefinementOfTheEstimate) {
    for (const bool fast : {false, true}) {
        SCOPED_TRACE(fast ? "fast motion" : "default motion");
        fgsr_session_desc d = default_desc();
        d.flags = FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH | (fast ? FGSR_SESSION_FAST_MOTION : 0u);
        d.modes = FGSR_MODE_INTERPOLATE;
        d.scale = 1.f;
        auto c = open_session(path(), d);
        ASSERT_TRUE(c);
        RawSession& s = *c->s;
        for (uint32_t frame = 0; frame < 3; ++frame) {
            s.fill(frame % 2, 2.f * float(frame));
            const auto [done, passes] = submit_interpolating(s, frame % 2, 0);
            if (frame == 0) {
                EXPECT_EQ(done.status, FGSR_STATUS_NOT_READY);
                continue;
            }
            EXPECT_EQ(done.status, FGSR_STATUS_OK);
            EXPECT_NE(done.output_slot, FGSR_NO_SLOT);
            expect_motion_passes(passes);
            EXPECT_EQ(passes.count(FGSR_PASS_POLISH), fast ? 0u : 1u);
            if (done.output_slot != FGSR_NO_SLOT) s.release(done.output_slot);
        }
    }
}

// A still scene (same frame, zero vectors): the completion's pass records carry the engine's tile
// counts, every splat tile is skipped (so the splat bit of skipped_passes is set), and a moving
// scene skips none.
TEST_F(Daemon, TelemetryReportsSkippedTilesOfAStillScene) {
    fgsr_session_desc d = default_desc();
    d.scale = 1.f;
    d.modes = FGSR_MODE_INTERPOLATE;
    auto c = open_session(path(), d);
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    auto interp = [&](uint32_t frame, float shift, float step) {
        s.fill(frame % 2, shift, step);
        fgsr_submit_entry e = s.entry(frame % 2, FGSR_SUBMIT_HAS_MV);
        e.interp_count = 1;
        e.interp_alphas[0] = 0.5f;
        s.push(e);
        auto v = s.wait_submit();
        for (const auto& x : v)
            if (x.output_slot != FGSR_NO_SLOT) s.release(x.output_slot);
        return v;
    };
    auto splat_record = [](const fgsr_completion_entry& e) -> const fgsr_pass_record* {
        for (uint32_t i = 0; i < e.telemetry.pass_count; ++i)
            if (e.telemetry.passes[i].pass == FGSR_PASS_SPLAT) return &e.telemetry.passes[i];
        return nullptr;
    };
    interp(0, 0.f, 0.f);
    auto still = interp(1, 0.f, 0.f);
    ASSERT_EQ(still.size(), 1u);
    ASSERT_EQ(still[0].status, FGSR_STATUS_OK);
    const fgsr_pass_record* r = splat_record(still[0]);
    ASSERT_NE(r, nullptr);
    EXPECT_GT(r->tiles_total, 0u);
    EXPECT_EQ(r->tiles_skipped, r->tiles_total);
    EXPECT_NE(still[0].telemetry.skipped_passes & (1u << FGSR_PASS_SPLAT), 0u);
    bool classified = false;
    for (uint32_t i = 0; i < still[0].telemetry.pass_count; ++i)
        classified |= still[0].telemetry.passes[i].pass == FGSR_PASS_CLASSIFY;
    EXPECT_TRUE(classified);

    auto moving = interp(2, 1.f, 1.f);
    ASSERT_EQ(moving.size(), 1u);
    ASSERT_EQ(moving[0].status, FGSR_STATUS_OK);
    r = splat_record(moving[0]);
    ASSERT_NE(r, nullptr);
    if (r->tiles_total > 0) {
        EXPECT_EQ(r->tiles_skipped, 0u); // every tile moves
    }
    EXPECT_EQ(moving[0].telemetry.skipped_passes & (1u << FGSR_PASS_SPLAT), 0u);
}

TEST_F(Daemon, BadFrameContentCompletesWithBadFrameAndTheSessionGoesOn) {
    auto c = open_session(path());
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    s.fill(1, 0.f);
    fgsr_submit_entry e = s.entry(1, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR);
    e.jitter_x = 5.f; // the engine accepts [-1, 1] pixels
    s.push(e);
    auto v = s.wait_submit();
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].status, FGSR_STATUS_BAD_FRAME);
    EXPECT_EQ(v[0].input_slot, 1u);
    EXPECT_EQ(v[0].output_slot, FGSR_NO_SLOT);
    EXPECT_EQ(v[0].flags, FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST);
    // The slot is the client's again: submitting it is legal.
    s.fill(1, 0.f);
    s.push(s.entry(1, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    v = s.wait_submit();
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
}

// Malformed control messages: the sender is dropped (after an ERROR where it can be sent),
// another client with a live session is unaffected.
TEST_F(Daemon, MalformedControlMessagesDropOnlyTheSender) {
    auto good = open_session(path());
    ASSERT_TRUE(good);
    struct Case {
        const char* what;
        std::vector<std::byte> bytes;
        bool hello_first;
        bool attach_fd;
    };
    auto bytes_of = [](const void* p, size_t n) {
        std::vector<std::byte> b(n);
        std::memcpy(b.data(), p, n);
        return b;
    };
    fgsr_hello h{};
    h.header = header(FGSR_MSG_HELLO, sizeof(h));
    h.major = FGSR_PROTOCOL_MAJOR;
    fgsr_hello wrong_magic = h;
    wrong_magic.header.magic = 0xdeadbeef;
    fgsr_hello size_lies = h;
    size_lies.header.size = 40;
    fgsr_session_ref unknown{};
    unknown.header = header(99, sizeof(unknown));
    fgsr_session_ref stats_first{};
    stats_first.header = header(FGSR_MSG_STATS, sizeof(stats_first));
    fgsr_create_session truncated{};
    truncated.header = header(FGSR_MSG_CREATE_SESSION, 40);
    std::vector<std::byte> oversized(FGSR_MAX_MESSAGE_SIZE + 512);
    fgsr_msg_header oh = header(FGSR_MSG_STATS, uint32_t(oversized.size()));
    std::memcpy(oversized.data(), &oh, sizeof(oh));
    fgsr_create_session bad_struct_size{};
    bad_struct_size.header = header(FGSR_MSG_CREATE_SESSION, sizeof(bad_struct_size));
    bad_struct_size.desc = default_desc();
    bad_struct_size.desc.struct_size = 4000;
    const std::vector<Case> cases = {
        {"shorter than a header", bytes_of(&h, 8), false, false},
        {"wrong magic", bytes_of(&wrong_magic, sizeof(h)), false, false},
        {"header size disagrees with the packet", bytes_of(&size_lies, sizeof(h)), false, false},
        {"hello truncated", bytes_of(&h, 20), false, false},
        {"request before hello", bytes_of(&stats_first, sizeof(stats_first)), false, false},
        {"unknown type", bytes_of(&unknown, sizeof(unknown)), true, false},
        {"create session truncated", bytes_of(&truncated, 40), true, false},
        {"oversized", oversized, true, false},
        {"struct_size beyond the message", bytes_of(&bad_struct_size, sizeof(bad_struct_size)), true, false},
        {"fd attached", bytes_of(&stats_first, sizeof(stats_first)), true, true},
        {"second hello", bytes_of(&h, sizeof(h)), true, false},
    };
    float shift = 0;
    for (const Case& k : cases) {
        SCOPED_TRACE(k.what);
        auto bad = Raw::connect(path());
        ASSERT_TRUE(bad);
        if (k.hello_first) {
            ASSERT_EQ(bad->hello().status, FGSR_STATUS_OK);
        }
        Fd efd(k.attach_fd ? eventfd(0, EFD_CLOEXEC) : -1);
        ASSERT_TRUE(bad->send(k.bytes.data(), k.bytes.size(), efd.fd));
        bool eof = false;
        auto m = bad->recv(nullptr, &eof);
        if (!eof) {
            ASSERT_EQ(m.size(), sizeof(fgsr_reply));
            auto r = as<fgsr_reply>(m);
            EXPECT_EQ(r.header.type, FGSR_MSG_ERROR);
            EXPECT_EQ(r.status, FGSR_STATUS_PROTOCOL_ERROR);
            EXPECT_GT(std::strlen(r.reason), 0u);
            EXPECT_TRUE(bad->closed_by_daemon());
        }
        expect_alive(*good, shift += 1.f);
    }
    EXPECT_TRUE(daemon_->running());
}

// Corrupted ring entries: protocol violations disconnect the offender only.
TEST_F(Daemon, CorruptedRingEntriesDropOnlyTheOffender) {
    auto good = open_session(path());
    ASSERT_TRUE(good);
    using Corrupt = void (*)(RawSession&);
    const std::vector<std::pair<const char*, Corrupt>> cases = {
        {"slot out of range", [](RawSession& s) { s.push(s.entry(FGSR_MAX_SLOTS + 3)); }},
        {"sequence not increasing",
         [](RawSession& s) {
             fgsr_submit_entry e = s.entry(0), f = e;
             f.input_slot = 1; // same sequence again
             s.push_many({e, f});
         }},
        {"interpolation alpha out of range",
         [](RawSession& s) {
             fgsr_submit_entry e = s.entry(0);
             e.interp_count = 1;
             e.interp_alphas[0] = 1.5f;
             s.push(e);
         }},
        {"alpha NaN",
         [](RawSession& s) {
             fgsr_submit_entry e = s.entry(0);
             e.extrap_count = 1;
             e.extrap_alphas[0] = std::nanf("");
             s.push(e);
         }},
        {"too many alphas",
         [](RawSession& s) {
             fgsr_submit_entry e = s.entry(0);
             e.interp_count = FGSR_MAX_ALPHAS + 1;
             s.push(e);
         }},
        {"slot still held by the daemon",
         [](RawSession& s) {
             fgsr_submit_entry e = s.entry(0, FGSR_SUBMIT_WANT_SR);
             s.push_many({e, s.entry(0)}); // slot 0 again before a completion released it
         }},
        {"head beyond capacity",
         [](RawSession& s) {
             fgsr_ring_publish(s.hdr(s.rl.submit_header), s.layout().ring_capacity + 5);
             s.signal();
         }},
        {"release of a slot not held", [](RawSession& s) { s.release(2); }},
        {"release slot out of range", [](RawSession& s) { s.release(1000); }},
        {"completion tail beyond head",
         [](RawSession& s) {
             fgsr_ring_consume(s.hdr(s.rl.completion_header), 12345);
             s.signal();
         }},
        {"unknown submit flags", [](RawSession& s) { s.push(s.entry(0, 0x80)); }},
    };
    float shift = 0;
    for (const auto& [what, corrupt] : cases) {
        SCOPED_TRACE(what);
        auto bad = open_session(path());
        ASSERT_TRUE(bad);
        corrupt(*bad->s);
        bool got_error = false;
        for (int i = 0; i < 4; ++i) {
            bool eof = false;
            auto m = bad->raw.recv(nullptr, &eof);
            if (eof || m.empty()) break;
            auto r = as<fgsr_reply>(m);
            if (r.header.type == FGSR_MSG_ERROR) {
                got_error = true;
                EXPECT_EQ(r.status, FGSR_STATUS_PROTOCOL_ERROR);
                EXPECT_GT(std::strlen(r.reason), 0u);
                break;
            }
        }
        EXPECT_TRUE(got_error);
        EXPECT_TRUE(bad->raw.closed_by_daemon());
        expect_alive(*good, shift += 1.f);
    }
    // A submit naming a mode the session did not declare.
    fgsr_session_desc d = default_desc();
    d.modes = FGSR_MODE_SR;
    auto bad = open_session(path(), d);
    ASSERT_TRUE(bad);
    fgsr_submit_entry e = bad->s->entry(0);
    e.interp_count = 1;
    e.interp_alphas[0] = 0.5f;
    bad->s->push(e);
    auto r = as<fgsr_reply>(bad->raw.recv());
    EXPECT_EQ(r.header.type, FGSR_MSG_ERROR);
    EXPECT_NE(std::string(r.reason).find("did not declare"), std::string::npos) << r.reason;
    expect_alive(*good, 100.f);
}

TEST_F(Daemon, FifoProcessesEverySubmitInOrderAsOutputSlotsFree) {
    fgsr_session_desc d = default_desc();
    d.output_slots = 1;
    d.queue_policy = FGSR_QUEUE_FIFO;
    auto c = open_session(path(), d);
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    for (uint32_t i = 0; i < 3; ++i) {
        s.fill(i, float(i));
        s.push(s.entry(i, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    }
    for (uint64_t seq = 1; seq <= 3; ++seq) {
        auto v = s.wait_submit();
        ASSERT_EQ(v.size(), 1u);
        EXPECT_EQ(v[0].sequence, seq);
        EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
        EXPECT_EQ(v[0].output_slot, 0u);
        // The next one waits for this slot: nothing else arrives while it is held.
        if (seq < 3) {
            EXPECT_FALSE(s.wait(200).has_value());
        }
        s.release(v[0].output_slot);
    }
}

TEST_F(Daemon, MailboxDropsAllButTheNewestPendingSubmit) {
    fgsr_session_desc d = default_desc();
    d.output_slots = 1;
    d.input_slots = 4;
    d.queue_policy = FGSR_QUEUE_MAILBOX;
    auto c = open_session(path(), d);
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    auto first = roundtrip(s, 0.f, false); // holds the only output slot
    ASSERT_EQ(first.size(), 1u);
    ASSERT_EQ(first[0].status, FGSR_STATUS_OK);
    for (uint32_t i = 1; i <= 3; ++i) {
        s.fill(i, float(i));
        s.push(s.entry(i, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    }
    // Sequences 2 and 3 are superseded by 4 while no output slot is free.
    for (uint64_t seq = 2; seq <= 3; ++seq) {
        auto v = s.wait_submit();
        ASSERT_EQ(v.size(), 1u);
        EXPECT_EQ(v[0].sequence, seq);
        EXPECT_EQ(v[0].status, FGSR_STATUS_DROPPED);
        EXPECT_EQ(v[0].flags, FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST);
        EXPECT_EQ(v[0].output_slot, FGSR_NO_SLOT);
    }
    s.release(first[0].output_slot);
    auto v = s.wait_submit();
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].sequence, 4u);
    EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
    fgsr_session_ref ref{};
    ref.header = header(FGSR_MSG_STATS, sizeof(ref), 3);
    ref.session_id = s.reply.session_id;
    ASSERT_TRUE(c->raw.send(&ref, sizeof(ref)));
    auto st = as<fgsr_stats_reply>(c->raw.recv());
    EXPECT_EQ(st.stats.frames_dropped, 2u);
    EXPECT_EQ(st.stats.frames_submitted, 4u);
}

TEST_F(Daemon, AStalledClientDoesNotBlockOthers) {
    // The stalled client never releases outputs nor reads completions.
    fgsr_session_desc d = default_desc();
    d.output_slots = 1;
    d.ring_capacity = 4;
    auto stalled = open_session(path(), d);
    ASSERT_TRUE(stalled);
    for (uint32_t i = 0; i < 3; ++i) {
        stalled->s->fill(i, 0.f);
        stalled->s->push(stalled->s->entry(i, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
    }
    std::vector<Conn> others;
    for (int k = 0; k < 7; ++k) {
        auto c = open_session(path());
        ASSERT_TRUE(c);
        others.push_back(std::move(*c));
    }
    for (int frame = 0; frame < 3; ++frame) {
        for (Conn& c : others) {
            c.s->fill(0, float(frame));
            c.s->push(c.s->entry(0, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
        }
        for (Conn& c : others) {
            auto v = c.s->wait_submit();
            ASSERT_EQ(v.size(), 1u);
            EXPECT_EQ(v[0].status, FGSR_STATUS_OK);
            c.s->release(v[0].output_slot);
        }
    }
}

// A client that never reads its completions fills the completion ring: its later submits wait
// (nothing lost), other sessions go on, and draining the ring lets the waiting submits finish.
TEST_F(Daemon, AFullCompletionRingWaitsWithoutBlockingOthers) {
    fgsr_session_desc d = default_desc();
    d.input_slots = 4;
    d.output_slots = 4;
    d.ring_capacity = 4;
    auto slow = open_session(path(), d);
    auto other = open_session(path());
    ASSERT_TRUE(slow && other);
    RawSession& s = *slow->s;
    // Submits without outputs: one completion each, no output slot.
    for (uint32_t i = 0; i < 4; ++i) {
        s.fill(i, 0.f);
        s.push(s.entry(i));
    }
    // Wait until the ring is full (4 completions published, none read).
    for (int i = 0; i < 500 && fgsr_ring_load_head(s.hdr(s.rl.completion_header)) < 4; ++i) usleep(10000);
    ASSERT_EQ(fgsr_ring_load_head(s.hdr(s.rl.completion_header)), 4u);
    // The slots came back with those completions (the entries say so); submit them again.
    for (uint32_t i = 0; i < 4; ++i) s.push(s.entry(i));
    for (int frame = 0; frame < 3; ++frame) expect_alive(*other, float(frame));
    EXPECT_EQ(fgsr_ring_load_head(s.hdr(s.rl.completion_header)), 4u) << "published into a full ring";
    for (uint64_t seq = 1; seq <= 8; ++seq) {
        auto c = s.wait();
        ASSERT_TRUE(c) << "sequence " << seq;
        EXPECT_EQ(c->sequence, seq);
        EXPECT_EQ(c->status, FGSR_STATUS_OK);
        EXPECT_EQ(c->telemetry.frame_type, uint32_t(FGSR_FRAME_NONE));
        EXPECT_EQ(c->flags, FGSR_COMPLETION_INPUT_RELEASED | FGSR_COMPLETION_LAST);
    }
}

// A hostile client scribbles over an input slot while the daemon ingests it (zero-copy reads the
// client's memory in place): every frame still completes with finite pixels, the daemon survives.
TEST_F(Daemon, ConcurrentWritesToAnInputSlotAreTolerated) {
    auto c = open_session(path());
    ASSERT_TRUE(c);
    RawSession& s = *c->s;
    std::atomic<bool> stop{false};
    std::byte* slot = s.slot(0);
    const size_t bytes = size_t(s.layout().input_slot_stride);
    std::thread scribbler([&] {
        uint32_t x = 12345;
        while (!stop.load(std::memory_order_relaxed))
            for (size_t i = 0; i < bytes; i += 4) {
                x = x * 1664525u + 1013904223u; // arbitrary bits: NaN, Inf, huge, negative
                std::memcpy(slot + i, &x, 4);
            }
    });
    for (int frame = 0; frame < 4; ++frame) {
        fgsr_submit_entry e = s.entry(0, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR);
        e.interp_count = 1;
        e.interp_alphas[0] = 0.5f;
        s.push(e);
        auto v = s.wait_submit();
        ASSERT_EQ(v.size(), 2u);
        for (const auto& ce : v) {
            if (frame > 0 || ce.telemetry.frame_type == FGSR_FRAME_UPSCALED) {
                EXPECT_EQ(ce.status, FGSR_STATUS_OK);
            }
            if (ce.output_slot == FGSR_NO_SLOT) continue;
            const auto* px = reinterpret_cast<const float*>(s.out_slot(ce.output_slot));
            bool finite = true;
            for (size_t i = 0; i < size_t(s.layout().output.size) / 4; ++i) finite &= std::isfinite(px[i]);
            EXPECT_TRUE(finite) << "frame " << frame;
            s.release(ce.output_slot);
        }
    }
    stop = true;
    scribbler.join();
    EXPECT_TRUE(daemon_->running());
}

// The daemon's resources, counted from /proc.
struct Usage {
    int fds = 0, maps = 0;
    long memfd_bytes = 0, rss_kib = 0;
};
// Lines of the daemon's /proc/<pid>/maps; in ThreadSanitizer builds only those with a path (files,
// memfds, devices). Its runtime maps shadow and metadata for the heap as the heap grows, anonymous
// regions in its own address ranges (0x1f00..., 0x3000..., 0x7b...): seen 4 to 7 lines more after
// the session-state kills, creeping by one now and then, and none of them the daemon's.
int counted_mappings(const FgsrdProcess& d) {
#ifdef FGSR_TEST_TSAN
    const std::vector<std::string> lines = d.mappings();
    return int(std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
        // address perms offset dev inode [path]: a path is a sixth field
        std::istringstream in(l);
        std::string field;
        int n = 0;
        while (in >> field) ++n;
        return n >= 6;
    }));
#else
    return d.mapping_count();
#endif
}

Usage usage(const FgsrdProcess& d) {
    return {d.fd_count(), counted_mappings(d), d.memfd_mapped_bytes(), d.rss_kib()};
}

// Waits until the daemon's fd count returns to `base` and its mapping count to `base` + extra_maps or below
// (teardown is asynchronous to the kill); returns the last usage seen.
Usage settle(const FgsrdProcess& d, const Usage& base, int extra_maps = 0) {
    Usage u;
    for (int i = 0; i < 500; ++i) {
        u = usage(d);
        if (u.fds == base.fds && u.maps <= base.maps + extra_maps && u.memfd_bytes == 0) break;
        usleep(20000);
    }
    return u;
}

// Waits until the daemon holds no session memory and its counts stay put for 100 ms.
Usage quiesce(const FgsrdProcess& d) {
    Usage u = usage(d);
    for (int i = 0; i < 100; ++i) {
        usleep(100000);
        const Usage v = usage(d);
        if (v.fds == u.fds && v.maps == u.maps && v.memfd_bytes == 0) return v;
        u = v;
    }
    return u;
}

enum class State { connected, hello, session, submitting };

// A child process that reaches `state`, tells the parent through `ready`, and keeps going.
pid_t spawn_client(const std::string& path, State state, int ready) {
    const pid_t pid = fork();
    if (pid != 0) return pid;
    auto report = [&] {
        const char b = 1;
        (void)!write(ready, &b, 1);
    };
    if (state == State::connected || state == State::hello) {
        auto raw = Raw::connect(path);
        if (!raw) _exit(1);
        if (state == State::hello && raw->hello().status != FGSR_STATUS_OK) _exit(1);
        report();
        for (;;) pause();
    }
    auto c = open_session(path);
    if (!c) _exit(1);
    if (state == State::session) {
        report();
        for (;;) pause();
    }
    bool reported = false;
    for (uint32_t k = 0;; ++k) {
        c->s->fill(k % 3, float(k));
        c->s->push(c->s->entry(k % 3, FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR));
        auto v = c->s->wait_submit();
        for (auto& ce : v)
            if (ce.output_slot != FGSR_NO_SLOT) c->s->release(ce.output_slot);
        if (!reported && k >= 1) {
            report();
            reported = true;
        }
    }
}

// AddressSanitizer builds: ASan's allocator keeps freed blocks in a quarantine (256 MiB) instead of
// returning them, and serves large blocks from mappings of their own, so the mappings of a killed
// session's freed buffers stay (or split their neighbours) until the quarantine recycles them: one
// or two more lines in /proc/<pid>/maps per cycle and RSS that only grows, with no leak. The daemon
// of this test runs without the quarantine there, which makes its mapping count as exact as in
// the other builds; leaks of heap memory are LeakSanitizer's, at the daemon's exit.
// (ThreadSanitizer builds count only the mappings with a path: counted_mappings.)
#if defined(FGSR_TEST_ASAN)
constexpr int kSanitizerRegions = 2;
#else
constexpr int kSanitizerRegions = 0;
#endif

// The lines of `now` (/proc/<pid>/maps) that `before` does not have, one per line.
std::string mappings_not_in(const std::vector<std::string>& now, const std::vector<std::string>& before) {
    std::string out = "mappings not in the baseline:\n";
    for (const std::string& line : now)
        if (std::find(before.begin(), before.end(), line) == before.end()) out += "  " + line + "\n";
    return out;
}

TEST(DaemonProcess, KillNineAtEachProtocolStateLeavesNoFdOrMappingBehind) {
    auto d = [] {
        const AsanOptionForChildren no_quarantine("quarantine_size_mb=0");
        return FgsrdProcess::start();
    }();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    // Warm up once (first-session allocations that stay, e.g. driver caches and the code of
    // every pipeline variant: first frame, moving frames, still frames with tile skipping), then
    // the baseline.
    {
        auto c = open_session(d->socket_path());
        ASSERT_TRUE(c);
        for (float shift : {0.f, 1.f, 2.f, 3.f, 3.f, 3.f}) ASSERT_EQ(roundtrip(*c->s, shift).size(), 1u);
    }
    const Usage base = quiesce(*d);
    const std::vector<std::string> base_maps = d->mappings();
    ASSERT_GT(base.fds, 0);
    for (State st : {State::connected, State::hello, State::session, State::submitting}) {
        for (int round = 0; round < 2; ++round) {
            SCOPED_TRACE("state " + std::to_string(int(st)) + " round " + std::to_string(round));
            int p[2];
            ASSERT_EQ(pipe2(p, O_CLOEXEC), 0);
            const pid_t child = spawn_client(d->socket_path(), st, p[1]);
            close(p[1]);
            char b = 0;
            pollfd pf{p[0], POLLIN, 0};
            ASSERT_EQ(poll(&pf, 1, 30000), 1);
            ASSERT_EQ(read(p[0], &b, 1), 1);
            close(p[0]);
            const Usage during = usage(*d);
            if (st == State::session || st == State::submitting) {
                EXPECT_GT(during.memfd_bytes, 0);
            }
            if (st != State::connected) { // accepted by now
                EXPECT_GT(during.fds, base.fds);
            }
            kill(child, SIGKILL);
            int status = 0;
            waitpid(child, &status, 0);
            const Usage after = settle(*d, base, kSanitizerRegions);
            EXPECT_EQ(after.fds, base.fds);
            // Nothing left behind: no more mappings than at the baseline. Fewer is not a leak:
            // under ASan its allocator returns regions of the warm-up's blocks to the kernel at
            // its own pace (seen: 488 at the baseline, 485 after a later kill). It also maps
            // regions at its own pace: seen, one anonymous 536 KiB rw region more after the
            // second session-state kill, 2 fewer than the baseline after the next two kills. So
            // under ASan up to kSanitizerRegions more; the regular build (in the main suite) is exact,
            // and LeakSanitizer checks the heap at the daemon's exit.
            EXPECT_LE(after.maps, base.maps + kSanitizerRegions) << mappings_not_in(d->mappings(), base_maps);
            EXPECT_EQ(after.memfd_bytes, 0);
            // Resident memory: no growth beyond allocator noise per cycle.
            EXPECT_LT(after.rss_kib, base.rss_kib + 32 * 1024);
            std::printf("[ kill -9 ] state %d: fds %d -> %d -> %d, maps %d -> %d -> %d, rss %ld -> %ld KiB\n",
                        int(st), base.fds, during.fds, after.fds, base.maps, during.maps, after.maps,
                        base.rss_kib, after.rss_kib);
        }
    }
    EXPECT_TRUE(d->running());
    const std::string err = d->stderr_text();
    EXPECT_EQ(err.find("validation error"), std::string::npos) << err;
}

TEST(DaemonProcess, SigtermShutsDownCleanlyAndRemovesTheSocket) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto c = open_session(d->socket_path());
    ASSERT_TRUE(c);
    ASSERT_EQ(roundtrip(*c->s, 0.f).size(), 1u);
    const int status = d->terminate();
    EXPECT_TRUE(WIFEXITED(status)) << status;
    EXPECT_EQ(WEXITSTATUS(status), 0);
    EXPECT_NE(access(d->socket_path().c_str(), F_OK), 0) << "socket file left behind";
    EXPECT_TRUE(c->raw.closed_by_daemon(5000));
    EXPECT_NE(d->stderr_text().find("shutting down"), std::string::npos);
}

// --warm-up: the engine's warm-up runs (and is logged) before the socket accepts; then the
// daemon serves as usual.
TEST(DaemonProcess, WarmUpRunsBeforeListening) {
    auto d = FgsrdProcess::start({"--warm-up", "--log-level", "info"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto c = open_session(d->socket_path());
    ASSERT_TRUE(c);
    EXPECT_EQ(roundtrip(*c->s, 0.f).size(), 1u);
    const std::string err = d->stderr_text();
    const size_t warmed = err.find("warmed up in"), listening = err.find("listening on");
    ASSERT_NE(warmed, std::string::npos) << err;
    ASSERT_NE(listening, std::string::npos) << err;
    EXPECT_LT(warmed, listening) << err;
    EXPECT_EQ(err.find("warm-up failed"), std::string::npos) << err;
}

TEST(DaemonProcess, ClientsBeyondMaxClientsGetBusy) {
    auto d = FgsrdProcess::start({"--max-clients", "1"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    auto first = Raw::connect(d->socket_path());
    ASSERT_TRUE(first);
    ASSERT_EQ(first->hello().status, FGSR_STATUS_OK);
    auto second = Raw::connect(d->socket_path());
    ASSERT_TRUE(second);
    EXPECT_EQ(second->hello().status, FGSR_STATUS_BUSY);
    EXPECT_TRUE(second->closed_by_daemon());
    first.reset(); // its slot frees once the daemon sees the hang-up
    bool served = false;
    for (int i = 0; i < 100 && !served; ++i) {
        auto again = Raw::connect(d->socket_path());
        served = again && again->hello().status == FGSR_STATUS_OK;
        if (!served) usleep(20000);
    }
    EXPECT_TRUE(served);
}

// Connections that never say HELLO cannot pile up: beyond --max-pending the oldest is closed,
// and each is closed after --hello-timeout; clients that do say HELLO are served meanwhile.
TEST(DaemonProcess, ConnectionsWithoutHelloAreBoundedAndTimedOut) {
    auto d = FgsrdProcess::start({"--max-pending", "4", "--hello-timeout", "0.5"});
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    const int baseline = d->fd_count();
    ASSERT_GT(baseline, 0);
    std::vector<Raw> idle;
    for (int i = 0; i < 12; ++i) {
        auto r = Raw::connect(d->socket_path());
        ASSERT_TRUE(r);
        idle.push_back(std::move(*r));
    }
    // The first 8 were closed as newer ones arrived (oldest first), the last 4 wait.
    for (int i = 0; i < 8; ++i) EXPECT_TRUE(idle[size_t(i)].closed_by_daemon(2000)) << i;
    EXPECT_LE(d->fd_count(), baseline + 4);
    auto good = Raw::connect(d->socket_path());
    ASSERT_TRUE(good);
    EXPECT_EQ(good->hello().status, FGSR_STATUS_OK);
    // After the timeout the waiting ones are closed too; the client that said HELLO stays.
    for (int i = 8; i < 12; ++i) EXPECT_TRUE(idle[size_t(i)].closed_by_daemon(5000)) << i;
    EXPECT_FALSE(good->closed_by_daemon(300));
    // At most the served client's fd above the baseline (the baseline, taken right after start, may
    // include a transient fd of the daemon's start-up).
    EXPECT_LE(d->fd_count(), baseline + 1);
    EXPECT_NE(d->stderr_text().find("no HELLO in time"), std::string::npos);
}

// Another uid: refused by SO_PEERCRED unless --allow-any-user (needs root to switch uid).
TEST(DaemonProcess, OtherUsersArePermissionDeniedUnlessAllowed) {
    if (geteuid() != 0) GTEST_SKIP() << "needs root to connect as another user";
    for (bool allow : {false, true}) {
        auto d = allow ? FgsrdProcess::start({"--allow-any-user"}) : FgsrdProcess::start();
        ASSERT_TRUE(d) << FgsrdProcess::last_error();
        // Let the other user reach the socket file, so that only the daemon's check decides.
        chmod(d->dir().c_str(), 0755);
        chmod(d->socket_path().c_str(), 0666);
        int p[2];
        ASSERT_EQ(pipe2(p, O_CLOEXEC), 0);
        const pid_t child = fork();
        if (child == 0) {
            int32_t status = -1;
            if (setgid(65534) == 0 && setuid(65534) == 0)
                if (auto raw = Raw::connect(d->socket_path())) status = raw->hello().status;
            (void)!write(p[1], &status, sizeof(status));
            _exit(0);
        }
        close(p[1]);
        int32_t status = -2;
        EXPECT_EQ(read(p[0], &status, sizeof(status)), ssize_t(sizeof(status)));
        close(p[0]);
        waitpid(child, nullptr, 0);
        EXPECT_EQ(status, allow ? FGSR_STATUS_OK : FGSR_STATUS_PERMISSION_DENIED) << "allow " << allow;
    }
}

TEST(DaemonProcess, DefaultSocketLivesInXdgRuntimeDir) {
    char tmpl[] = "/tmp/fgsrd-xdg-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    const std::string xdg = tmpl, dir = xdg + "/fgsr", path = dir + "/fgsrd.sock";
    const pid_t p = FgsrdProcess::spawn({std::string(FGSR_BIN_DIR) + "/fgsrd"}, xdg + "/stderr.log",
                                        {"XDG_RUNTIME_DIR=" + xdg});
    ASSERT_GT(p, 0);
    std::optional<Raw> raw;
    for (int i = 0; i < 3000 && !raw; ++i) {
        raw = Raw::connect(path);
        if (!raw) usleep(20000);
    }
    ASSERT_TRUE(raw);
    EXPECT_EQ(raw->hello().status, FGSR_STATUS_OK);
    struct stat st {};
    ASSERT_EQ(stat(dir.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0700u);
    ASSERT_EQ(stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    kill(p, SIGTERM);
    int status = 0;
    ASSERT_EQ(waitpid(p, &status, 0), p);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    EXPECT_NE(access(path.c_str(), F_OK), 0);
    std::error_code ec;
    std::filesystem::remove_all(xdg, ec);
}

TEST(DaemonProcess, SecondDaemonOnTheSameSocketRefusesToStart) {
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    const std::string err = d->dir() + "/second.log";
    const pid_t p =
        FgsrdProcess::spawn({std::string(FGSR_BIN_DIR) + "/fgsrd", "--socket", d->socket_path()}, err);
    int status = 0;
    ASSERT_EQ(waitpid(p, &status, 0), p);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0);
    auto raw = Raw::connect(d->socket_path());
    ASSERT_TRUE(raw);
    EXPECT_EQ(raw->hello().status, FGSR_STATUS_OK) << "the first daemon still serves";
}

TEST(DaemonProcess, SocketActivationUsesTheInheritedSocket) {
    char tmpl[] = "/tmp/fgsrd-act-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    const std::string dir = tmpl, path = dir + "/act.sock";
    Fd ls(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strcpy(a.sun_path, path.c_str());
    ASSERT_EQ(bind(ls.fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    ASSERT_EQ(listen(ls.fd, 8), 0);
    const pid_t p =
        FgsrdProcess::spawn({std::string(FGSR_BIN_DIR) + "/fgsrd", "--socket", dir + "/unused.sock"},
                            dir + "/stderr.log", {}, ls.fd, 3);
    ASSERT_GT(p, 0);
    // The listening socket already accepts (backlog); HELLO is answered once fgsrd runs.
    auto raw = Raw::connect(path);
    ASSERT_TRUE(raw);
    EXPECT_EQ(raw->hello().status, FGSR_STATUS_OK);
    EXPECT_NE(access((dir + "/unused.sock").c_str(), F_OK), 0) << "--socket ignored under activation";
    kill(p, SIGTERM);
    int status = 0;
    ASSERT_EQ(waitpid(p, &status, 0), p);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    EXPECT_EQ(access(path.c_str(), F_OK), 0) << "the activated socket belongs to systemd";
    unlink(path.c_str());
    unlink((dir + "/stderr.log").c_str());
    rmdir(dir.c_str());
}

// The same frames through a zero-copy daemon and a staging daemon give identical output bytes.
TEST(DaemonProcess, ZeroCopyAndStagingGiveIdenticalOutputs) {
    auto zc = FgsrdProcess::start();
    auto st = FgsrdProcess::start({"--no-zero-copy"});
    ASSERT_TRUE(zc && st) << FgsrdProcess::last_error();
    auto a = open_session(zc->socket_path()), b = open_session(st->socket_path());
    ASSERT_TRUE(a && b);
    auto caps = [](const std::string& path) {
        auto raw = Raw::connect(path);
        return raw ? raw->hello().capabilities : 0u;
    };
    const bool zero_copy = (caps(zc->socket_path()) & FGSR_CAP_ZERO_COPY_INPUT) != 0;
    EXPECT_EQ(caps(st->socket_path()) & FGSR_CAP_ZERO_COPY_INPUT, 0u);
    const size_t out_bytes = size_t(a->s->layout().output.size);
    for (int frame = 0; frame < 3; ++frame) {
        std::vector<std::vector<std::byte>> outs[2];
        Conn* conns[2] = {&*a, &*b};
        for (int k = 0; k < 2; ++k) {
            RawSession& s = *conns[k]->s;
            s.fill(uint32_t(frame), float(frame) * 1.5f, 1.5f);
            fgsr_submit_entry e = s.entry(uint32_t(frame), FGSR_SUBMIT_HAS_MV | FGSR_SUBMIT_WANT_SR);
            e.interp_count = 1;
            e.interp_alphas[0] = 0.5f;
            e.jitter_x = 0.25f * float(frame % 2);
            s.push(e);
            auto v = s.wait_submit();
            ASSERT_EQ(v.size(), 2u);
            for (auto& ce : v) {
                if (ce.output_slot == FGSR_NO_SLOT) {
                    outs[k].emplace_back();
                    continue;
                }
                const std::byte* px = s.out_slot(ce.output_slot);
                outs[k].emplace_back(px, px + out_bytes);
                s.release(ce.output_slot);
            }
        }
        ASSERT_EQ(outs[0].size(), outs[1].size());
        for (size_t i = 0; i < outs[0].size(); ++i)
            EXPECT_TRUE(outs[0][i] == outs[1][i]) << "frame " << frame;
    }
    auto stats = [](Conn& c) {
        fgsr_session_ref ref{};
        ref.header = header(FGSR_MSG_STATS, sizeof(ref), 5);
        ref.session_id = c.s->reply.session_id;
        c.raw.send(&ref, sizeof(ref));
        return as<fgsr_stats_reply>(c.raw.recv()).stats;
    };
    const uint64_t frame_bytes = uint64_t(kW) * kH * (16 + 4 + 8);
    EXPECT_EQ(stats(*b).bytes_copied, 3 * frame_bytes);
    if (zero_copy)
        EXPECT_EQ(stats(*a).bytes_copied, 0u);
    else
        std::printf("[ note ] the device cannot import host memory: both daemons copied\n");
}

} // namespace
} // namespace fgsr::test
