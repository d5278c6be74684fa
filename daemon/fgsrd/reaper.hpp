// The reaper: a thread that frees what it is handed, so that freeing large blocks does not delay a
// client. A lane's frame makes the engine's output images (a 1280x720 rgba32f image is 14.7 MB,
// each in its own mapping: fgsrd fixes glibc's mmap threshold, main.cpp); unmapping them took
// 0.8-1 ms, which the client waited for when the lane freed them before handing the frame back,
// and the next frame waited for when the lane freed them after (docs/SERVICE.md).
//
// The thread runs at nice +19, so that its frees (0.9 ms of CPU at 1280x720) yield to the server's,
// the lanes' and the clients' threads on a busy machine instead of delaying their wake-ups.
// Only plain memory goes here: nothing that must be destroyed on a particular thread (engine
// objects are destroyed on their lane). Bounded: when max_bytes (or max_items) are queued
// already, dispose() frees on the caller's thread instead, so memory never piles up behind a
// starved reaper.
//
// Thread-safety: dispose() from any thread. The thread starts on the first dispose(), with
// SIGTERM and SIGINT blocked (the server reads them through a signalfd).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

namespace fgsrd {

class Reaper {
  public:
    explicit Reaper(size_t max_bytes = size_t(256) << 20, size_t max_items = 16)
        : max_bytes_(max_bytes), max_items_(max_items) {}
    // Frees what is still queued, then joins the thread.
    ~Reaper();
    Reaper(const Reaper&) = delete;
    Reaper& operator=(const Reaper&) = delete;

    // Destroys `garbage` (about `bytes` of memory) on the reaper's thread, or here when the backlog
    // is full.
    void dispose(std::shared_ptr<void> garbage, size_t bytes);
    // Items freed on the reaper's thread and on callers' threads (backlog full), for tests.
    size_t freed_async() const;
    size_t freed_inline() const;

  private:
    void loop();

    const size_t max_bytes_, max_items_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<std::pair<std::shared_ptr<void>, size_t>> queue_;
    size_t queued_bytes_ = 0;
    size_t freed_async_ = 0, freed_inline_ = 0;
    bool stop_ = false;
    std::thread thread_;
};

} // namespace fgsrd
