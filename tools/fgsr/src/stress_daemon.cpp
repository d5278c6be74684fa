// `fgsr stress --daemon`: the stress cases fed through fgsrd (fgsr/stress/daemon.hpp). Without
// --socket it spawns the fgsrd next to this executable on a socket in a fresh temporary directory,
// with its stderr in a file there (read for the rejection reasons), and stops it (SIGTERM) after.
#include <fgsr/cli/stress.hpp>

#include <fgsr/capture/stress.hpp>
#include <fgsr/stress/daemon.hpp>

#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fgsr::cli {

namespace {

// Frames above this many pixels are not fed through the daemon (the 1920x1080 case of the full
// table: the engine feeder covers it; through the daemon it only adds copies).
constexpr size_t kMaxDaemonPixels = 1u << 20;

// A spawned fgsrd. Owns the child and its temporary directory; the destructor stops both.
class OwnDaemon {
  public:
    static std::unique_ptr<OwnDaemon> start(std::string& error) {
        std::error_code ec;
        const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        const std::filesystem::path fgsrd = exe.parent_path() / "fgsrd";
        if (ec || access(fgsrd.c_str(), X_OK) != 0) {
            error = "no executable fgsrd next to " + exe.string() + " (build it, or pass --socket)";
            return nullptr;
        }
        char tmpl[] = "/tmp/fgsr-stress-XXXXXX";
        if (!mkdtemp(tmpl)) {
            error = "mkdtemp failed";
            return nullptr;
        }
        std::unique_ptr<OwnDaemon> d(new OwnDaemon());
        d->dir_ = tmpl;
        d->socket_ = d->dir_ + "/fgsrd.sock";
        d->log_ = d->dir_ + "/fgsrd.log";
        const std::string bin = fgsrd.string();
        d->pid_ = fork();
        if (d->pid_ < 0) {
            error = "fork failed";
            return nullptr;
        }
        if (d->pid_ == 0) {
            const int err = open(d->log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
            if (err >= 0) dup2(err, 2);
            const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
            if (in >= 0) dup2(in, 0);
            execl(bin.c_str(), bin.c_str(), "--socket", d->socket_.c_str(), static_cast<char*>(nullptr));
            _exit(127);
        }
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (std::chrono::steady_clock::now() < deadline) {
            if (!d->alive()) {
                error = "fgsrd exited at start; its log:\n" + d->log_text();
                return nullptr;
            }
            if (d->accepts()) return d;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        error = "fgsrd did not listen within 60 s; its log:\n" + d->log_text();
        return nullptr;
    }

    ~OwnDaemon() {
        if (pid_ > 0 && alive()) {
            ::kill(pid_, SIGTERM);
            for (int i = 0; i < 1000 && alive(); ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            if (alive()) {
                ::kill(pid_, SIGKILL);
                int st = 0;
                waitpid(pid_, &st, 0);
            }
        }
        std::error_code ec;
        if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
    }

    bool alive() {
        if (exited_) return false;
        int st = 0;
        if (waitpid(pid_, &st, WNOHANG) == pid_) {
            exited_ = true;
            status_ = st;
        }
        return !exited_;
    }
    int status() const { return status_; }
    std::string log_text() const {
        std::ifstream f(log_);
        std::stringstream s;
        s << f.rdbuf();
        return s.str();
    }
    const std::string& socket() const { return socket_; }
    const std::string& log_path() const { return log_; }

  private:
    OwnDaemon() = default;
    bool accepts() const {
        const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        if (fd < 0) return false;
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::snprintf(a.sun_path, sizeof a.sun_path, "%s", socket_.c_str());
        const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
        close(fd);
        return ok;
    }
    pid_t pid_ = -1;
    bool exited_ = false;
    int status_ = 0;
    std::string dir_, socket_, log_;
};

} // namespace

int stress_daemon_main(const StressCli& o) {
    std::unique_ptr<OwnDaemon> own;
    stress::DaemonTarget target;
    if (o.socket.empty()) {
        std::string error;
        own = OwnDaemon::start(error);
        if (!own) {
            std::fprintf(stderr, "fgsr: cannot start fgsrd: %s\n", error.c_str());
            return 1;
        }
        target.socket = own->socket();
        target.log = [d = own.get()] { return d->log_text(); };
        target.alive = [d = own.get()] { return d->alive(); };
        if (!o.quiet)
            std::fprintf(stderr, "fgsrd started on %s (log %s)\n", own->socket().c_str(),
                         own->log_path().c_str());
    } else {
        target.socket = o.socket;
        if (!o.quiet)
            std::fprintf(stderr,
                         "fgsrd at %s: its log is not readable here, rejection reasons are unchecked\n",
                         o.socket.c_str());
    }
    // The client library's own notes (e.g. "fgsrd refused the session") would interleave with the
    // report: the feeder reads the reasons from the daemon's log instead.
    setenv("FGSR_CLIENT_QUIET", "1", 1);

    nlohmann::json header;
    header["target"] = "fgsrd";
    header["socket"] = target.socket;
    return run_and_report(
        o, "fgsr stress through fgsrd (" + target.socket + ")", header,
        [&](const stress::Case& c, const stress::RunOptions& ro) {
            return stress::run_on_daemon(target, c, ro, kMaxDaemonPixels);
        },
        [&] {
            if (!own || own->alive()) return false;
            std::fprintf(stderr, "fgsr: fgsrd died (wait status %d); its log:\n%s\n", own->status(),
                         own->log_text().c_str());
            return true;
        });
}

} // namespace fgsr::cli
