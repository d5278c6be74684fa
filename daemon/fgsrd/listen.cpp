#include "listen.hpp"

#include "log.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

namespace fgsrd {

using fgsr::ipc::UniqueFd;

namespace {

// Socket activation (sd_listen_fds, by hand): LISTEN_PID is this process and LISTEN_FDS >= 1;
// the first passed fd (3) must be a listening SOCK_SEQPACKET Unix socket.
int activated_socket() {
    const char* pid = std::getenv("LISTEN_PID");
    const char* fds = std::getenv("LISTEN_FDS");
    if (!pid || !fds) return -1;
    const bool mine = std::strtol(pid, nullptr, 10) == long(getpid());
    const long n = std::strtol(fds, nullptr, 10);
    unsetenv("LISTEN_PID");
    unsetenv("LISTEN_FDS");
    unsetenv("LISTEN_FDNAMES");
    if (!mine || n < 1) return -1;
    if (n > 1) log::warn("socket activation passed {} fds; using the first", n);
    int type = 0;
    socklen_t len = sizeof(type);
    if (getsockopt(3, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_SEQPACKET) {
        log::error("socket activation: fd 3 is not a SOCK_SEQPACKET socket (use ListenSequentialPacket=)");
        return -2;
    }
    fcntl(3, F_SETFD, FD_CLOEXEC);
    fcntl(3, F_SETFL, fcntl(3, F_GETFL) | O_NONBLOCK);
    return 3;
}

// $XDG_RUNTIME_DIR/fgsr: created 0700; an existing one must be a directory of this user that
// nobody else can write (else another user could replace the socket under the clients).
bool runtime_dir(std::string& dir) {
    const char* xdg = std::getenv("XDG_RUNTIME_DIR");
    if (!xdg || !*xdg) {
        log::error("XDG_RUNTIME_DIR is not set; pass --socket PATH");
        return false;
    }
    dir = std::string(xdg) + "/fgsr";
    if (mkdir(dir.c_str(), 0700) == 0) return true;
    if (errno != EEXIST) {
        log::error("cannot create {}: {}", dir, std::strerror(errno));
        return false;
    }
    struct stat st {};
    if (lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
        log::error("{} exists and is not a directory; refusing to use it", dir);
        return false;
    }
    if (st.st_uid != geteuid() || (st.st_mode & 0077) != 0) {
        log::error("refusing to use {}: owner uid {} mode {:04o}; it must belong to uid {} with mode 0700 "
                   "(others could replace the socket); fix it with chmod 700 or remove it",
                   dir, st.st_uid, st.st_mode & 07777, geteuid());
        return false;
    }
    return true;
}

} // namespace

Listener open_listener(const std::string& requested, bool allow_any_user) {
    Listener out;
    const int act = activated_socket();
    if (act == -2) return out;
    if (act >= 0) {
        out.fd.reset(act);
        log::info("listening on the socket systemd passed (fd 3)");
        return out;
    }
    std::string path = requested;
    if (path.empty()) {
        std::string dir;
        if (!runtime_dir(dir)) return out;
        path = dir + "/fgsrd.sock";
    }
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof(addr.sun_path)) {
        log::error("socket path {} is longer than {} bytes", path, sizeof(addr.sun_path) - 1);
        return out;
    }
    std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
    UniqueFd fd(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
    if (!fd) {
        log::error("socket: {}", std::strerror(errno));
        return out;
    }
    const int bound = bind(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
    if (bound != 0 && errno == EADDRINUSE) {
        // Something is there. Only a socket file nobody answers on is stale and may be replaced:
        // a regular file, a directory or a symlink (even to a socket) is somebody's, and stays.
        struct stat st {};
        if (lstat(path.c_str(), &st) != 0 || !S_ISSOCK(st.st_mode)) {
            log::error(
                "{} exists and is not a socket ({}); not replacing it: remove it or pass another --socket",
                path,
                S_ISLNK(st.st_mode)   ? "a symbolic link"
                : S_ISREG(st.st_mode) ? "a regular file"
                : S_ISDIR(st.st_mode) ? "a directory"
                                      : "not a socket");
            return out;
        }
        UniqueFd probe(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
        if (connect(probe.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
            log::error("another fgsrd is already listening on {}", path);
            return out;
        }
        unlink(path.c_str());
        if (bind(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
            log::error("bind {}: {}", path, std::strerror(errno));
            return out;
        }
    } else if (bound != 0) {
        log::error("bind {}: {}", path, std::strerror(errno));
        return out;
    }
    out.created_path = path;
    // Connecting needs write permission on the socket file: only this user, or everyone.
    chmod(path.c_str(), allow_any_user ? 0666 : 0600);
    if (listen(fd.get(), 64) != 0) {
        log::error("listen {}: {}", path, std::strerror(errno));
        unlink(path.c_str());
        out.created_path.clear();
        return out;
    }
    log::info("listening on {}", path);
    out.fd = std::move(fd);
    return out;
}

} // namespace fgsrd
