// One client session of fgsrd: its shared memory (input and output slot pools, rings), eventfds,
// engine session, slot ownership, pending submits and statistics.
//
// Thread-safety: the server's thread owns a ServiceSession, except that execute() and the
// destructor run on the session's lane (lane.hpp): execute() touches only the engine session, the
// input and output pools (the output slots begin() reserved) and the FrameJob; the server starts
// no second job for a session while one is in flight.
// Shared memory is hostile: every ring entry and counter the client writes is copied once into
// private memory and validated there; the daemon keeps private copies of the positions it owns.
#pragma once

#include <fgsr/core/clock.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/ipc/ring.hpp>
#include <fgsr/ipc/unique_fd.hpp>
#include <fgsr/wire.h>

#include <array>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fgsrd {

using fgsr::monotonic_ns;
using fgsr::ipc::Mapping;
using fgsr::ipc::UniqueFd;
uint64_t thread_cpu_ns();
// Adds 1 to an eventfd the client shares. The client can clear O_NONBLOCK on the shared file
// description and fill the counter, which would block write() for good; so the write runs under a
// per-thread timer whose signal interrupts it. False when it was interrupted (a hostile client)
// or failed for another reason than a full counter.
bool signal_eventfd(int fd);

class ServiceSession {
  public:
    // Validates desc (copied by the caller) and allocates everything. zero_copy: import the input
    // pool into the device when it supports VK_EXT_external_memory_host with FGSR_PLANE_ALIGNMENT.
    // engine null: a session whose frames complete with DEVICE_ERROR, for tests and fuzzing of
    // the ring protocol (poll, begin, finish) without a device.
    static std::unique_ptr<ServiceSession> create(fgsr::Engine* engine, uint32_t id,
                                                  const fgsr_session_desc& desc, bool zero_copy,
                                                  int32_t& status, std::string& reason);
    ~ServiceSession();
    ServiceSession(const ServiceSession&) = delete;
    ServiceSession& operator=(const ServiceSession&) = delete;

    uint32_t id() const { return id_; }
    const fgsr_pool_layout& layout() const { return layout_; }
    const fgsr_session_desc& desc() const { return desc_; } // normalised
    int submit_event_fd() const { return submit_event_.get(); }
    bool zero_copy() const { return import_ != nullptr; }
    // The five fds of the CREATE_SESSION reply in FGSR_FD_* order. The memfds are closed by
    // close_shared_fds() once sent (the mappings stay).
    std::array<int, FGSR_FD_COUNT> fds() const;
    void close_shared_fds();

    // Reads the submit and release rings (the submit eventfd is only a wake-up: the server watches
    // it edge-triggered and never reads it, so no flag the client sets on it can block the daemon).
    // Returns a reason on a protocol violation (the caller disconnects the client), else nullopt.
    std::optional<std::string> poll();
    // True when the next pending submit (or a mailbox drop) can be completed now.
    bool ready() const;
    // True when work is pending but waits for the client to consume completions (no eventfd tells
    // the daemon when that happens, so the server re-polls on a short timer).
    bool waiting_on_completion_ring() const;

    // A frame runs in three steps: begin() on the server's thread takes the next submit (drops,
    // rejections and other completions that need no engine are published at once) and reserves
    // its output slots; execute() on the session's lane makes the engine calls and writes the
    // outputs into those slots; finish() on the server's thread publishes the completions.
    struct FrameJob;
    struct Begun {
        std::optional<std::string> violation;
        std::shared_ptr<FrameJob> job; // null: nothing for the engine
    };
    Begun begin();
    // The engine's images of a frame: execute() moves them here, and its caller has them freed off
    // the clients' critical path (reaper.hpp).
    struct Spent {
        std::optional<fgsr::GeneratedFrame> sr;
        std::vector<fgsr::GeneratedFrame> interp, extrap;
        size_t bytes() const;
    };
    void execute(FrameJob& job, Spent& spent);
    void execute(FrameJob& job) {
        Spent spent;
        execute(job, spent);
    }
    std::optional<std::string> finish(FrameJob& job);
    bool in_flight() const { return in_flight_; }

