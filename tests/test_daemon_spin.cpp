// Bounded spinning (fgsr/ipc/spin.hpp, used by fgsrd --spin-us and FGSR_WAIT_SPIN_US) and fgsrd's
// reaper (daemon/fgsrd/reaper.hpp): functional properties only, no time thresholds beyond
// "returns" (a spin that never ends would hang the test).
#include "reaper.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/ipc/spin.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

namespace {

TEST(DaemonSpin, SpinUntilReturnsWhenReady) {
    int calls = 0;
    EXPECT_TRUE(fgsr::ipc::spin_until([&] { return ++calls == 3; }, 10'000'000'000ull));
    EXPECT_EQ(calls, 3);
    calls = 0;
    EXPECT_TRUE(fgsr::ipc::spin_until([&] { return ++calls == 1; }, 0));
    EXPECT_EQ(calls, 1);
}

TEST(DaemonSpin, SpinUntilStopsAtItsBudget) {
    int calls = 0;
    EXPECT_FALSE(fgsr::ipc::spin_until([&] { return ++calls, false; }, 0)); // budget 0: one look
    EXPECT_EQ(calls, 1);
    const uint64_t t0 = fgsr::monotonic_ns();
    EXPECT_FALSE(fgsr::ipc::spin_until([] { return false; }, 2'000'000)); // returns: bounded
    EXPECT_GE(fgsr::monotonic_ns() - t0, 2'000'000u);                     // not before its budget
}

TEST(DaemonSpin, SpinUntilSeesAnotherThreadsStore) {
    std::atomic<bool> flag{false};
    std::thread t([&] { flag.store(true, std::memory_order_release); });
    // Generous budget: the thread may be slow to start on a loaded machine; the spin still ends.
    const bool seen =
        fgsr::ipc::spin_until([&] { return flag.load(std::memory_order_acquire); }, 5'000'000'000ull);
    t.join();
    EXPECT_TRUE(seen);
}

// Counts its destructions (and where they ran) through a shared counter.
struct Tracked {
    std::atomic<int>* destroyed;
    std::thread::id* where;
    ~Tracked() {
        if (where) *where = std::this_thread::get_id();
        destroyed->fetch_add(1);
    }
};

TEST(DaemonSpin, ReaperFreesOnItsThreadAndEverythingAtDestruction) {
    std::atomic<int> destroyed{0};
    std::thread::id where;
    {
        fgsrd::Reaper reaper;
        reaper.dispose(std::make_shared<Tracked>(&destroyed, &where), 100);
        for (int i = 0; i < 5; ++i)
            reaper.dispose(std::make_shared<Tracked>(&destroyed, nullptr), 100);
    }
    EXPECT_EQ(destroyed.load(), 6);
    EXPECT_NE(where, std::this_thread::get_id());
}

TEST(DaemonSpin, ReaperFreesInlineWhenItsBacklogIsFull) {
    // The first item blocks the reaper's thread until released, so the queue fills up.
    std::mutex m;
    std::condition_variable cv;
    bool release = false, started = false;
    struct Blocker {
        std::mutex* m;
        std::condition_variable* cv;
        bool* release;
        bool* started;
        ~Blocker() {
            std::unique_lock lock(*m);
            *started = true;
            cv->notify_all();
            cv->wait(lock, [&] { return *release; });
        }
    };
    std::atomic<int> destroyed{0};
    {
        fgsrd::Reaper reaper(1000, 2); // at most 2 queued, 1000 bytes
        reaper.dispose(std::make_shared<Blocker>(&m, &cv, &release, &started), 1);
        {
            std::unique_lock lock(m);
            cv.wait(lock, [&] { return started; }); // the reaper is inside the blocker
        }
        reaper.dispose(std::make_shared<Tracked>(&destroyed, nullptr), 10);
        reaper.dispose(std::make_shared<Tracked>(&destroyed, nullptr), 10);
        EXPECT_EQ(destroyed.load(), 0);                                              // queued
        reaper.dispose(std::make_shared<Tracked>(&destroyed, nullptr), 10); // 2 queued: inline
        EXPECT_EQ(destroyed.load(), 1);
        EXPECT_EQ(reaper.freed_inline(), 1u);
        {
            std::lock_guard lock(m);
            release = true;
        }
        cv.notify_all();
    }
    EXPECT_EQ(destroyed.load(), 3);
}

TEST(DaemonSpin, ReaperFreesInlineWhatExceedsItsByteBound) {
    std::atomic<int> destroyed{0};
    fgsrd::Reaper reaper(1000, 16);
    reaper.dispose(std::make_shared<Tracked>(&destroyed, nullptr), 1001);
    EXPECT_EQ(destroyed.load(), 1);
    EXPECT_EQ(reaper.freed_inline(), 1u);
}

} // namespace
