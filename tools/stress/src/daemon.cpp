// The daemon feeder of the numerical stress cases (see fgsr/stress/daemon.hpp).
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/session_desc.hpp>
#include <fgsr/capture/stress_checks.hpp>
#include <fgsr/client.hpp>
#include <fgsr/stress/client_planes.hpp>
#include <fgsr/stress/daemon.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>

namespace fgsr::stress {

namespace {

constexpr uint32_t kWaitMs = 120000; // one submit's outputs; generous for lavapipe
constexpr uint32_t kOutputSlots = 2 * FGSR_MAX_ALPHAS + 1;

std::string where(size_t i, const Step& s) {
    return step_where(i, s.op);
}

// Why the case's Params cannot be sent in a fgsr_session_desc (empty: they can).
std::string inexpressible_params(const Params& p) {
    const Params d;
    std::string why;
    auto add = [&](const std::string& s) { why += (why.empty() ? "" : ", ") + s; };
    if (!p.lut.empty()) add("a custom LUT");
    if (p.blend != d.blend) add("the blend mode");
    if (p.resample != d.resample) add("history resampling");
    if (p.separate_passes != d.separate_passes) add("separate passes");
    if (p.fill_gaps != d.fill_gaps || p.fill_holes != d.fill_holes) add("gap and hole filling switches");
    // On the wire 0 means "the engine's default".
    if (p.t_depth == 0.f && d.t_depth != 0.f) add("t_depth = 0 (0 means the default)");
    if (p.t_bright == 0.f && d.t_bright != 0.f) add("t_bright = 0 (0 means the default)");
    if (p.sr_a == 0.f && d.sr_a != 0.f) add("sr_a = 0 (0 means the default)");
    if (p.sr_b == 0.f && d.sr_b != 0.f) add("sr_b = 0 (0 means the default)");
    if (why.empty()) return why;
    return "fgsr_session_desc cannot express " + why;
}

fgsr_session_desc make_desc(const FrameFormat& f, const Params& p) {
    // Every mode the session may be asked for; SR only where the scale allows it (a request for SR
    // in a session that does not upscale is then refused by the client, as the engine refuses it).
    fgsr_session_desc d = capture::session_desc(
        f, p, FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE | (p.scale > 1.f ? FGSR_MODE_SR : 0u));
    d.input_slots = 2;
    d.output_slots = kOutputSlots;
    return d;
}

// True when libfgsr_client must refuse the request before sending it (fgsr_submit's checks).
bool refused_by_client(const Step& r, float scale) {
    if (r.op == Op::super_resolve) return !(scale > 1.f);
    if (r.alphas.size() > FGSR_MAX_ALPHAS) return true;
    for (float a : r.alphas)
        if (!std::isfinite(a) || a <= 0.f || a > 1.f || (r.op == Op::interpolate && a >= 1.f)) return true;
    return false;
}

// A tightly packed plane of `rows` rows into a slot.
void copy_plane(void* dst, uint32_t pitch, const std::vector<std::byte>& src, uint32_t rows) {
    stress::copy_plane(dst, pitch, src, rows ? src.size() / rows : 0, rows);
}

std::string status_name(int32_t s) {
    return fgsr_status_string(s);
}

class DaemonRunner {
  public:
    DaemonRunner(const DaemonTarget& t, const Case& c, CaseResult& r) : t_(t), c_(c), r_(r), checks_(r) {}

    bool fail(std::string why) { return checks_.fail(std::move(why)); }
    bool failed() const { return checks_.failed(); }
    void na(const std::string& what, const std::string& why) {
        r_.not_applicable.push_back(what + ": " + why);
    }

