#include "lane.hpp"

#include "log.hpp"

#include <fgsr/core/clock.hpp>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <future>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

namespace fgsrd {

fgsr::Result<std::unique_ptr<Lane>> Lane::start(const Config& config,
                                                std::function<void(Continuation)> deliver, bool wait) {
    std::unique_ptr<Lane> lane(new Lane(config));
    lane->deliver_ = std::move(deliver);
    auto started = std::make_shared<std::promise<void>>();
    auto ready = started->get_future();
    Lane* self = lane.get();
    lane->thread_ = std::thread([self, started] {
        // The server handles SIGTERM/SIGINT through a signalfd; no lane or driver thread takes them.
        sigset_t mask;
        sigemptyset(&mask);
        sigaddset(&mask, SIGTERM);
        sigaddset(&mask, SIGINT);
        pthread_sigmask(SIG_BLOCK, &mask, nullptr);
        pthread_setname_np(pthread_self(), ("fgsr-" + self->config_.name).substr(0, 15).c_str());
        if (self->config_.nice != 0) {
            // Per thread on Linux; threads the driver starts from here inherit it.
            errno = 0;
            const int now = getpriority(PRIO_PROCESS, gettid());
            if (errno == 0 && setpriority(PRIO_PROCESS, gettid(), now + self->config_.nice) != 0)
                log::warn("lane {}: cannot lower its priority: {}", self->config_.name, std::strerror(errno));
        }
        auto engine = fgsr::Engine::create(fgsr::DeviceOptions{self->config_.device});
        std::unique_ptr<fgsr::Engine> owned;
        if (engine) {
            owned = std::move(*engine);
            self->device_name_ = owned->device_name();
            self->host_import_alignment_ = owned->host_import_alignment();
            self->calibrated_time_ = owned->calibrated_time();
            if (self->config_.warm_up) {
                const uint64_t t0 = fgsr::monotonic_ns();
                auto warmed = owned->warm_up();
                const double ms = double(fgsr::monotonic_ns() - t0) / 1e6;
                if (warmed)
                    log::info("lane {}: warmed up in {:.0f} ms ({} frames, {} pipelines)", self->config_.name,
                              ms, *warmed, owned->pipelines_created());
                else
                    log::warn("lane {}: warm-up failed after {:.0f} ms: {}", self->config_.name, ms,
                              warmed.error().message);
            }
        } else {
            self->engine_error_ = engine.error().message;
        }
        started->set_value();
        self->loop(owned.get());
        owned.reset(); // the engine goes on the thread that made it, after its sessions
    });
    if (wait) {
        ready.wait();
        if (!lane->engine_error_.empty()) return fgsr::make_error(fgsr::Errc::no_device, lane->engine_error_);
    }
    return lane;
}

Lane::~Lane() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void Lane::post(Job job) {
    {
        std::lock_guard lock(mutex_);
        jobs_.push_back(std::move(job));
    }
    wake_.notify_one();
}

bool Lane::idle() const {
    std::lock_guard lock(mutex_);
    return jobs_.empty() && !running_job_;
}

uint64_t Lane::busy_ns() const {
    std::lock_guard lock(mutex_);
    return busy_ns_;
}

void Lane::loop(fgsr::Engine* engine) {
    for (;;) {
        Job job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || !jobs_.empty(); });
            if (jobs_.empty()) return; // stop_, and every queued job has run
            job = std::move(jobs_.front());
            jobs_.pop_front();
            running_job_ = true;
        }
        const uint64_t t0 = fgsr::monotonic_ns();
        Continuation then = job(engine);
        const uint64_t spent = fgsr::monotonic_ns() - t0;
        // Delivered before the lane reads as idle: the server never sees an idle lane whose last
        // job's continuation it has not been given.
        if (then) deliver_(std::move(then));
        std::lock_guard lock(mutex_);
        running_job_ = false;
        busy_ns_ += spent;
    }
}

} // namespace fgsrd
