// Private pieces of libfgsr_client shared by its translation units: the connection and session
// objects behind the C handles, and small helpers. Nothing here is exported (the version script
// exports only the fgsr_* C functions of fgsr/client.h and fgsr/protocol.h).
//
// Translation units: client.cpp (connection, handshake, request/reply), session.cpp (session
// creation and the reply's checks, destroy, stats, recording switch), frames.cpp (acquire,
// submit, wait, release: the rings), record.cpp (recording submitted frames as a capture).
#pragma once

#include <fgsr/client.h>
#include <fgsr/ipc/ring.hpp>
#include <fgsr/ipc/unique_fd.hpp>
#include <fgsr/wire.h>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

namespace fgsr::client {

using Fd = fgsr::ipc::UniqueFd;
using fgsr::ipc::Mapping;

inline constexpr uint32_t kDefaultTimeoutMs = 5000;

// Milliseconds left until `deadline_ns` (0 when passed), for poll().
int ms_left(uint64_t deadline_ns);
// How long fgsr_wait and fgsr_acquire_input spin for a completion before they sleep on the
// complete eventfd: $FGSR_WAIT_SPIN_US microseconds (0 to 1000; 0: never spin), else
// kDefaultWaitSpinUs. Read at session creation; a malformed value is logged and the default used.
inline constexpr uint32_t kDefaultWaitSpinUs = 0; // off: see docs/SERVICE.md, "Spinning"
uint64_t wait_spin_ns_from_env();
// One line on stderr ("fgsr_client: " + fmt), unless FGSR_CLIENT_QUIET is set.
void log_line(const char* fmt, const char* a, unsigned long b = 0, unsigned long c = 0);
// A status the daemon sent, checked against the statuses the API may return for the request.
fgsr_status peer_status(int32_t s);

// Runs `f` and turns any exception into a status: nothing throws across the C API.
template <class F> fgsr_status guarded(F&& f) noexcept {
    try {
        return f();
    } catch (const std::bad_alloc&) {
        return FGSR_STATUS_OUT_OF_MEMORY;
    } catch (...) {
        return FGSR_STATUS_INTERNAL;
    }
}

// Recording of submitted frames as an fgsr capture (record.cpp). Not thread-safe: owned by one
// session, used from the thread that uses the session.
class Recorder {
  public:
    virtual ~Recorder() = default;
    // Writes one frame (planes as laid out in the input slot). Returns a status.
    virtual fgsr_status add(const fgsr_pool_layout& layout, const std::byte* slot,
                            const fgsr_submit_entry& e) = 0;
    // Writes the manifest (the capture is complete). Returns a status.
    virtual fgsr_status finish() = 0;
    // Reason of the last failure, for the log.
    virtual const std::string& error() const = 0;
};

// A recorder writing to `dir` (created if missing); nullptr with `reason` set when it cannot.
std::unique_ptr<Recorder> make_recorder(const std::string& dir, const std::string& name,
                                        const fgsr_session_desc& desc, std::string& reason);

enum class InputState : uint8_t { free, acquired, submitted };

struct Outstanding {
    uint32_t input_slot;
    uint32_t outputs_seen;
};

} // namespace fgsr::client

struct fgsr_connection {
    fgsr::client::Fd sock;
    std::mutex mutex; // one request/reply exchange at a time (sessions may be on other threads)
    uint32_t next_request = 1;
    bool dead = false; // the daemon went away or violated the protocol; guarded by mutex
    fgsr_daemon_info info{};
    std::string name;

    // Sends `msg` (header filled here) and receives the reply of type `reply_type` into `reply`
    // (exactly reply_size bytes are kept; a longer reply from a newer minor version is cut).
    // fds received with it are appended to `fds` (nullptr: any fd is an error).
    fgsr_status request(void* msg, uint32_t size, uint16_t type, void* reply, uint32_t reply_size,
                        uint16_t reply_type, std::vector<fgsr::client::Fd>* fds, uint32_t timeout_ms);
    // DESTROY_SESSION for `session_id` under the mutex; the exchange's status.
    fgsr_status destroy_session(uint32_t session_id);
};

struct fgsr_session {
    fgsr_connection* conn = nullptr;
    uint32_t id = 0;
    fgsr_session_desc desc{};
    fgsr_pool_layout layout{};
    fgsr::client::Fd fds[FGSR_FD_COUNT];
    fgsr::client::Mapping input, output, rings_map;
    fgsr::ipc::Rings rings{};
    // Private copies of the positions this side writes (never read back from shared memory).
    uint64_t submit_head = 0, completion_tail = 0, release_head = 0;
    uint64_t next_sequence = 1;
    fgsr::client::InputState inputs[FGSR_MAX_SLOTS] = {};
    bool output_held[FGSR_MAX_SLOTS] = {};
    std::map<uint64_t, fgsr::client::Outstanding> outstanding; // sequences without their LAST completion
    std::deque<fgsr_completion_entry> ready;                   // validated, not yet returned by wait
    fgsr_status broken = FGSR_STATUS_OK; // DISCONNECTED or PROTOCOL_ERROR once it happened
    std::unique_ptr<fgsr::client::Recorder> recorder;
    std::string record_dir;
    // Present reports not yet sent (fgsr_report_presents), and when the oldest was buffered.
    std::vector<fgsr_present_report> reports;
    uint64_t reports_since_ns = 0;
    uint64_t reports_lost = 0; // dropped because the socket was full
    uint64_t wait_spin_ns = 0; // wait_event's spin budget (wait_spin_ns_from_env at creation)

    fgsr_status pump();
    // Waits until a completion may be there: first spins up to wait_spin_ns for the completion ring's
    // head to move (no syscall; a completion published meanwhile needs no wake-up of this thread),
    // then sleeps on the complete eventfd. When the daemon has hung up it returns OK only while
    // what the caller waits for is still there (a queued completion; with for_input, a free input
    // slot), else DISCONNECTED.
    fgsr_status wait_event(uint64_t deadline_ns, bool for_input = false);
    bool input_free() const {
        for (uint32_t i = 0; i < layout.input_slot_count; ++i)
            if (inputs[i] == fgsr::client::InputState::free) return true;
        return false;
    }
    fgsr_status fail(fgsr_status s) {
        if (broken == FGSR_STATUS_OK) broken = s;
        return s;
    }
    void stop_recording();
    // Sends the buffered reports (FGSR_MSG_REPORT, no reply, never blocks).
    fgsr_status flush_reports();
};
