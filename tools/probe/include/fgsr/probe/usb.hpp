// The libusb layer of fgsr_probe: owners of a libusb context and of an open device (with the
// interfaces it claimed, and the kernel drivers it detached to claim them, reattached when it is
// closed), bulk and control transfers with timeouts, and the messages for libusb's failures
// (permission denied names the udev rule file, docs/PROBE.md "Permissions").
//
// Every transfer takes a timeout in ms (> 0); none blocks longer. Errors are values: a transfer
// returns UsbIo (the libusb status kept, so that a caller can tell a timeout from the rest) and
// usb_io_error() turns a failed one into an fgsr::Error whose message says what was being done.
// Not thread-safe: one thread uses a context and its handles.
#pragma once

#include <fgsr/core/result.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

struct libusb_context;
struct libusb_device;
struct libusb_device_handle;

namespace fgsr::probe {

// What a libusb status means for a probe.
enum class UsbFailure {
    none,      // success
    timeout,   // nothing within the timeout
    stall,     // the endpoint stalled (the device refused the transfer)
    no_device, // the device is gone (unplugged, reset)
    access,    // permission denied (udev rule missing)
    busy,      // another driver or program holds the interface
    other,     // anything else (overflow, I/O error, ...)
};
UsbFailure usb_failure(int libusb_status);

// "LIBUSB_ERROR_TIMEOUT (Operation timed out)".
std::string usb_status_text(int libusb_status);

// The message for a device that cannot be opened for lack of permission: names the udev rule file
// (in the source tree and where `cmake --install` puts it) and how to install it.
std::string permission_message(const std::string& device);

// The result of one transfer: the libusb status (0: success) and the bytes moved.
struct UsbIo {
    int status = 0;
    size_t bytes = 0;
    UsbFailure failure() const { return usb_failure(status); }
    bool ok() const { return status == 0; }
};

// An Error for a failed transfer: "<what>: <why>" (timeout: "no reply within N ms"; stall; unplug;
// permission; others with libusb's name). Errc::no_device for a vanished device, Errc::io else.
Error usb_io_error(const UsbIo& io, const std::string& what, int timeout_ms);

class UsbContext {
  public:
    static Result<UsbContext> create();
    UsbContext(UsbContext&& o) noexcept;
    UsbContext& operator=(UsbContext&& o) noexcept;
    UsbContext(const UsbContext&) = delete;
    UsbContext& operator=(const UsbContext&) = delete;
    ~UsbContext();

    libusb_context* get() const { return ctx_; }
    // Handles pending libusb events (hot-plug callbacks) for at most timeout_ms.
    void handle_events(int timeout_ms);

  private:
    explicit UsbContext(libusb_context* c) : ctx_(c) {}
    libusb_context* ctx_ = nullptr;
};

// "bus 1 address 5 (1209:0001)": how messages name a device.
std::string device_label(libusb_device* dev);

class UsbDevice {
  public:
    // Opens dev (LIBUSB_ERROR_ACCESS: permission_message()).
    static Result<UsbDevice> open(libusb_device* dev);
    UsbDevice(UsbDevice&& o) noexcept;
    UsbDevice& operator=(UsbDevice&& o) noexcept;
    UsbDevice(const UsbDevice&) = delete;
    UsbDevice& operator=(const UsbDevice&) = delete;
    // Releases the claimed interfaces, reattaches the kernel drivers it detached, closes.
    ~UsbDevice();

    // Claims interface; detaches the kernel driver bound to it first (cdc_acm for a serial probe),
    // remembering to reattach it. A device or platform without kernel-driver support counts as
    // "no driver bound".
    Result<void> claim(uint8_t interface);
    // Releases every claimed interface and reattaches what was detached (also the destructor's
    // job); returns the first failure (the others are still attempted).
    Result<void> release_all();

    UsbIo bulk_write(uint8_t endpoint, std::span<const uint8_t> data, int timeout_ms);
    UsbIo bulk_read(uint8_t endpoint, std::span<uint8_t> buffer, int timeout_ms);
    // A control transfer without data stage or with an OUT data stage.
    UsbIo control_out(uint8_t request_type, uint8_t request, uint16_t value, uint16_t index,
                      std::span<const uint8_t> data, int timeout_ms);

    // Clears a stalled endpoint (after a stall, before the endpoint is used again).
    UsbIo clear_halt(uint8_t endpoint);

    // Interfaces whose kernel driver this handle detached (and has not reattached yet).
    const std::vector<uint8_t>& detached() const { return detached_; }
    const std::string& label() const { return label_; }
    libusb_device_handle* get() const { return handle_; }

  private:
    UsbDevice(libusb_device_handle* h, std::string label) : handle_(h), label_(std::move(label)) {}
    void close();
    libusb_device_handle* handle_ = nullptr;
    std::string label_;
    std::vector<uint8_t> claimed_, detached_;
};

} // namespace fgsr::probe
