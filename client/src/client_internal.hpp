// Private pieces of libfgsr_client shared by its translation units. Nothing here is exported
// (the library is built with hidden visibility; only the fgsr_* C functions are public).
#pragma once

#include <fgsr/protocol.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>

namespace fgsr::client {

// Owns one file descriptor; move-only; closes on destruction.
class Fd {
  public:
    Fd() = default;
    explicit Fd(int fd) : fd_(fd) {}
    Fd(Fd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
    Fd& operator=(Fd&& o) noexcept {
        if (this != &o) {
            reset();
            fd_ = std::exchange(o.fd_, -1);
        }
        return *this;
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { reset(); }
    int get() const { return fd_; }
    bool valid() const { return fd_ >= 0; }
    void reset();

  private:
    int fd_ = -1;
};

// Owns one mmap'ed range; move-only; unmaps on destruction.
class Mapping {
  public:
    Mapping() = default;
    Mapping(void* p, size_t n) : p_(p), n_(n) {}
    Mapping(Mapping&& o) noexcept : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)) {}
    Mapping& operator=(Mapping&& o) noexcept {
        if (this != &o) {
            reset();
            p_ = std::exchange(o.p_, nullptr);
            n_ = std::exchange(o.n_, 0);
        }
        return *this;
    }
    Mapping(const Mapping&) = delete;
    Mapping& operator=(const Mapping&) = delete;
    ~Mapping() { reset(); }
    std::byte* data() const { return static_cast<std::byte*>(p_); }
    size_t size() const { return n_; }
    void reset();

  private:
    void* p_ = nullptr;
    size_t n_ = 0;
};

// Bytes per pixel of a protocol colour format (0 for an unknown value).
size_t color_bytes(uint32_t format);
// Bytes per pixel of a protocol vector format (0 for an unknown value).
size_t mv_bytes(uint32_t format);

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

} // namespace fgsr::client
