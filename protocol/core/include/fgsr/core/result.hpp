// Errors as values: every fallible engine, importer and tool function returns Result<T>.
// No exceptions cross the engine's public surface.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace fgsr {

enum class Errc {
    invalid_argument, // a caller-supplied value is out of range (alpha, size, index)
    size_mismatch,    // planes or frames whose sizes disagree with the session
    unsupported,      // a format, convention or device feature fgsr does not handle
    empty_input,      // missing plane, zero-sized frame, or no frame where one is needed
    io,               // file missing, unreadable, or malformed
    vulkan,           // a Vulkan call failed
    no_device,        // no Vulkan device matches the selection
};

const char* errc_name(Errc c);

struct Error {
    Errc code;
    std::string message; // human-readable reason, names the offending value
};

template <class T> class [[nodiscard]] Result {
  public:
    Result(T value) : v_(std::move(value)) {}
    Result(Error e) : v_(std::move(e)) {}
    bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }
    T& value() & { return std::get<0>(v_); }
    const T& value() const& { return std::get<0>(v_); }
    T&& value() && { return std::get<0>(std::move(v_)); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    const Error& error() const { return std::get<1>(v_); }

  private:
    std::variant<T, Error> v_;
};

template <> class [[nodiscard]] Result<void> {
  public:
    Result() = default;
    Result(Error e) : e_(std::move(e)), ok_(false) {}
    bool ok() const { return ok_; }
    explicit operator bool() const { return ok_; }
    const Error& error() const { return e_; }

  private:
    Error e_{Errc::invalid_argument, {}};
    bool ok_ = true;
};

inline Error make_error(Errc c, std::string msg) {
    return Error{c, std::move(msg)};
}

} // namespace fgsr

// Propagates the error of a Result expression out of the enclosing function.
#define FGSR_TRY(expr)                                                                                       \
    do {                                                                                                     \
        auto&& fgsr_try_r_ = (expr);                                                                         \
        if (!fgsr_try_r_) return fgsr_try_r_.error();                                                        \
    } while (0)
