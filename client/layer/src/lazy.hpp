// A process-wide object of the layer, made at its first use and freed on request, after which the
// next use makes a fresh one. The layer's state lives this way so that it can be freed when the
// loader unloads the layer (layer.cpp, the exit hook): the loader loads the layer again with the
// next instance, and a process that does that in a loop must not leak the state of each load.
#pragma once

#include <atomic>
#include <mutex>

namespace fgsr::layer {

template <class T> class Lazy {
  public:
    // The object, made now if there is none (thread-safe; a load and no lock once it exists).
    T& get() {
        if (T* p = object_.load(std::memory_order_acquire)) return *p;
        std::lock_guard l(mutex_);
        T* p = object_.load(std::memory_order_relaxed);
        if (!p) {
            p = new T();
            object_.store(p, std::memory_order_release);
        }
        return *p;
    }
    // Frees the object if there is one and `may_free(object)` says so (called under the lock that
    // get() makes objects under). The caller makes sure no other thread still uses it.
    template <class Pred> void reset_if(Pred may_free) {
        std::lock_guard l(mutex_);
        T* p = object_.load(std::memory_order_relaxed);
        if (!p || !may_free(*p)) return;
        object_.store(nullptr, std::memory_order_release);
        delete p;
    }
    void reset() {
        reset_if([](const T&) { return true; });
    }

  private:
    std::atomic<T*> object_{nullptr};
    std::mutex mutex_;
};

} // namespace fgsr::layer
