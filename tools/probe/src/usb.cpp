// libusb context and device owners, transfers with timeouts, and the messages of libusb's failures.
#include <fgsr/probe/usb.hpp>

#include <libusb.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <utility>

namespace fgsr::probe {

UsbFailure usb_failure(int s) {
    switch (s) {
    case LIBUSB_SUCCESS:
        return UsbFailure::none;
    case LIBUSB_ERROR_TIMEOUT:
        return UsbFailure::timeout;
    case LIBUSB_ERROR_PIPE:
        return UsbFailure::stall;
    case LIBUSB_ERROR_NO_DEVICE:
        return UsbFailure::no_device;
    case LIBUSB_ERROR_ACCESS:
        return UsbFailure::access;
    case LIBUSB_ERROR_BUSY:
        return UsbFailure::busy;
    default:
        return UsbFailure::other;
    }
}

std::string usb_status_text(int s) {
    return std::string(libusb_error_name(s)) + " (" + libusb_strerror(s) + ")";
}

std::string permission_message(const std::string& device) {
    return "cannot open the probe at " + device +
           ": permission denied. The udev rule 70-fgsr-probe.rules gives the logged-in user the "
           "supported probes: sudo cp " FGSR_PROBE_RULES_SOURCE " /etc/udev/rules.d/ (cmake --install "
           "puts a copy in " FGSR_PROBE_RULES_INSTALLED ", which udev reads only under the prefix /usr), "
           "then sudo udevadm control --reload && sudo udevadm trigger, and replug the probe "
           "(docs/PROBE.md, \"Permissions\")";
}

Error usb_io_error(const UsbIo& io, const std::string& what, int timeout_ms) {
    switch (io.failure()) {
    case UsbFailure::none:
        return make_error(Errc::io, what + ": no error");
    case UsbFailure::timeout:
        return make_error(Errc::io, what + ": no reply within " + std::to_string(timeout_ms) + " ms");
    case UsbFailure::stall:
        return make_error(Errc::io, what + ": the endpoint stalled (the probe refused the transfer)");
    case UsbFailure::no_device:
        return make_error(Errc::no_device, what + ": the probe was unplugged (or reset)");
    case UsbFailure::access:
        return make_error(Errc::io, what + ": permission denied (docs/PROBE.md, \"Permissions\")");
    case UsbFailure::busy:
        return make_error(Errc::io, what + ": the device is busy (" + usb_status_text(io.status) + ")");
    case UsbFailure::other:
        break;
    }
    return make_error(Errc::io, what + ": " + usb_status_text(io.status));
}

// --- UsbContext ---

Result<UsbContext> UsbContext::create() {
    libusb_context* c = nullptr;
    if (int r = libusb_init(&c); r != 0)
        return make_error(Errc::io, "libusb_init failed: " + usb_status_text(r));
    return UsbContext(c);
}

UsbContext::UsbContext(UsbContext&& o) noexcept : ctx_(std::exchange(o.ctx_, nullptr)) {}

UsbContext& UsbContext::operator=(UsbContext&& o) noexcept {
    if (this != &o) {
        if (ctx_) libusb_exit(ctx_);
        ctx_ = std::exchange(o.ctx_, nullptr);
    }
    return *this;
}

UsbContext::~UsbContext() {
    if (ctx_) libusb_exit(ctx_);
}

void UsbContext::handle_events(int timeout_ms) {
    timeval tv{};
    tv.tv_sec = std::max(0, timeout_ms) / 1000;
    tv.tv_usec = (std::max(0, timeout_ms) % 1000) * 1000;
    libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
}

std::string device_label(libusb_device* dev) {
    libusb_device_descriptor d{};
    libusb_get_device_descriptor(dev, &d);
    char buf[64];
    std::snprintf(buf, sizeof buf, "bus %u address %u (%04x:%04x)", unsigned(libusb_get_bus_number(dev)),
                  unsigned(libusb_get_device_address(dev)), unsigned(d.idVendor), unsigned(d.idProduct));
    return buf;
}

// --- UsbDevice ---

Result<UsbDevice> UsbDevice::open(libusb_device* dev) {
    libusb_device_handle* h = nullptr;
    const std::string label = device_label(dev);
    const int r = libusb_open(dev, &h);
    if (r == LIBUSB_ERROR_ACCESS) return make_error(Errc::io, permission_message(label));
    if (r == LIBUSB_ERROR_NO_DEVICE)
        return make_error(Errc::no_device, "cannot open the probe at " + label + ": it was unplugged");
    if (r != 0) return make_error(Errc::io, "cannot open the probe at " + label + ": " + usb_status_text(r));
    return UsbDevice(h, label);
}

UsbDevice::UsbDevice(UsbDevice&& o) noexcept
    : handle_(std::exchange(o.handle_, nullptr)), label_(std::move(o.label_)),
      claimed_(std::move(o.claimed_)), detached_(std::move(o.detached_)) {}

UsbDevice& UsbDevice::operator=(UsbDevice&& o) noexcept {
    if (this != &o) {
        close();
        handle_ = std::exchange(o.handle_, nullptr);
        label_ = std::move(o.label_);
        claimed_ = std::move(o.claimed_);
        detached_ = std::move(o.detached_);
    }
    return *this;
}

UsbDevice::~UsbDevice() {
    close();
}

void UsbDevice::close() {
    if (!handle_) return;
    (void)release_all();
    libusb_close(handle_);
    handle_ = nullptr;
}

Result<void> UsbDevice::claim(uint8_t interface) {
    const std::string what = "interface " + std::to_string(interface) + " of the probe at " + label_;
    const int active = libusb_kernel_driver_active(handle_, interface);
    if (active == 1) {
        const int d = libusb_detach_kernel_driver(handle_, interface);
        if (d == LIBUSB_ERROR_NO_DEVICE)
            return make_error(Errc::no_device, what + ": the probe was unplugged");
        if (d != 0 && d != LIBUSB_ERROR_NOT_FOUND)
            return make_error(Errc::io,
                              "cannot detach the kernel driver from " + what + ": " + usb_status_text(d));
        if (d == 0) detached_.push_back(interface);
    } else if (active == LIBUSB_ERROR_NO_DEVICE) {
        return make_error(Errc::no_device, what + ": the probe was unplugged");
    } else if (active < 0 && active != LIBUSB_ERROR_NOT_SUPPORTED) {
        return make_error(Errc::io, "cannot ask which driver holds " + what + ": " + usb_status_text(active));
    }
    const int c = libusb_claim_interface(handle_, interface);
    if (c == LIBUSB_ERROR_BUSY)
        return make_error(Errc::io, "cannot claim " + what +
                                        ": another program holds it (a serial terminal, ModemManager, "
                                        "another fgsr probe?)");
    if (c == LIBUSB_ERROR_NO_DEVICE) return make_error(Errc::no_device, what + ": the probe was unplugged");
    if (c != 0) return make_error(Errc::io, "cannot claim " + what + ": " + usb_status_text(c));
    claimed_.push_back(interface);
    return {};
}

Result<void> UsbDevice::release_all() {
    Result<void> first;
    for (uint8_t i : claimed_) {
        const int r = libusb_release_interface(handle_, i);
        if (r != 0 && r != LIBUSB_ERROR_NO_DEVICE && first)
            first = make_error(Errc::io, "cannot release interface " + std::to_string(i) +
                                             " of the probe at " + label_ + ": " + usb_status_text(r));
    }
    claimed_.clear();
    for (uint8_t i : detached_) {
        // BUSY: the driver is back already (cdc_acm binds its data interface with the other one).
        const int r = libusb_attach_kernel_driver(handle_, i);
        if (r != 0 && r != LIBUSB_ERROR_NO_DEVICE && r != LIBUSB_ERROR_BUSY && first)
            first =
                make_error(Errc::io, "cannot reattach the kernel driver of interface " + std::to_string(i) +
                                         " of the probe at " + label_ + ": " + usb_status_text(r));
    }
    detached_.clear();
    return first;
}

UsbIo UsbDevice::bulk_write(uint8_t endpoint, std::span<const uint8_t> data, int timeout_ms) {
    UsbIo io;
    int moved = 0;
    if (data.size() > size_t(INT_MAX)) return UsbIo{LIBUSB_ERROR_INVALID_PARAM, 0};
    io.status = libusb_bulk_transfer(handle_, endpoint, const_cast<uint8_t*>(data.data()), int(data.size()),
                                     &moved, unsigned(std::max(1, timeout_ms)));
    io.bytes = size_t(std::max(0, moved));
    return io;
}

UsbIo UsbDevice::bulk_read(uint8_t endpoint, std::span<uint8_t> buffer, int timeout_ms) {
    UsbIo io;
    int moved = 0;
    if (buffer.size() > size_t(INT_MAX)) return UsbIo{LIBUSB_ERROR_INVALID_PARAM, 0};
    io.status = libusb_bulk_transfer(handle_, endpoint, buffer.data(), int(buffer.size()), &moved,
                                     unsigned(std::max(1, timeout_ms)));
    // libusb reports what arrived before a failure too; never more than the buffer.
    io.bytes = std::min(buffer.size(), size_t(std::max(0, moved)));
    return io;
}

UsbIo UsbDevice::clear_halt(uint8_t endpoint) {
    return UsbIo{libusb_clear_halt(handle_, endpoint), 0};
}

UsbIo UsbDevice::control_out(uint8_t request_type, uint8_t request, uint16_t value, uint16_t index,
                             std::span<const uint8_t> data, int timeout_ms) {
    if (data.size() > 0xffff) return UsbIo{LIBUSB_ERROR_INVALID_PARAM, 0};
    const int r = libusb_control_transfer(handle_, request_type, request, value, index,
                                          const_cast<uint8_t*>(data.data()), uint16_t(data.size()),
                                          unsigned(std::max(1, timeout_ms)));
    if (r < 0) return UsbIo{r, 0};
    return UsbIo{0, size_t(r)};
}

} // namespace fgsr::probe