    bool run(const RunOptions& options) {
        if (const std::string why = inexpressible_params(c_.params); !why.empty()) {
            r_.applicable = false;
            r_.not_applicable.push_back(why);
            return true;
        }
        if (fgsr_status s = conn_.connect(t_.socket.c_str(), "fgsr-stress"); s != FGSR_STATUS_OK)
            return fail("cannot connect to fgsrd at " + t_.socket + ": " + status_name(s));
        if (!c_.reject_session.empty()) {
            session_rejected();
            return health();
        }
        mark_ = log_size();
        if (fgsr_status s = session_.create(conn_, make_desc(c_.format, c_.params)); s != FGSR_STATUS_OK)
            return fail("session refused: " + status_name(s) + log_reason_line("session refused"));
        (void)session_.layout(layout_);

        std::optional<Step> sub;
        size_t sub_index = 0;
        std::vector<std::pair<size_t, Step>> reqs;
        for (size_t i = 0; i < c_.step_count && !failed(); ++i) {
            if (options.progress && c_.step_count > options.progress_every && i % options.progress_every == 0)
                options.progress(c_.name + " (daemon): step " + std::to_string(i) + "/" +
                                 std::to_string(c_.step_count));
            Step st = c_.step(i);
            ++r_.steps_run;
            if (st.op == Op::submit) {
                if (sub) flush(sub_index, *sub, reqs);
                sub = std::move(st);
                sub_index = i;
                reqs.clear();
            } else if (!sub) {
                na(where(i, st), "a request before the first frame (every request rides on a submit)");
            } else {
                reqs.emplace_back(i, std::move(st));
            }
        }
        if (sub && !failed()) flush(sub_index, *sub, reqs);
        if (!failed()) checks_.check_min_drift(c_.min_drift_db);
        return health() && !failed();
    }

  private:
    size_t log_size() const { return t_.log ? t_.log().size() : 0; }

    // The first line of the daemon's log since mark_ that contains `needle` (" [log: ...]"), or "".
    std::string log_reason_line(const std::string& needle) const {
        if (!t_.log) return "";
        const std::string text = t_.log();
        size_t pos = std::min(mark_, text.size());
        while (pos < text.size()) {
            size_t end = text.find('\n', pos);
            if (end == std::string::npos) end = text.size();
            const std::string line = text.substr(pos, end - pos);
            if (contains_nocase(line, needle)) return " [log: " + line + "]";
            pos = end + 1;
        }
        return "";
    }

    // A rejection completed with `status`: the daemon's log (since mark_) must state the reason.
    bool daemon_rejection(const std::string& what, int32_t status, const std::string& reason) {
        if (!t_.log) {
            r_.rejections.push_back("fgsrd: " + status_name(status) +
                                    " (reason not checked: log not readable)");
            return true;
        }
        const std::string line = log_reason_line(reason);
        if (line.empty())
            return fail(what + ": completed with " + status_name(status) +
                        " but the daemon's log states no reason mentioning '" + reason + "'");
        r_.rejections.push_back("fgsrd: " + status_name(status) + ":" + line);
        return true;
    }

    bool session_rejected() {
        mark_ = log_size();
        client::Session s;
        const fgsr_status st = s.create(conn_, make_desc(c_.format, c_.params));
        if (st == FGSR_STATUS_OK)
            return fail("session created; expected a refusal mentioning '" + c_.reject_session + "'");
        // Refused by the daemon (a "session refused" line since mark_) or by the client before sending.
        const std::string refused = log_reason_line("session refused");
        if (!t_.log)
            r_.rejections.push_back(status_name(st) + " (reason not checked: log not readable)");
        else if (refused.empty())
            r_.rejections.push_back("client: " + status_name(st) + " (refused before sending)");
        else if (!contains_nocase(refused, c_.reject_session))
            return fail("the daemon refused the session but its log line does not mention '" +
                        c_.reject_session + "':" + refused);
        else
            r_.rejections.push_back("fgsrd: " + status_name(st) + ":" + refused);
        return good_session();
    }

    // The daemon serves a good session: two frames, one interpolation, finite output.
    bool good_session() {
        FrameFormat f;
        f.width = f.height = 16;
        Params p;
        fgsr_session_desc d = make_desc(f, p);
        client::Session s;
        if (fgsr_status st = s.create(conn_, d); st != FGSR_STATUS_OK)
            return fail("a good session after the refusal failed: " + status_name(st));
        fgsr_pool_layout l{};
        (void)s.layout(l);
        for (int k = 0; k < 2; ++k) {
            fgsr_input_slot in{};
            if (fgsr_status st = s.acquire_input(kWaitMs, in); st != FGSR_STATUS_OK)
                return fail("a good session: no input slot: " + status_name(st));
            std::memset(in.color, 0, l.color.size);
            for (uint64_t i = 0; i < l.depth.size / 4; ++i)
                static_cast<float*>(in.depth)[i] = 10.f + float(k);
            fgsr_submit_info si{};
            si.struct_size = sizeof(si);
            si.input_slot = in.index;
            const float a = 0.5f;
            si.interp_count = k == 1 ? 1 : 0;
            si.interp_alphas = &a;
            if (fgsr_status st = s.submit(si); st != FGSR_STATUS_OK)
                return fail("a good session: submit: " + status_name(st));
            for (;;) {
                fgsr_output out{};
                if (fgsr_status st = s.wait(kWaitMs, out); st != FGSR_STATUS_OK)
                    return fail("a good session: wait: " + status_name(st));
                if (out.status != FGSR_STATUS_OK)
                    return fail("a good session: output status " + status_name(out.status));
                if (out.output_slot != FGSR_NO_SLOT) {
                    const ImageRGBA img = output_image(out);
                    (void)s.release_output(out.output_slot);
                    if (!checks_.check_image(img, "a good session")) return false;
                }
                if (out.flags & FGSR_COMPLETION_LAST) break;
            }
        }
        return true;
    }

