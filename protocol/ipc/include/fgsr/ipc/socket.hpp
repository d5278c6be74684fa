// One packet on the control socket with the file descriptors that travel with it (SCM_RIGHTS),
// for libfgsr_client and fgsrd alike.
#pragma once

#include <fgsr/ipc/unique_fd.hpp>

#include <cstddef>
#include <sys/types.h>
#include <vector>

namespace fgsr::ipc {

// The most fds one packet may carry; more are a truncated control message (EPROTO).
inline constexpr size_t kMaxPacketFds = 16;

// Receives one packet with its fds (MSG_CMSG_CLOEXEC | `flags`, EINTR retried); every received fd
// ends up owned by `fds` (closed by the caller's vector on any error). Returns the packet length,
// 0 for an orderly close, or -1 with errno (EMSGSIZE: truncated packet, EPROTO: truncated control
// data; EAGAIN with MSG_DONTWAIT and nothing to read).
ssize_t recv_with_fds(int sock, void* buf, size_t cap, std::vector<UniqueFd>& fds, int flags = 0);

// Sends one packet with `nfds` (<= kMaxPacketFds) fds attached (MSG_NOSIGNAL | `flags`, EINTR
// retried). Returns what sendmsg returns.
ssize_t send_with_fds(int sock, const void* msg, size_t size, const int* fds = nullptr, size_t nfds = 0,
                      int flags = 0);

} // namespace fgsr::ipc
