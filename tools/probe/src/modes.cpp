// The measurement mode: a command started per frame-generation mode with the layer's environment,
// warmed up, measured and stopped.
#include <fgsr/probe/modes.hpp>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fgsr::probe {

namespace {

constexpr const char* kLayerVariables[] = {"FGSR_ENABLE", "FGSR_DISABLE", "FGSR_MODE"};

} // namespace

std::vector<std::pair<std::string, std::string>> mode_environment(Mode m) {
    switch (m) {
    case Mode::off:
        return {{"FGSR_DISABLE", "1"}};
    case Mode::interpolate:
        return {{"FGSR_ENABLE", "1"}, {"FGSR_MODE", "interpolate"}};
    case Mode::extrapolate:
        return {{"FGSR_ENABLE", "1"}, {"FGSR_MODE", "extrapolate"}};
    case Mode::unknown:
        break;
    }
    return {};
}

Result<ChildProcess> ChildProcess::spawn(const std::string& command,
                                         const std::vector<std::pair<std::string, std::string>>& set_env,
                                         const std::vector<std::string>& unset_env) {
    if (command.empty()) return make_error(Errc::invalid_argument, "--run-command: empty command");
    // The child's environment, built before fork (no allocation after it).
    std::vector<std::string> env;
    for (char** e = environ; *e; ++e) {
        const std::string_view kv(*e);
        const std::string_view key = kv.substr(0, kv.find('='));
        bool drop = false;
        for (const std::string& u : unset_env) drop |= key == u;
        for (const auto& [k, v] : set_env) drop |= key == k;
        if (!drop) env.emplace_back(kv);
    }
    for (const auto& [k, v] : set_env) env.push_back(k + "=" + v);
    std::vector<char*> envp;
    for (std::string& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    std::string cmd = command;
    char sh[] = "/bin/sh", dash_c[] = "-c";
    char* argv[] = {sh, dash_c, cmd.data(), nullptr};

    const pid_t pid = fork();
    if (pid < 0)
        return make_error(Errc::io, std::string("cannot start the command: fork: ") + std::strerror(errno));
    if (pid == 0) {
        setpgid(0, 0);
        execve("/bin/sh", argv, envp.data());
        _exit(127);
    }
    setpgid(pid, pid); // also from the parent: no race with an early stop()
    return ChildProcess(pid);
}

ChildProcess::ChildProcess(ChildProcess&& o) noexcept
    : pid_(std::exchange(o.pid_, -1)), status_(o.status_), exited_(o.exited_) {}

ChildProcess& ChildProcess::operator=(ChildProcess&& o) noexcept {
    if (this != &o) {
        if (pid_ > 0) stop();
        pid_ = std::exchange(o.pid_, -1);
        status_ = o.status_;
        exited_ = o.exited_;
    }
    return *this;
}

ChildProcess::~ChildProcess() {
    if (pid_ > 0) stop();
}

bool ChildProcess::running() {
    if (pid_ <= 0 || exited_) return false;
    int st = 0;
    const pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
        exited_ = true;
        status_ = st;
        kill(-pid_, SIGTERM); // what the shell left behind
        return false;
    }
    return r == 0;
}

std::string ChildProcess::exit_text() const {
    if (!exited_) return "still running";
    if (WIFEXITED(status_)) return "exited with status " + std::to_string(WEXITSTATUS(status_));
    if (WIFSIGNALED(status_)) return "killed by signal " + std::to_string(WTERMSIG(status_));
    return "ended";
}

std::string ChildProcess::stop(int grace_ms) {
    if (pid_ <= 0) return "not started";
    if (running()) {
        kill(-pid_, SIGTERM);
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(grace_ms);
        while (running() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (!exited_) {
            kill(-pid_, SIGKILL);
            int st = 0;
            if (waitpid(pid_, &st, 0) == pid_) status_ = st;
            exited_ = true;
        }
    }
    const std::string how = exit_text();
    pid_ = -1;
    return how;
}

Result<std::vector<ModeRun>> run_modes(Probe& probe, const MeasureOptions& options) {
    if (options.modes.empty()) return make_error(Errc::invalid_argument, "--modes: no mode to measure");
    if (!(options.warmup_s >= 0 && options.warmup_s <= 600))
        return make_error(Errc::invalid_argument,
                          "--warmup " + std::to_string(options.warmup_s) + " s: 0 to 600");
    std::vector<ModeRun> out;
    std::vector<std::string> unset(std::begin(kLayerVariables), std::end(kLayerVariables));
    for (Mode m : options.modes) {
        const std::string name = mode_name(m);
        auto child = ChildProcess::spawn(options.command, mode_environment(m), unset);
        if (!child) return child.error();
        const uint32_t pid = uint32_t(child->pid());
        if (options.run.progress)
            std::fprintf(stderr, "%s: started '%s' (pid %u), warming up %.1f s\n", name.c_str(),
                         options.command.c_str(), pid, options.warmup_s);
        const auto warm_end =
            std::chrono::steady_clock::now() + std::chrono::milliseconds(int64_t(options.warmup_s * 1000));
        while (std::chrono::steady_clock::now() < warm_end) {
            if (!child->running())
                return make_error(Errc::io,
                                  name + ": the command " + child->exit_text() + " during the warm-up");
            if (options.run.cancel && options.run.cancel->load())
                return make_error(Errc::io, name + ": interrupted");
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        RunOptions ro = options.run;
        ro.progress_prefix = name + ": ";
        ro.on_sample = [&](const Sample& s) {
            if (options.on_sample) options.on_sample(m, s, pid);
        };
        auto r = probe.run(ro);
        const bool alive = child->running();
        const std::string ended = child->exit_text();
        const std::string how = child->stop();
        if (!r) return make_error(r.error().code, name + ": " + r.error().message);
        if (!alive) return make_error(Errc::io, name + ": the command " + ended + " during the measurement");
        if (options.run.progress)
            std::fprintf(stderr, "%s: measured, command stopped (%s)\n", name.c_str(), how.c_str());
        ModeRun run;
        run.mode = m;
        run.pid = pid;
        run.summary = summarize(r->samples);
        run.result = std::move(*r);
        out.push_back(std::move(run));
    }
    return out;
}

} // namespace fgsr::probe