    // After the case: the process lives, the case's session answers STATS (with the daemon-side
    // frame rejections counted), a fresh client connects.
    bool health() {
        if (t_.alive && !t_.alive()) return fail("fgsrd is no longer running");
        if (session_) {
            fgsr_session_stats st{};
            if (fgsr_status s = session_.stats(st); s != FGSR_STATUS_OK)
                return fail("STATS after the case: " + status_name(s));
            if (st.frames_rejected != daemon_rejected_frames_)
                return fail("STATS counts " + std::to_string(st.frames_rejected) +
                            " rejected frames, the feeder saw " + std::to_string(daemon_rejected_frames_));
            session_.reset();
        }
        client::Connection fresh;
        if (fgsr_status s = fresh.connect(t_.socket.c_str(), "fgsr-stress-probe"); s != FGSR_STATUS_OK)
            return fail("a fresh client after the case: " + status_name(s));
        return true;
    }

    struct Expect {
        size_t req = 0;     // index into the group's requests
        std::string reject; // non-empty: must complete with a non-OK status, log stating this
        bool seen = false;
    };

    // One submit step and the requests that follow it: one fgsr_submit_info.
    void flush(size_t si_index, const Step& sub, std::vector<std::pair<size_t, Step>>& reqs) {
        const std::string sw = where(si_index, sub);
        const Frame& fr = sub.frame;
        const bool planes_ok = fr.color.size() == layout_.color.size &&
                               fr.depth.size() == layout_.depth.size &&
                               (fr.mv.empty() || fr.mv.size() == layout_.mv.size);
        auto rest_na = [&](const std::string& why) {
            for (auto& [i, r] : reqs) na(where(i, r), why);
        };
        if (!planes_ok) {
            if (sub.reject.empty()) {
                fail(sw + ": plane sizes differ from the session's layout");
                return;
            }
            na(sw, "plane sizes are fixed by the slot layout (colour " + std::to_string(layout_.color.size) +
                       ", depth " + std::to_string(layout_.depth.size) + ", vectors " +
                       std::to_string(layout_.mv.size) + " or none); this frame's are " +
                       std::to_string(fr.color.size()) + ", " + std::to_string(fr.depth.size()) + ", " +
                       std::to_string(fr.mv.size()));
            rest_na("rides on a frame that cannot be sent");
            return;
        }
        if (!held_) {
            fgsr_input_slot in{};
            if (fgsr_status s = session_.acquire_input(kWaitMs, in); s != FGSR_STATUS_OK) {
                fail(sw + ": no input slot: " + status_name(s));
                return;
            }
            held_ = in;
        }
        copy_plane(held_->color, layout_.color.row_pitch, fr.color, c_.format.height);
        copy_plane(held_->depth, layout_.depth.row_pitch, fr.depth, c_.format.height);
        copy_plane(held_->mv, layout_.mv.row_pitch, fr.mv, c_.format.height);
        fgsr_submit_info base{};
        base.struct_size = sizeof(base);
        base.input_slot = held_->index;
        base.flags = (fr.reset ? FGSR_SUBMIT_RESET : 0u) | (fr.mv.empty() ? 0u : FGSR_SUBMIT_HAS_MV);
        base.jitter_x = fr.jitter_x;
        base.jitter_y = fr.jitter_y;

        // Requests the client must refuse: each probed on its own.
        std::vector<bool> handled(reqs.size(), false);
        for (size_t q = 0; q < reqs.size(); ++q) {
            const auto& [i, r] = reqs[q];
            if (r.op != Op::super_resolve && r.alphas.empty()) {
                na(where(i, r), "an empty alpha list cannot be sent (a count of 0 means no such output)");
                handled[q] = true;
                continue;
            }
            if (r.reject.empty() || !refused_by_client(r, c_.params.scale)) continue;
            handled[q] = true;
            fgsr_submit_info probe = base;
            if (r.op == Op::super_resolve) probe.flags |= FGSR_SUBMIT_WANT_SR;
            if (r.op == Op::interpolate) {
                probe.interp_count = uint32_t(r.alphas.size());
                probe.interp_alphas = r.alphas.data();
            }
            if (r.op == Op::extrapolate) {
                probe.extrap_count = uint32_t(r.alphas.size());
                probe.extrap_alphas = r.alphas.data();
            }
            const fgsr_status s = session_.submit(probe);
            if (s == FGSR_STATUS_OK) {
                held_.reset();
                fail(where(i, r) + ": the client accepted a request that must be refused ('" + r.reject +
                     "')");
                return;
            }
            r_.rejections.push_back("client: " + status_name(s) + " (refused before sending)");
        }
        if (!sub.reject.empty() && !(std::isfinite(fr.jitter_x) && std::isfinite(fr.jitter_y))) {
            const fgsr_status s = session_.submit(base);
            if (s == FGSR_STATUS_OK) {
                held_.reset();
                fail(sw + ": the client accepted a non-finite jitter");
                return;
            }
            r_.rejections.push_back("client: " + status_name(s) + " (refused before sending)");
            for (size_t q = 0; q < reqs.size(); ++q)
                if (!handled[q]) na(where(reqs[q].first, reqs[q].second), "rides on a refused frame");
            return; // the slot stays acquired for the next frame
        }

        // The submit with every remaining request, outputs in presentation order.
        std::vector<float> interp, extrap;
        std::vector<Expect> interp_x, extrap_x;
        std::optional<Expect> sr_x;
        for (size_t q = 0; q < reqs.size(); ++q) {
            if (handled[q]) continue;
            const auto& [i, r] = reqs[q];
            if (r.across_cut) {
                na(where(i, r), "the check across a scene cut compares outputs with the session's stored "
                                "frames, which the protocol does not expose (run by the engine feeder)");
                handled[q] = true;
                continue;
            }
            if (!sub.reject.empty()) {
                na(where(i, r), "rides on a frame that must be refused");
                handled[q] = true;
                continue;
            }
            if (r.op == Op::super_resolve) {
                if (sr_x) {
                    na(where(i, r), "a second super-resolved output of one frame");
                    handled[q] = true;
                    continue;
                }
                sr_x = Expect{q, r.reject, false};
                continue;
            }
            std::vector<float>& list = r.op == Op::interpolate ? interp : extrap;
            if (list.size() + r.alphas.size() > FGSR_MAX_ALPHAS) {
                na(where(i, r), std::to_string(r.alphas.size()) + " alphas with " +
                                    std::to_string(list.size()) +
                                    " already in this submit exceed FGSR_MAX_ALPHAS (" +
                                    std::to_string(FGSR_MAX_ALPHAS) + ") per submit");
                handled[q] = true;
                continue;
            }
            for (float a : r.alphas) {
                list.push_back(a);
                (r.op == Op::interpolate ? interp_x : extrap_x).push_back(Expect{q, r.reject, false});
            }
        }
        std::vector<Expect> expect = interp_x;
        if (sr_x) expect.push_back(*sr_x);
        expect.insert(expect.end(), extrap_x.begin(), extrap_x.end());

        fgsr_submit_info info = base;
        info.flags |= sr_x ? FGSR_SUBMIT_WANT_SR : 0u;
        info.interp_count = uint32_t(interp.size());
        info.interp_alphas = interp.data();
        info.extrap_count = uint32_t(extrap.size());
        info.extrap_alphas = extrap.data();
        mark_ = log_size();
        if (fgsr_status s = session_.submit(info); s != FGSR_STATUS_OK) {
            if (!sub.reject.empty()) { // e.g. a check the client makes that the table did not foresee
                r_.rejections.push_back("client: " + status_name(s) + " (refused before sending)");
                return;
            }
            fail(sw + ": fgsr_submit: " + status_name(s));
            return;
        }
        held_.reset();

        std::vector<std::vector<ImageRGBA>> images(reqs.size());
        std::vector<bool> reason_recorded(reqs.size(), false);
        for (;;) {
            fgsr_output out{};
            if (fgsr_status s = session_.wait(kWaitMs, out); s != FGSR_STATUS_OK) {
                fail(sw + ": waiting for completions: " + status_name(s) +
                     (t_.alive && !t_.alive() ? " (fgsrd died)" : ""));
                return;
            }
            std::optional<ImageRGBA> img;
            if (out.output_slot != FGSR_NO_SLOT) {
                img = output_image(out);
                (void)session_.release_output(out.output_slot);
            }
            const bool last = (out.flags & FGSR_COMPLETION_LAST) != 0;
            if (!sub.reject.empty()) {
                if (out.status == FGSR_STATUS_OK) {
                    fail(sw + ": the daemon accepted a frame that must be refused ('" + sub.reject + "')");
                    return;
                }
                ++daemon_rejected_frames_;
                if (!daemon_rejection(sw, out.status, sub.reject)) return;
            } else if (expect.empty()) {
                if (out.status != FGSR_STATUS_OK || img) {
                    fail(sw + ": a submit without outputs completed with " + status_name(out.status));
                    return;
                }
            } else {
                if (out.output_index >= expect.size()) {
                    fail(sw + ": completion of output " + std::to_string(out.output_index) + " of " +
                         std::to_string(expect.size()));
                    return;
                }
                Expect& e = expect[out.output_index];
                e.seen = true;
                const auto& [ri, r] = reqs[e.req];
                const std::string rw = where(ri, r);
                if (e.reject.empty() && r.cut_allowed && out.status == FGSR_STATUS_NOT_READY) {
                    // Content the engine took for a scene cut: refused as after a reset.
                    if (!reason_recorded[e.req]) {
                        reason_recorded[e.req] = true;
                        if (!daemon_rejection(rw, out.status, "needs two submitted frames")) return;
                    }
                } else if (e.reject.empty()) {
                    if (out.status != FGSR_STATUS_OK || !img) {
                        fail(rw + " failed: " + status_name(out.status) + log_reason_line("session"));
                        return;
                    }
                    if (!checks_.check_image(*img, rw + " output " + std::to_string(out.output_index)))
                        return;
                    images[e.req].push_back(std::move(*img));
                } else {
                    if (out.status == FGSR_STATUS_OK) {
                        fail(rw + " was accepted; expected a rejection mentioning '" + e.reject + "'");
                        return;
                    }
                    if (!reason_recorded[e.req]) {
                        reason_recorded[e.req] = true;
                        if (!daemon_rejection(rw, out.status, e.reject)) return;
                    }
                }
            }
            if (last) break;
        }
        for (const Expect& e : expect)
            if (!e.seen) {
                fail(sw + ": output " + where(reqs[e.req].first, reqs[e.req].second) + " never completed");
                return;
            }

        // Determinism and drift, per request in step order.
        for (size_t q = 0; q < reqs.size(); ++q) {
            const auto& [i, r] = reqs[q];
            if (handled[q] || !r.reject.empty()) continue;
            if (!checks_.check_repeat_and_drift(r, images[q], where(i, r))) return;
        }
    }

