// The numerical stress cases (fgsr/capture/stress.hpp) in their reduced form fed through a real
// fgsrd (fgsr/testing/fgsrd_process.hpp) with libfgsr_client (fgsr/stress/daemon.hpp): no case fails, the
// daemon survives every case, every rejection completes with a non-OK status and, when the daemon
// refused it, its log states the reason; what the protocol cannot express is reported as n/a.
#include <fgsr/testing/fgsrd_process.hpp>

#include <fgsr/capture/stress.hpp>
#include <fgsr/stress/daemon.hpp>

#include <gtest/gtest.h>

#include <set>

namespace fgsr::test {
namespace {

stress::DaemonTarget target_of(FgsrdProcess& d) {
    stress::DaemonTarget t;
    t.socket = d.socket_path();
    t.log = [&d] { return d.stderr_text(); };
    t.alive = [&d] { return d.running(); };
    return t;
}

// The whole reduced table (195 cases, the colour-only ones with their NO_MVS / NO_DEPTH sessions; the long SR
// run at 300 frames): a few seconds on lavapipe.
TEST(StressDaemon, EveryCasePassesThroughFgsrd) {
    setenv("FGSR_CLIENT_QUIET", "1", 1);
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    const stress::DaemonTarget t = target_of(*d);
    stress::CaseOptions o;
    o.reduced = true;
    o.sr_frames = 300;
    size_t passed = 0, na = 0, daemon_reasons = 0, client_refusals = 0, outputs = 0;
    std::set<std::string> na_names;
    for (const stress::Case& c : stress::make_cases(o)) {
        const stress::CaseResult r = stress::run_on_daemon(t, c);
        EXPECT_TRUE(r.pass) << c.name << ": " << r.failure;
        ASSERT_TRUE(d->running()) << "fgsrd died in " << c.name << "; stderr:\n" << d->stderr_text();
        if (!r.applicable) {
            EXPECT_FALSE(r.not_applicable.empty()) << c.name;
            na_names.insert(c.name);
            ++na;
            continue;
        }
        ++passed;
        EXPECT_EQ(r.steps_run, c.reject_session.empty() ? c.step_count : 0) << c.name;
        for (const std::string& why : r.rejections) {
            // Either the client refused before sending or the daemon's log line is quoted.
            const bool client = why.rfind("client: ", 0) == 0;
            EXPECT_TRUE(client || why.find("[log: fgsrd: ") != std::string::npos) << c.name << ": " << why;
            (client ? client_refusals : daemon_reasons) += 1;
        }
        outputs += r.outputs_checked;
        if (r.drift_db) {
            EXPECT_GE(*r.drift_db, c.min_drift_db) << c.name;
            std::printf("[ measured ] %s through fgsrd: drift %.2f dB\n", c.name.c_str(), *r.drift_db);
        }
    }
    std::printf(
        "[ measured ] through fgsrd: %zu cases run, %zu n/a, %zu outputs checked finite, %zu rejections "
        "with the daemon's logged reason, %zu refused by the client\n",
        passed, na, outputs, daemon_reasons, client_refusals);
    // What the wire cannot carry is reported, and only that.
    for (const char* expected :
         {"combined/separate-passes", "combined/sr-bilinear", "reject/session/lut-nan"})
        EXPECT_TRUE(na_names.count(expected)) << expected;
    EXPECT_EQ(na, 9u);
    EXPECT_GT(daemon_reasons, 50u); // NOT_READY (scene cuts), BAD_FRAME (jitter), refused sessions
    EXPECT_GT(client_refusals, 20u);
    EXPECT_EQ(d->terminate(), 0) << d->stderr_text();
}

// fgsrd logs why an interpolation or extrapolation completes with NOT_READY (it did not before:
// the status came back with nothing in the log), and the feeder fails a case whose rejection
// reason the log does not state.
TEST(StressDaemon, NotReadyIsLoggedAndReasonsAreChecked) {
    setenv("FGSR_CLIENT_QUIET", "1", 1);
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    const stress::DaemonTarget t = target_of(*d);
    stress::CaseOptions o;
    std::vector<stress::Case> cases = stress::make_cases(o);
    auto it = std::find_if(cases.begin(), cases.end(),
                           [](const stress::Case& c) { return c.name == "scene-cut/reset-every-frame"; });
    ASSERT_NE(it, cases.end());
    const stress::CaseResult good = stress::run_on_daemon(t, *it);
    ASSERT_TRUE(good.pass) << good.failure;
    ASSERT_FALSE(good.rejections.empty());
    EXPECT_NE(good.rejections[0].find("needs two submitted frames"), std::string::npos) << good.rejections[0];
    EXPECT_NE(d->stderr_text().find("interpolation not ready: needs two submitted frames"),
              std::string::npos);

    // The same case claiming a reason the daemon does not log fails, naming the step.
    stress::Case wrong = *it;
    auto inner = wrong.step;
    wrong.step = [inner](size_t i) {
        stress::Step s = inner(i);
        if (!s.reject.empty()) s.reject = "no such reason";
        return s;
    };
    const stress::CaseResult r = stress::run_on_daemon(t, wrong);
    EXPECT_FALSE(r.pass);
    EXPECT_NE(r.failure.find("no such reason"), std::string::npos) << r.failure;

    // A request the daemon answers with outputs, claimed to be rejected, fails too.
    auto cut = std::find_if(cases.begin(), cases.end(),
                            [](const stress::Case& c) { return c.name == "alpha/extremes"; });
    ASSERT_NE(cut, cases.end());
    stress::Case accepted = *cut;
    auto inner2 = accepted.step;
    accepted.step = [inner2](size_t i) {
        stress::Step s = inner2(i);
        if (i == 3) s.reject = "alpha"; // extrapolation at 1e-40, 1e-6, 1: valid, sent and served
        return s;
    };
    const stress::CaseResult a = stress::run_on_daemon(t, accepted);
    EXPECT_FALSE(a.pass);
    EXPECT_NE(a.failure.find("step 3"), std::string::npos) << a.failure;
    EXPECT_TRUE(d->running());
}

} // namespace
} // namespace fgsr::test
