// The one launcher of a real fgsrd (library fgsr_testing), for multi-process tests and for
// `fgsr stress --daemon`: spawns an fgsrd on a socket in a fresh temporary directory, waits until
// the socket accepts connections, and observes the process (/proc fd and mapping counts, VmRSS, its
// stderr).
//
//   auto d = fgsr::test::FgsrdProcess::start({"--log-level", "debug"});
//   ASSERT_TRUE(d) << fgsr::test::FgsrdProcess::last_error();
//   connect to d->socket_path() ...; d->terminate();   // SIGTERM, returns the wait status
//
// Ownership: the object owns the child and the temporary directory; the destructor SIGKILLs a child
// still running, reaps it and removes the directory. Not thread-safe; use from the test's thread.
#pragma once

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace fgsr::daemon_process {

class FgsrdProcess {
  public:
#ifdef FGSR_BIN_DIR
    // Starts FGSR_BIN_DIR/fgsrd (the tests' build) as start_at does.
    static std::unique_ptr<FgsrdProcess> start(const std::vector<std::string>& args = {},
                                               int timeout_ms = 60000) {
        return start_at(std::string(FGSR_BIN_DIR) + "/fgsrd", args, timeout_ms);
    }
#endif

    // Starts the executable `fgsrd` with `--socket <tmp>/fgsrd.sock` followed by `args`, in a fresh
    // directory /tmp/<tmp_prefix>-XXXXXX; waits up to timeout_ms for the socket to accept. Returns
    // nullptr on failure (reason in last_error(), stderr included).
    static std::unique_ptr<FgsrdProcess> start_at(const std::string& fgsrd,
                                                  const std::vector<std::string>& args = {},
                                                  int timeout_ms = 60000,
                                                  const std::string& tmp_prefix = "fgsrd-test") {
        std::unique_ptr<FgsrdProcess> p(new FgsrdProcess());
        std::string tmpl = "/tmp/" + tmp_prefix + "-XXXXXX";
        if (!mkdtemp(tmpl.data())) return fail("mkdtemp: " + std::string(std::strerror(errno)));
        p->dir_ = tmpl;
        p->socket_ = p->dir_ + "/fgsrd.sock";
        p->stderr_path_ = p->dir_ + "/stderr.log";
        std::vector<std::string> argv_s = {fgsrd, "--socket", p->socket_};
        argv_s.insert(argv_s.end(), args.begin(), args.end());
        p->argv_ = argv_s;
        if (!p->launch(timeout_ms)) return nullptr;
        return p;
    }

    // After the daemon exited (kill9, terminate): starts the same command line again, on the same
    // socket, with stderr appended to the same file; waits up to timeout_ms for the socket to
    // accept. False on failure (reason in last_error()).
    bool restart(int timeout_ms = 60000) {
        if (running()) {
            error_() = "fgsrd is still running";
            return false;
        }
        exited_ = false;
        status_ = -1;
        return launch(timeout_ms, true);
    }

    // Starts `argv` (argv[0] a path) with stderr to `stderr_path` and stdin from /dev/null; `env`
    // entries ("NAME=value") override the inherited environment; append: stderr appended to the
    // file rather than replacing it. Returns the child's pid or -1.
    // Socket activation: keep_fd >= 0 passes that fd as fd keep_as (3 for systemd) and sets
    // LISTEN_FDS=1 and LISTEN_PID=<the child's pid>, as systemd does.
    static pid_t spawn(const std::vector<std::string>& argv_s, const std::string& stderr_path,
                       const std::vector<std::string>& env = {}, int keep_fd = -1, int keep_as = -1,
                       bool append = false) {
        // Everything the child needs is built before fork: after it only async-signal-safe calls.
        std::vector<char*> argv;
        for (const std::string& a : argv_s) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        std::vector<std::string> env_s;
        for (char** e = environ; *e; ++e) {
            const std::string entry = *e;
            const std::string name = entry.substr(0, entry.find('='));
            bool overridden = false;
            for (const std::string& o : env) overridden |= o.rfind(name + "=", 0) == 0;
            if (!overridden) env_s.push_back(entry);
        }
        env_s.insert(env_s.end(), env.begin(), env.end());
        const bool activate = keep_fd >= 0 && keep_as >= 0;
        if (activate) env_s.push_back("LISTEN_FDS=1");
        std::vector<char*> envp;
        for (const std::string& e : env_s) envp.push_back(const_cast<char*>(e.c_str()));
        char listen_pid[32] = "LISTEN_PID=";
        if (activate) envp.push_back(listen_pid);
        envp.push_back(nullptr);
        const pid_t pid = fork();
        if (pid != 0) return pid;
        const int err =
            open(stderr_path.c_str(), O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC) | O_CLOEXEC, 0600);
        if (err >= 0) dup2(err, 2);
        const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
        if (in >= 0) dup2(in, 0);
        if (activate) {
            char digits[16];
            int n = 0;
            for (pid_t v = getpid(); v > 0 && n < 15; v /= 10) digits[n++] = char('0' + v % 10);
            char* d = listen_pid + 11;
            while (n > 0) *d++ = digits[--n];
            *d = 0;
            if (keep_fd == keep_as)
                fcntl(keep_fd, F_SETFD, 0);
            else
                dup2(keep_fd, keep_as); // dup2 clears FD_CLOEXEC on the copy
        }
        execve(argv[0], argv.data(), envp.data());
        _exit(127);
    }

    ~FgsrdProcess() {
        if (pid_ > 0 && running()) {
            ::kill(pid_, SIGKILL);
            wait_exit(10000);
        }
        if (!dir_.empty()) {
            std::error_code ec;
            std::filesystem::remove_all(dir_, ec);
        }
    }
    FgsrdProcess(const FgsrdProcess&) = delete;
    FgsrdProcess& operator=(const FgsrdProcess&) = delete;

    pid_t pid() const { return pid_; }
    const std::string& socket_path() const { return socket_; }
    const std::string& dir() const { return dir_; }
    const std::string& stderr_path() const { return stderr_path_; }

    // True while the child has not exited (reaps it when it has).
    bool running() {
        if (exited_) return false;
        int st = 0;
        const pid_t r = waitpid(pid_, &st, WNOHANG);
        if (r == pid_) {
            exited_ = true;
            status_ = st;
            return false;
        }
        return r == 0;
    }

    // Sends SIGTERM and waits up to timeout_ms; returns the wait status (-1: still running, then
    // killed with SIGKILL).
    int terminate(int timeout_ms = 20000) { return stop(SIGTERM, timeout_ms); }
    // SIGKILL; returns the wait status.
    int kill9() { return stop(SIGKILL, 10000); }
    int signal(int sig) { return ::kill(pid_, sig); }
    // The child's wait status once it has exited.
    int exit_status() const { return status_; }

    std::string stderr_text() const {
        std::ifstream f(stderr_path_);
        std::stringstream s;
        s << f.rdbuf();
        return s.str();
    }

    // Open fds of the daemon (/proc/<pid>/fd), or -1.
    int fd_count() const {
        std::error_code ec;
        int n = 0;
        for (auto it = std::filesystem::directory_iterator("/proc/" + std::to_string(pid_) + "/fd", ec);
             !ec && it != std::filesystem::directory_iterator(); it.increment(ec))
            ++n;
        return ec ? -1 : n;
    }
    // Lines of /proc/<pid>/maps (memory mappings), or -1 (a live process has some).
    int mapping_count() const {
        const size_t n = mappings().size();
        return n == 0 ? -1 : int(n);
    }
    // The lines of /proc/<pid>/maps themselves (empty if it cannot be read), for a failure message
    // that says which mappings a check found more of.
    std::vector<std::string> mappings() const {
        std::ifstream f("/proc/" + std::to_string(pid_) + "/maps");
        std::vector<std::string> lines;
        std::string line;
        while (std::getline(f, line)) lines.push_back(line);
        return lines;
    }
    // VmRSS in KiB from /proc/<pid>/status, or -1.
    long rss_kib() const { return status_field("VmRSS:"); }
    // Bytes of memfd mappings ("/memfd:" in /proc/<pid>/maps): the sessions' shared memory.
    long memfd_mapped_bytes() const {
        std::ifstream f("/proc/" + std::to_string(pid_) + "/maps");
        long total = 0;
        std::string line;
        while (std::getline(f, line)) {
            if (line.find("/memfd:") == std::string::npos) continue;
            unsigned long a = 0, b = 0;
            if (std::sscanf(line.c_str(), "%lx-%lx", &a, &b) == 2) total += long(b - a);
        }
        return total;
    }

    // Connects a SOCK_SEQPACKET socket to the daemon; returns the fd (caller owns it) or -1.
    static int connect_to(const std::string& path) {
        const int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        if (fd < 0) return -1;
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        if (path.size() >= sizeof(a.sun_path)) {
            close(fd);
            return -1;
        }
        std::memcpy(a.sun_path, path.c_str(), path.size() + 1);
        if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
            close(fd);
            return -1;
        }
        return fd;
    }

    static const std::string& last_error() { return error_(); }

  private:
    FgsrdProcess() = default;

    static std::string& error_() {
        static std::string e;
        return e;
    }
    static std::unique_ptr<FgsrdProcess> fail(const std::string& why) {
        error_() = why;
        return nullptr;
    }

    bool launch(int timeout_ms, bool append = false) {
        pid_ = spawn(argv_, stderr_path_, {}, -1, -1, append);
        if (pid_ < 0) {
            error_() = "fork: " + std::string(std::strerror(errno));
            return false;
        }
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
        while (std::chrono::steady_clock::now() < deadline) {
            if (!running()) {
                error_() =
                    "fgsrd exited early (status " + std::to_string(status_) + "); stderr:\n" + stderr_text();
                return false;
            }
            if (probe()) return true;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        error_() = "fgsrd did not accept on " + socket_ + " within " + std::to_string(timeout_ms) +
                   " ms; stderr:\n" + stderr_text();
        return false;
    }

    bool probe() const {
        const int fd = connect_to(socket_);
        if (fd < 0) return false;
        close(fd);
        return true;
    }

    int wait_exit(int timeout_ms) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
        while (running()) {
            if (std::chrono::steady_clock::now() >= deadline) return -1;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        return status_;
    }

    int stop(int sig, int timeout_ms) {
        if (!running()) return status_;
        ::kill(pid_, sig);
        const int st = wait_exit(timeout_ms);
        if (st == -1) {
            ::kill(pid_, SIGKILL);
            wait_exit(10000);
            return -1;
        }
        return st;
    }

    long status_field(const char* key) const {
        std::ifstream f("/proc/" + std::to_string(pid_) + "/status");
        std::string line;
        while (std::getline(f, line))
            if (line.rfind(key, 0) == 0) return std::strtol(line.c_str() + std::strlen(key), nullptr, 10);
        return -1;
    }

    pid_t pid_ = -1;
    bool exited_ = false;
    int status_ = -1;
    std::string dir_, socket_, stderr_path_;
    std::vector<std::string> argv_;
};

} // namespace fgsr::daemon_process

namespace fgsr::test {
using daemon_process::FgsrdProcess;
} // namespace fgsr::test
