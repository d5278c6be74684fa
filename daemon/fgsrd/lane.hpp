// A lane: one worker thread that owns one fgsr::Engine and makes every engine call of the sessions
// assigned to it (their creation, frames and destruction), one job at a time in posting order.
//
// Why: an engine call can take seconds (a 4096x4096 session with eight outputs per submit), and
// the Vulkan queue it waits on cannot be shared between threads without a lock. With the engine
// calls on lanes, the server's thread only moves bytes between sockets and rings and never waits
// for the device, so HELLO, STATS and other sessions' completions do not wait behind a frame.
// fgsrd runs two lanes: `interactive` for sessions up to a pixel budget and `bulk` for the larger
// ones, created at lower CPU priority (nice) so that on a CPU device (lavapipe) their shader
// threads yield to interactive frames (see server.cpp).
//
// Thread-safety: post() and idle() from the server's thread; a job runs on the lane's thread and
// returns a continuation that the lane hands to `deliver` (called on the lane's thread), which
// must queue it for the server's thread.
#pragma once

#include <fgsr/engine/engine.hpp>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace fgsrd {

class Lane {
  public:
    using Continuation = std::function<void()>;
    // The engine is null when it could not be created (engine_error() says why).
    using Job = std::function<Continuation(fgsr::Engine*)>;

    struct Config {
        std::string name;   // for logs: "interactive", "bulk"
        std::string device; // fgsr::DeviceOptions::device
        int nice = 0;       // added to the thread's nice value before the engine starts
        bool warm_up = false; // run fgsr::Engine::warm_up after creating the engine, before jobs
    };

    // Starts the thread and creates the engine on it (driver threads it starts inherit the
    // thread's priority). wait: return once the engine exists, or its error; else at once (jobs
    // posted meanwhile run after the engine's creation).
    static fgsr::Result<std::unique_ptr<Lane>> start(const Config& config,
                                                     std::function<void(Continuation)> deliver, bool wait);
    // Runs the jobs still queued (destructions), destroys the engine on the lane's thread, joins.
    ~Lane();
    Lane(const Lane&) = delete;
    Lane& operator=(const Lane&) = delete;

    const std::string& name() const { return config_.name; }
    // Set before start(wait = true) returns, constant after.
    const std::string& device_name() const { return device_name_; }
    size_t host_import_alignment() const { return host_import_alignment_; }
    bool calibrated_time() const { return calibrated_time_; }
    // Why the engine could not be created (read on the lane's thread, in a job given no engine).
    const std::string& engine_error() const { return engine_error_; }

    void post(Job job);
    // No job queued or running.
    bool idle() const;
    // Engine time (ns) spent on jobs so far.
    uint64_t busy_ns() const;

  private:
    explicit Lane(Config c) : config_(std::move(c)) {}
    void loop(fgsr::Engine* engine);

    Config config_;
    std::function<void(Continuation)> deliver_;
    std::string device_name_;
    size_t host_import_alignment_ = 0;
    bool calibrated_time_ = false;
    std::string engine_error_;

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Job> jobs_;
    bool running_job_ = false;
    bool stop_ = false;
    uint64_t busy_ns_ = 0;
    std::thread thread_;
};

} // namespace fgsrd
