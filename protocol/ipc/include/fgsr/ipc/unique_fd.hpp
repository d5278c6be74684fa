// Move-only owners of kernel resources shared by libfgsr_client and fgsrd: a file descriptor and
// a memory mapping. Every fd and mapping either side holds lives in one of these, so tearing a
// session or connection down frees everything by destruction. Not thread-safe (each owner is
// used by one thread).
#pragma once

#include <cstddef>
#include <utility>

namespace fgsr::ipc {

class UniqueFd {
  public:
    UniqueFd() = default;
    explicit UniqueFd(int fd) : fd_(fd) {}
    UniqueFd(UniqueFd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
    UniqueFd& operator=(UniqueFd&& o) noexcept {
        if (this != &o) reset(std::exchange(o.fd_, -1));
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;
    ~UniqueFd() { reset(); }

    int get() const { return fd_; }
    bool valid() const { return fd_ >= 0; }
    explicit operator bool() const { return valid(); }
    // Closes the owned fd (if any) and owns `fd` instead.
    void reset(int fd = -1);
    // Gives up ownership without closing.
    int release() { return std::exchange(fd_, -1); }

  private:
    int fd_ = -1;
};

// A mmap()ed range, unmapped on destruction.
class Mapping {
  public:
    Mapping() = default;
    Mapping(void* data, size_t size) : data_(data), size_(size) {}
    Mapping(Mapping&& o) noexcept
        : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
    Mapping& operator=(Mapping&& o) noexcept {
        if (this != &o) {
            reset();
            data_ = std::exchange(o.data_, nullptr);
            size_ = std::exchange(o.size_, 0);
        }
        return *this;
    }
    Mapping(const Mapping&) = delete;
    Mapping& operator=(const Mapping&) = delete;
    ~Mapping() { reset(); }

    // Maps `size` bytes of `fd` MAP_SHARED with `prot`; an invalid Mapping on failure (errno set).
    static Mapping map(int fd, size_t size, int prot);

    std::byte* data() const { return static_cast<std::byte*>(data_); }
    size_t size() const { return size_; }
    bool valid() const { return data_ != nullptr; }
    void reset();

  private:
    void* data_ = nullptr;
    size_t size_ = 0;
};

} // namespace fgsr::ipc