    const DaemonTarget& t_;
    const Case& c_;
    CaseResult& r_;
    client::Connection conn_;
    client::Session session_;
    fgsr_pool_layout layout_{};
    std::optional<fgsr_input_slot> held_; // acquired, not yet submitted
    size_t mark_ = 0;                     // log length before the current submit
    uint64_t daemon_rejected_frames_ = 0;
    CaseChecks checks_;
};

} // namespace

CaseResult run_on_daemon(const DaemonTarget& target, const Case& c, const RunOptions& options,
                         size_t max_pixels) {
    CaseResult r;
    r.name = c.name;
    r.checks = c.checks;
    r.pass = true;
    const auto t0 = std::chrono::steady_clock::now();
    if (max_pixels > 0 && size_t(c.format.width) * c.format.height > max_pixels) {
        r.applicable = false;
        r.not_applicable.push_back("frames of " + std::to_string(c.format.width) + "x" +
                                   std::to_string(c.format.height) +
                                   " skipped through the daemon (too slow; run by the engine feeder)");
        return r;
    }
    {
        DaemonRunner runner(target, c, r);
        runner.run(options);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (c.max_seconds > 0 && r.pass && r.seconds > c.max_seconds) {
        r.pass = false;
        r.failure = "the case took " + std::to_string(r.seconds) +
                    " s through fgsrd, more than its bound of " + std::to_string(c.max_seconds) + " s";
    }
    return r;
}

} // namespace fgsr::stress
