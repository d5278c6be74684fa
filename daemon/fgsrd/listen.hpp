// fgsrd's listening socket: systemd socket activation, or a path it binds (replacing a stale
// socket file, never anything else), in a runtime directory only its user can write.
#pragma once

#include <fgsr/ipc/unique_fd.hpp>

#include <string>

namespace fgsrd {

struct Listener {
    fgsr::ipc::UniqueFd fd;
    std::string created_path; // unlinked at shutdown when this process created it; empty otherwise
};

// path empty: $XDG_RUNTIME_DIR/fgsr/fgsrd.sock. Logs the reason and returns an invalid fd on
// failure.
Listener open_listener(const std::string& path, bool allow_any_user);

} // namespace fgsrd
