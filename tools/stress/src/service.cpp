// `fgsr stress --service` (fgsr/stress/service.hpp): the shared checks and the scenario table.
#include "service_internal.hpp"

#include <fgsr/client.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <unistd.h>

namespace fgsr::stress {

namespace service {

bool Run::start(const std::vector<std::string>& args) {
    if (opt.fgsrd.empty()) return check(!opt.socket.empty(), "no fgsrd to start and no --socket");
    daemon = FgsrdProcess::start_at(opt.fgsrd, args, 60000, "fgsr-stress-service");
    if (!daemon) return check(false, "cannot start fgsrd: " + FgsrdProcess::last_error());
    note("fgsrd started on " + daemon->socket_path());
    return true;
}

bool Run::check(bool ok, const std::string& what) {
    if (ok) return true;
    ++failures;
    if (result.failure.empty()) result.failure = what;
    note("FAILED: " + what);
    return false;
}

bool Run::served(const std::string& after) {
    if (daemon && !check(daemon->running(), after + ": fgsrd died; its log:\n" + log())) return false;
    double worst = 0;
    bool answered = true;
    for (int i = 0; i < 3; ++i) {
        const double ms = raw::hello_ms(socket(), 2000);
        answered &= ms >= 0;
        worst = std::max(worst, ms);
    }
    auto& hello = result.metrics["hello_after_ms"];
    if (!hello.is_object()) hello = nlohmann::json::object();
    hello[after] = worst;
    bool ok = check(answered, after + ": a fresh HELLO was not answered");
    ok &= check(worst <= hello_limit_ms(opt), fmt::format("{}: fresh HELLO took {:.1f} ms (limit {:.0f})",
                                                          after, worst, hello_limit_ms(opt)));
    const std::string why = library_frames(socket(), 64, 64, 2);
    ok &= check(why.empty(), after + ": a well-behaved client failed: " + why);
    return ok;
}

std::string library_frames(const std::string& socket, uint32_t w, uint32_t h, uint32_t frames) {
    fgsr_connect_info ci{};
    ci.struct_size = sizeof(ci);
    ci.socket_path = socket.c_str();
    ci.client_name = "fgsr-stress-good";
    ci.timeout_ms = 5000;
    fgsr_connection* c = nullptr;
    fgsr_status st = fgsr_connect(&ci, &c);
    if (st != FGSR_STATUS_OK) return std::string("connect: ") + fgsr_status_string(st);
    fgsr_session_desc d = raw::small_desc(w, h);
    fgsr_session* s = nullptr;
    st = fgsr_session_create(c, &d, &s);
    if (st != FGSR_STATUS_OK) {
        fgsr_disconnect(c);
        return std::string("session: ") + fgsr_status_string(st);
    }
    std::string why;
    fgsr_pool_layout l{};
    fgsr_session_layout(s, &l);
    for (uint32_t f = 0; f < frames && why.empty(); ++f) {
        fgsr_input_slot in{};
        st = fgsr_acquire_input(s, 10000, &in);
        if (st != FGSR_STATUS_OK) {
            why = std::string("acquire: ") + fgsr_status_string(st);
            break;
        }
        auto* px = static_cast<float*>(in.color);
        for (size_t p = 0; p < size_t(w) * h; ++p) {
            const float v = float((p + f * 2) % 29) / 28.f;
            px[4 * p] = v;
            px[4 * p + 1] = 1.f - v;
            px[4 * p + 2] = 0.5f;
            px[4 * p + 3] = 1.f;
            static_cast<float*>(in.depth)[p] = 10.f;
            static_cast<float*>(in.mv)[2 * p] = -2.f;
            static_cast<float*>(in.mv)[2 * p + 1] = 0.f;
        }
        const float alpha = 0.5f;
        fgsr_submit_info si{};
        si.struct_size = sizeof(si);
        si.input_slot = in.index;
        si.flags = FGSR_SUBMIT_HAS_MV;
        si.interp_count = f == 0 ? 0 : 1;
        si.interp_alphas = &alpha;
        st = fgsr_submit(s, &si, nullptr);
        if (st != FGSR_STATUS_OK) {
            why = std::string("submit: ") + fgsr_status_string(st);
            break;
        }
        for (;;) {
            fgsr_output out{};
            st = fgsr_wait(s, 30000, &out);
            if (st != FGSR_STATUS_OK) {
                why = std::string("wait: ") + fgsr_status_string(st);
                break;
            }
            if (out.status != FGSR_STATUS_OK) why = std::string("frame: ") + fgsr_status_string(out.status);
            if (out.output_slot != FGSR_NO_SLOT) fgsr_release_output(s, out.output_slot);
            if (out.flags & FGSR_COMPLETION_LAST) break;
        }
    }
    fgsr_session_destroy(s);
    fgsr_disconnect(c);
    return why;
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t i = std::min(v.size() - 1, size_t(p / 100.0 * double(v.size() - 1) + 0.5));
    return v[i];
}

double max_of(const std::vector<double>& v) {
    return v.empty() ? 0 : *std::max_element(v.begin(), v.end());
}

} // namespace service

namespace {

struct Scenario {
    const char* name;
    void (*run)(service::Run&);
};

constexpr Scenario kScenarios[] = {
    {"hostile-client", service::hostile_client},    {"flag-attack", service::flag_attack},
    {"heavy-session", service::heavy_session},      {"idle-clients", service::idle_clients},
    {"kill-9-clients", service::kill_nine_clients}, {"daemon-restart", service::daemon_restart},
};

} // namespace

std::vector<std::string> service_scenario_names() {
    std::vector<std::string> v;
    for (const Scenario& s : kScenarios) v.emplace_back(s.name);
    return v;
}

std::vector<ScenarioResult> run_service_scenarios(const ServiceOptions& o) {
    std::vector<ScenarioResult> out;
    for (const Scenario& s : kScenarios) {
        if (std::string(s.name).find(o.filter) == std::string::npos) continue;
        if (o.progress) o.progress(std::string("[") + s.name + "]");
        const auto t0 = std::chrono::steady_clock::now();
        service::Run r(o, s.name);
        s.run(r);
        r.result.pass = r.failures == 0;
        if (r.daemon && r.daemon->running()) {
            const int st = r.daemon->terminate(10000);
            if (st != 0 && r.result.pass)
                r.check(false,
                        "fgsrd did not exit cleanly on SIGTERM (wait status " + std::to_string(st) + ")");
            r.result.pass = r.failures == 0;
        }
        r.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (o.progress)
            o.progress(std::string("  ") + s.name + ": " +
                       (r.result.skipped ? "skipped"
                        : r.result.pass  ? "pass"
                                         : "FAIL") +
                       fmt::format(" ({:.1f} s)", r.result.seconds));
        out.push_back(std::move(r.result));
    }
    return out;
}

} // namespace fgsr::stress