    // Grows whenever the client pushes a submit or a release (for idle detection).
    uint64_t ring_activity() const { return submit_tail_ + release_tail_; }
    bool has_work() const { return in_flight_ || !pending_.empty(); }
    // Engine time this session has used (ns), for fair scheduling between sessions.
    uint64_t engine_ns() const { return engine_ns_; }
    // Signals the complete eventfd. False when the write had to be interrupted: the client made
    // the eventfd blocking and filled its counter (see server.cpp); the caller drops the client.
    bool signal_complete();
    // Completions were pushed since the last signal_complete().
    bool signal_pending() const { return signal_pending_; }
    fgsr_session_stats stats() const;
    // Called with every completion pushed (on the server's thread): the telemetry hub.
    void set_completion_observer(std::function<void(const fgsr_completion_entry&)> observer) {
        observer_ = std::move(observer);
    }

  private:
    struct Pending {
        fgsr_submit_entry entry; // private, validated copy
        uint64_t dequeue_ns = 0;
    };
    struct Output {
        int32_t status = FGSR_STATUS_OK;
        uint32_t frame_type = FGSR_FRAME_NONE;
        float target_time = 1.f;
        const fgsr::GeneratedFrame* frame = nullptr; // image and passes when status is OK
    };

  public:
    struct FrameJob {
        Pending pending;
        std::vector<uint32_t> slots;                    // output slots reserved by begin()
        std::vector<fgsr_completion_entry> completions; // written by execute()
        uint64_t bytes_copied = 0;
        uint64_t engine_ns = 0;
    };

  private:
    ServiceSession() = default;
    std::optional<std::string> validate(const fgsr_submit_entry& e) const;
    uint32_t requested_outputs(const fgsr_submit_entry& e) const;
    std::optional<uint64_t> completion_free() const; // nullopt: the client corrupted the tail
    void push_completion(const fgsr_completion_entry& c);
    void complete_without_output(const Pending& p, int32_t status);
    bool reserved(uint32_t slot) const; // by the frame in flight
    void write_output(uint32_t slot, const fgsr::ImageRGBA& image);
    void record_latency(std::vector<uint64_t>& v, uint64_t ns);

    uint32_t id_ = 0;
    fgsr_session_desc desc_{};
    fgsr_pool_layout layout_{};
    fgsr::ipc::Rings rings_{}; // in rings_map_, set once the mapping exists

    // Declaration order is destruction order reversed: the engine session goes first, then the
    // imported memory, then the mappings and fds.
    UniqueFd input_fd_, output_fd_, rings_fd_, submit_event_, complete_event_;
    Mapping input_map_, output_map_, rings_map_;
    std::unique_ptr<fgsr::HostMemory> import_;
    std::unique_ptr<fgsr::Session> engine_session_;

    // Ownership: true where the daemon holds the slot (input) or where the client holds it or a
    // running frame will write it (output).
    std::array<bool, FGSR_MAX_SLOTS> input_with_daemon_{};
    std::array<bool, FGSR_MAX_SLOTS> output_taken_{};
    uint32_t free_outputs_ = 0;
    bool in_flight_ = false;
    std::vector<uint32_t> reserved_; // output slots of the frame in flight
    bool signal_pending_ = false;    // completions pushed since the last signal
    uint64_t engine_ns_ = 0;

    // Private ring positions (never re-read from shared memory).
    uint64_t submit_tail_ = 0, completion_head_ = 0, release_tail_ = 0;
    uint64_t last_sequence_ = 0;
    uint64_t previous_present_ns_ = 0; // present time of the last processed frame (0: unknown); lane only
    std::deque<Pending> pending_;
    std::function<void(const fgsr_completion_entry&)> observer_;

    fgsr_session_stats stats_{};
    std::vector<uint64_t> latency_, gpu_, queue_wait_; // the most recent samples, for percentiles
};

} // namespace fgsrd
