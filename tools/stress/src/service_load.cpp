// Scenarios 3 and 4 of `fgsr stress --service`: a heavy session next to a small well-behaved
// client (its p99 round trip with and without the heavy one, HELLO throughout), and idle clients
// filling the daemon (eviction of the longest idle, --idle-timeout).
#include "service_internal.hpp"

#include <atomic>
#include <mutex>
#include <thread>
#include <unistd.h>

namespace fgsr::stress::service {

namespace {

// A new connection's HELLO status (-1: no connection or no reply) and the connection.
int32_t hello_status(const std::string& socket, std::optional<raw::Connection>& conn,
                     int timeout_ms = 10000) {
    conn = raw::Connection::connect(socket);
    if (!conn) return -1;
    const auto h = conn->hello(timeout_ms);
    return h ? h->status : -1;
}

const char* status_text(int32_t st) {
    return st < 0 ? "no reply" : fgsr_status_string(st);
}

// Round trips (ms, push to LAST completion) of `frames` frames of the small session.
std::vector<double> small_frames(Run& r, raw::Session& s, uint32_t frames, uint32_t& frame_no) {
    std::vector<double> ms;
    for (uint32_t i = 0; i < frames; ++i, ++frame_no) {
        const uint32_t slot = frame_no % 3;
        s.fill(slot, float(frame_no * 2));
        fgsr_submit_entry e = s.entry(slot);
        e.interp_count = frame_no == 0 ? 0 : 1;
        e.interp_alphas[0] = 0.5f;
        const uint64_t t0 = raw::now_ns();
        s.push({e});
        auto v = s.wait_submit(60000);
        const double t = raw::ms_since(t0);
        for (const auto& c : v)
            if (c.output_slot != FGSR_NO_SLOT) s.release(c.output_slot);
        if (!r.check(!v.empty() && v.back().status == FGSR_STATUS_OK, "small client frame failed")) break;
        if (frame_no > 0) ms.push_back(t);
        usleep(20000); // a client at about 30-50 fps, not a saturating one
    }
    return ms;
}

} // namespace

void heavy_session(Run& r) {
    const uint32_t side = r.opt.heavy_size ? r.opt.heavy_size : r.opt.quick ? 1024 : 4096;
    const uint32_t frames = r.opt.quick ? 20 : 60;
    // The heavy session must land on the bulk lane, the 480x270 client on the interactive one.
    if (!r.start({"--interactive-pixels",
                  std::to_string(std::min<uint64_t>(uint64_t(side) * side - 1, 1920 * 1080))}))
        return;
    std::string why;
    auto small = raw::open_client(r.socket(), raw::small_desc(480, 270), &why);
    if (!r.check(bool(small), "small session: " + why)) return;

    std::atomic<bool> stop{false}, heavy_running{false};
    std::mutex hello_mutex;
    std::vector<double> hello_alone, hello_heavy;
    std::thread hello_thread([&] {
        while (!stop) {
            const double ms = raw::hello_ms(r.socket(), 2000);
            {
                std::lock_guard lock(hello_mutex);
                (heavy_running ? hello_heavy : hello_alone).push_back(ms < 0 ? 2000.0 : ms);
            }
            usleep(50000);
        }
    });
    uint32_t frame_no = 0;
    r.note(fmt::format("small 480x270 client alone: {} frames", frames));
    const std::vector<double> alone = small_frames(r, *small->session, frames, frame_no);

    fgsr_session_desc hd = raw::small_desc(side, side);
    hd.color_format = hd.output_format = FGSR_COLOR_RGBA8_SRGB;
    hd.mv_format = FGSR_MV_RG16F;
    hd.output_slots = 8;
    auto heavy = raw::open_client(r.socket(), hd, &why);
    std::atomic<uint32_t> heavy_submits{0};
    std::vector<double> heavy_ms;
    std::atomic<bool> stop_heavy{false}, heavy_failed{false};
    std::thread heavy_thread;
    if (r.check(bool(heavy), fmt::format("heavy {}x{} session: {}", side, side, why))) {
        for (uint32_t i = 0; i < 3; ++i) heavy->session->fill(i, float(i * 3));
        heavy_thread = std::thread([&] {
            raw::Session& s = *heavy->session;
            for (uint32_t f = 0; !stop_heavy; ++f) {
                fgsr_submit_entry e = s.entry(f % 3);
                e.interp_count = f == 0 ? 0 : 8;
                for (uint32_t k = 0; k < e.interp_count; ++k) e.interp_alphas[k] = float(k + 1) / 9.f;
                const uint64_t t0 = raw::now_ns();
                s.push({e});
                bool last = false;
                while (!last && !stop_heavy) {
                    auto c = s.wait(200);
                    if (!c) continue;
                    if (c->output_slot != FGSR_NO_SLOT) s.release(c->output_slot);
                    if (c->status != FGSR_STATUS_OK) heavy_failed = true;
                    last = c->flags & FGSR_COMPLETION_LAST;
                }
                if (!last) break;
                heavy_ms.push_back(raw::ms_since(t0));
                ++heavy_submits;
                heavy_running = true; // after the first submit: eight interpolations per submit from here on
            }
        });
        r.note(
            fmt::format("heavy {}x{} session, 8 interpolated frames per submit: waiting for its first submit",
                        side, side));
        const uint64_t t0 = raw::now_ns();
        while (!heavy_running && raw::ms_since(t0) < 300000 && !heavy_failed) usleep(20000);
    }
    std::vector<double> with;
    if (heavy_running) {
        r.note(fmt::format("small client with the heavy session running: {} frames", frames));
        // Keep measuring until the heavy session has run at least one 8-interpolation submit.
        with = small_frames(r, *small->session, frames, frame_no);
        const uint64_t t0 = raw::now_ns();
        while (heavy_submits < 2 && raw::ms_since(t0) < 300000)
            for (double v : small_frames(r, *small->session, 5, frame_no)) with.push_back(v);
    }
    stop_heavy = true;
    if (heavy_thread.joinable()) heavy_thread.join();
    stop = true;
    hello_thread.join();
    r.check(!heavy_failed, "the heavy session's frames failed");

    const double p50a = percentile(alone, 50), p99a = percentile(alone, 99);
    const double p50h = percentile(with, 50), p99h = percentile(with, 99);
    const double ratio = p99a > 0 ? p99h / p99a : 0;
    std::vector<double> all_hello = hello_alone;
    all_hello.insert(all_hello.end(), hello_heavy.begin(), hello_heavy.end());
    const double hello_max = max_of(all_hello), hello_max_heavy = max_of(hello_heavy);
    std::vector<double> heavy_8(heavy_ms.size() > 1 ? heavy_ms.begin() + 1 : heavy_ms.end(), heavy_ms.end());
    r.result.metrics.update({{"heavy_side", side},
                             {"small_frames_alone", alone.size()},
                             {"small_frames_with_heavy", with.size()},
                             {"p50_alone_ms", p50a},
                             {"p99_alone_ms", p99a},
                             {"p50_with_heavy_ms", p50h},
                             {"p99_with_heavy_ms", p99h},
                             {"p99_ratio", ratio},
                             {"hello_max_ms", hello_max},
                             {"hello_max_with_heavy_ms", hello_max_heavy},
                             {"hello_p99_ms", percentile(all_hello, 99)},
                             {"hello_samples", all_hello.size()},
                             {"heavy_submits", heavy_submits.load()},
                             {"heavy_submit_median_ms", percentile(heavy_8, 50)}});
    r.check(!with.empty(), "no frames measured with the heavy session running");
    r.check(ratio <= p99_ratio_limit(r.opt),
            fmt::format("p99 with the heavy session {:.1f} ms is {:.2f} x the p99 alone {:.1f} ms "
                        "(limit {:.0f})",
                        p99h, ratio, p99a, p99_ratio_limit(r.opt)));
    r.check(hello_max <= hello_limit_ms(r.opt),
            fmt::format("max HELLO {:.1f} ms (limit {:.0f})", hello_max, hello_limit_ms(r.opt)));
    r.result.measured =
        fmt::format("heavy {}x{} (8 interps/submit, median {:.0f} ms, {} submits): small 480x270 p99 "
                    "alone {:.1f} ms, with heavy {:.1f} ms, ratio {:.2f}; max HELLO {:.1f} ms ({} "
                    "samples)",
                    side, side, percentile(heavy_8, 50), heavy_submits.load(), p99a, p99h, ratio, hello_max,
                    all_hello.size());
    r.served("heavy-session");
}

void idle_clients(Run& r) {
    if (!r.own_daemon_possible()) return r.skip("needs its own daemon (--idle-timeout)");
    const uint32_t m = r.opt.max_clients;
    const double idle_timeout = r.opt.quick ? 2.0 : 4.0;
    if (!r.start({"--max-clients", std::to_string(m), "--max-clients-per-uid", std::to_string(m + 4),
                  "--idle-timeout", fmt::format("{}", idle_timeout)}))
        return;
    std::vector<raw::Connection> idle;
    for (uint32_t i = 0; i < m; ++i) {
        std::optional<raw::Connection> c;
        if (!r.check(hello_status(r.socket(), c) == FGSR_STATUS_OK,
                     fmt::format("idle client {} not served", i)))
            return;
        idle.push_back(std::move(*c));
    }
    // Full, nobody idle for a second yet: BUSY.
    {
        std::optional<raw::Connection> c;
        const int32_t st = hello_status(r.socket(), c);
        r.result.metrics["when_full_and_fresh"] = status_text(st);
        r.check(st == FGSR_STATUS_BUSY,
                std::string("a client beyond --max-clients got ") + status_text(st) + ", not BUSY");
    }
    usleep(1200000);
    // Now the longest idle one is evicted for a new client, which is served at once.
    const uint64_t t0 = raw::now_ns();
    std::optional<raw::Connection> fresh;
    const int32_t st = hello_status(r.socket(), fresh, 2000);
    const double hello = raw::ms_since(t0);
    r.result.metrics["hello_when_full_ms"] = hello;
    if (!r.check(st == FGSR_STATUS_OK,
                 std::string("a new client got ") + status_text(st) + " while idle ones held every place"))
        return;
    r.check(hello <= hello_limit_ms(r.opt), fmt::format("HELLO when full took {:.1f} ms", hello));
    int evicted = 0;
    std::vector<bool> gone(idle.size(), false);
    for (size_t i = 0; i < idle.size(); ++i) evicted += (gone[i] = idle[i].next_event(0) == "closed");
    r.result.metrics["evicted"] = evicted;
    r.check(evicted == 1, fmt::format("{} idle clients evicted for one new client (expected 1)", evicted));
    std::string why;
    auto s = raw::create_session(*fresh, raw::small_desc(64, 64), &why);
    if (!r.check(bool(s), "the new client's session: " + why)) return;
    // The others go after --idle-timeout; the working client stays.
    uint32_t frames = 0;
    const uint64_t t1 = raw::now_ns();
    while (raw::ms_since(t1) < (idle_timeout + 1.5) * 1000) {
        r.check(!raw::roundtrip(*s, float(frames), frames % 3).empty(), "the new client's frame failed");
        ++frames;
        usleep(300000);
    }
    int closed = 0;
    for (size_t i = 0; i < idle.size(); ++i) closed += !gone[i] && idle[i].closed_by_daemon(100);
    r.result.metrics["closed_after_idle_timeout"] = closed + evicted;
    r.check(closed + evicted == int(m), fmt::format("{} of {} idle clients closed after --idle-timeout {} s",
                                                    closed + evicted, m, idle_timeout));
    r.check(fresh->next_event(0) != "closed", "the working client was closed");
    r.result.measured =
        fmt::format("{} idle clients: BUSY at once, after 1.2 s a new client evicted {} and got HELLO "
                    "in {:.1f} ms; {} closed after --idle-timeout {} s; the working client kept "
                    "({} frames)",
                    m, evicted, hello, closed, idle_timeout, frames);
    r.served("idle-clients");
}

} // namespace fgsr::stress::service
