#include "reaper.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

namespace fgsrd {

Reaper::~Reaper() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void Reaper::dispose(std::shared_ptr<void> garbage, size_t bytes) {
    std::unique_lock lock(mutex_);
    if (queue_.size() >= max_items_ || queued_bytes_ + bytes > max_bytes_ || stop_) {
        ++freed_inline_;
        lock.unlock();
        garbage.reset();
        return;
    }
    if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
    queue_.emplace_back(std::move(garbage), bytes);
    queued_bytes_ += bytes;
    lock.unlock();
    wake_.notify_one();
}

size_t Reaper::freed_async() const {
    std::lock_guard lock(mutex_);
    return freed_async_;
}

size_t Reaper::freed_inline() const {
    std::lock_guard lock(mutex_);
    return freed_inline_;
}

void Reaper::loop() {
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGTERM);
    sigaddset(&mask, SIGINT);
    pthread_sigmask(SIG_BLOCK, &mask, nullptr);
    pthread_setname_np(pthread_self(), "fgsr-reaper");
    errno = 0;
    const int now = getpriority(PRIO_PROCESS, gettid());
    if (errno == 0) (void)setpriority(PRIO_PROCESS, gettid(), std::min(now + 19, 19));
    std::unique_lock lock(mutex_);
    for (;;) {
        wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
        if (queue_.empty()) return; // stop_, and everything queued is freed
        auto [item, bytes] = std::move(queue_.front());
        queue_.pop_front();
        lock.unlock();
        item.reset();
        lock.lock();
        queued_bytes_ -= bytes;
        ++freed_async_;
    }
}

} // namespace fgsrd
