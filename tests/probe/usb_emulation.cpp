// usbfs emulated for libusb through umockdev's ioctl handler API: what usb_emulation.hpp promises.
#include "usb_emulation.hpp"

#include <fgsr/core/clock.hpp>

#include <linux/ioctl.h>
#include <linux/usbdevice_fs.h>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace fgsr::probe::test {

namespace {

std::string hex(const std::vector<uint8_t>& b) {
    std::string s;
    char x[4];
    for (uint8_t c : b) {
        std::snprintf(x, sizeof x, "%02x", c);
        s += x;
    }
    return s;
}

std::string fmt(const char* f, auto... a) {
    char b[256];
    std::snprintf(b, sizeof b, f, a...);
    return b;
}

UMockdevIoctlData* resolve(UMockdevIoctlData* d, size_t offset, size_t len) {
    return umockdev_ioctl_data_resolve(d, offset, len, nullptr);
}

usbdevfs_urb* urb_of(UMockdevIoctlData* d) {
    return reinterpret_cast<usbdevfs_urb*>(d->data);
}

} // namespace

EmulatedDevice::EmulatedDevice(std::unique_ptr<Gadget> gadget, DriverBinding binding)
    : gadget_(std::move(gadget)), binding_(std::move(binding)), bound_(binding_.drivers) {
    handler_ = umockdev_ioctl_base_new();
    g_signal_connect(handler_, "handle-ioctl", G_CALLBACK(&EmulatedDevice::on_ioctl), this);
}

EmulatedDevice::~EmulatedDevice() {
    g_signal_handlers_disconnect_by_data(handler_, this);
    std::lock_guard lk(mutex_);
    for (auto* v : {&pending_, &done_, &discarded_})
        for (UMockdevIoctlData* d : *v) umockdev_ioctl_data_unref(d);
    g_object_unref(handler_);
}

std::vector<std::string> EmulatedDevice::log() const {
    std::lock_guard lk(mutex_);
    return log_;
}

std::string EmulatedDevice::driver(uint8_t interface) const {
    std::lock_guard lk(mutex_);
    auto it = bound_.find(interface);
    return it == bound_.end() ? "" : it->second;
}

size_t EmulatedDevice::ioctl_count() const {
    std::lock_guard lk(mutex_);
    return ioctls_;
}

bool EmulatedDevice::unplugged() const {
    std::lock_guard lk(mutex_);
    return unplugged_;
}

void EmulatedDevice::unplug() {
    std::lock_guard lk(mutex_);
    if (unplugged_) return;
    unplugged_ = true;
    log_.push_back("UNPLUG");
    fail_all_pending(-ENODEV);
}

gboolean EmulatedDevice::on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    static_cast<EmulatedDevice*>(self)->handle(client);
    return TRUE;
}

void EmulatedDevice::complete(UMockdevIoctlData* d, int status, size_t actual) {
    usbdevfs_urb* u = urb_of(d);
    u->status = status;
    u->actual_length = int(actual);
    done_.push_back(d);
}

void EmulatedDevice::fail_all_pending(int status) {
    for (UMockdevIoctlData* d : pending_) complete(d, status, 0);
    pending_.clear();
}

void EmulatedDevice::bind_group(uint8_t interface, bool bind) {
    std::vector<uint8_t> members{interface};
    for (const auto& g : binding_.groups)
        if (std::find(g.begin(), g.end(), interface) != g.end()) members = g;
    for (uint8_t m : members) {
        if (bind) {
            auto it = binding_.drivers.find(m);
            if (it != binding_.drivers.end()) bound_[m] = it->second;
        } else {
            bound_.erase(m);
        }
    }
}

void EmulatedDevice::handle(UMockdevIoctlClient* client) {
    std::lock_guard lk(mutex_);
    ++ioctls_;
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    const uint64_t now = fgsr::monotonic_ns();
    const auto done = [&](long result, int err) { umockdev_ioctl_client_complete(client, result, err); };

    if (request == USBDEVFS_REAPURB || request == USBDEVFS_REAPURBNDELAY) {
        reap(client, arg, now);
        return;
    }
    if (unplugged_) {
        done(-1, ENODEV);
        return;
    }
    switch (request) {
    case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData* d = resolve(arg, 0, sizeof(uint32_t));
        *reinterpret_cast<uint32_t*>(d->data) = USBDEVFS_CAP_BULK_CONTINUATION |
                                                USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                                USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
        umockdev_ioctl_data_unref(d);
        done(0, 0);
        return;
    }
    case USBDEVFS_GETDRIVER: {
        UMockdevIoctlData* d = resolve(arg, 0, sizeof(usbdevfs_getdriver));
        auto* g = reinterpret_cast<usbdevfs_getdriver*>(d->data);
        auto it = bound_.find(uint8_t(g->interface));
        log_.push_back(fmt("GETDRIVER %u %s", g->interface, it == bound_.end() ? "-" : it->second.c_str()));
        if (it == bound_.end()) {
            umockdev_ioctl_data_unref(d);
            done(-1, ENODATA);
            return;
        }
        std::snprintf(g->driver, sizeof g->driver, "%s", it->second.c_str());
        umockdev_ioctl_data_unref(d);
        done(0, 0);
        return;
    }
    case USBDEVFS_IOCTL: {
        UMockdevIoctlData* d = resolve(arg, 0, sizeof(usbdevfs_ioctl));
        const auto* c = reinterpret_cast<const usbdevfs_ioctl*>(d->data);
        const uint8_t ifc = uint8_t(c->ifno);
        const unsigned code = unsigned(c->ioctl_code);
        umockdev_ioctl_data_unref(d);
        const bool bound = bound_.count(ifc) != 0;
        if (code == USBDEVFS_DISCONNECT) {
            log_.push_back(fmt("DISCONNECT %u", unsigned(ifc)));
            if (!bound) return done(-1, ENODATA);
            bind_group(ifc, false);
            return done(0, 0);
        }
        if (code == USBDEVFS_CONNECT) {
            log_.push_back(fmt("CONNECT %u", unsigned(ifc)));
            if (bound) return done(-1, EBUSY);
            if (std::find(claimed_.begin(), claimed_.end(), ifc) != claimed_.end()) return done(-1, EBUSY);
            bind_group(ifc, true);
            return done(0, 0);
        }
        log_.push_back(fmt("IOCTL %u code %#x", unsigned(ifc), code));
        return done(-1, ENOTTY);
    }
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE: {
        UMockdevIoctlData* d = resolve(arg, 0, sizeof(unsigned));
        const uint8_t ifc = uint8_t(*reinterpret_cast<unsigned*>(d->data));
        umockdev_ioctl_data_unref(d);
        const bool claim = request == USBDEVFS_CLAIMINTERFACE;
        log_.push_back(fmt("%s %u", claim ? "CLAIM" : "RELEASE", unsigned(ifc)));
        if (claim) {
            if (bound_.count(ifc)) return done(-1, EBUSY); // a kernel driver holds it
            if (std::find(claimed_.begin(), claimed_.end(), ifc) == claimed_.end()) claimed_.push_back(ifc);
        } else {
            claimed_.erase(std::remove(claimed_.begin(), claimed_.end(), ifc), claimed_.end());
        }
        return done(0, 0);
    }
    case USBDEVFS_CLEAR_HALT:
    case USBDEVFS_RESETEP: {
        UMockdevIoctlData* d = resolve(arg, 0, sizeof(unsigned));
        log_.push_back(fmt("%s 0x%02x", request == USBDEVFS_CLEAR_HALT ? "CLEAR_HALT" : "RESETEP",
                           *reinterpret_cast<unsigned*>(d->data)));
        umockdev_ioctl_data_unref(d);
        return done(0, 0);
    }
    case USBDEVFS_SUBMITURB:
        submit(client, arg, now);
        return;
    case USBDEVFS_DISCARDURB: {
        const gulong addr = *reinterpret_cast<const gulong*>(arg->data);
        auto it = std::find_if(pending_.begin(), pending_.end(),
                               [&](UMockdevIoctlData* u) { return u->client_addr == addr; });
        if (it == pending_.end()) return done(-1, EINVAL);
        log_.push_back(fmt("DISCARD 0x%02x", unsigned(urb_of(*it)->endpoint)));
        discarded_.push_back(*it);
        pending_.erase(it);
        return done(0, 0);
    }
    default:
        log_.push_back(fmt("UNKNOWN %#lx", request));
        return done(-1, ENOTTY);
    }
}

void EmulatedDevice::submit(UMockdevIoctlClient* client, UMockdevIoctlData* arg, uint64_t now) {
    UMockdevIoctlData* d = resolve(arg, 0, sizeof(usbdevfs_urb));
    usbdevfs_urb* u = urb_of(d);
    const int length = u->buffer_length;
    if (length < 0 || length > (1 << 24)) {
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return;
    }
    // The buffer: resolved (copied from the client) so that it can be read and, for IN, filled.
    if (length > 0) {
        UMockdevIoctlData* b = resolve(d, offsetof(usbdevfs_urb, buffer), size_t(length));
        if (b) umockdev_ioctl_data_unref(b);
    }
    u = urb_of(d);
    auto* buffer = static_cast<uint8_t*>(u->buffer);
    const bool in = (u->endpoint & 0x80) != 0;
    if (u->type == USBDEVFS_URB_TYPE_CONTROL) {
        if (length < 8) {
            umockdev_ioctl_data_unref(d);
            umockdev_ioctl_client_complete(client, -1, EINVAL);
            return;
        }
        Setup s{buffer[0], buffer[1], uint16_t(buffer[2] | buffer[3] << 8),
                uint16_t(buffer[4] | buffer[5] << 8), uint16_t(buffer[6] | buffer[7] << 8)};
        log_.push_back(
            fmt("CONTROL %02x %02x %04x %04x %u", s.request_type, s.request, s.value, s.index, s.length));
        const size_t data = std::min<size_t>(s.length, size_t(length) - 8);
        const bool ok =
            !(s.request_type & 0x80) && gadget_->control(s, std::span<const uint8_t>(buffer + 8, data), now);
        complete(d, ok ? 0 : -EPIPE, ok ? data : 0);
    } else if (u->type == USBDEVFS_URB_TYPE_BULK) {
        log_.push_back(fmt("SUBMIT bulk 0x%02x %d", unsigned(u->endpoint), length));
        if (in) {
            pending_.push_back(d);
            pump(now);
        } else {
            const bool ok =
                gadget_->bulk_out(u->endpoint, std::span<const uint8_t>(buffer, size_t(length)), now);
            complete(d, ok ? 0 : -EPIPE, ok ? size_t(length) : 0);
        }
    } else {
        log_.push_back(fmt("SUBMIT type %u refused", unsigned(u->type)));
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return;
    }
    umockdev_ioctl_client_complete(client, 0, 0);
}

void EmulatedDevice::pump(uint64_t now) {
    // In order, like a device's endpoint queue: the first pending URB must be filled first.
    while (!pending_.empty() && !unplugged_) {
        UMockdevIoctlData* d = pending_.front();
        usbdevfs_urb* u = urb_of(d);
        InResult r = gadget_->bulk_in(u->endpoint, size_t(u->buffer_length), now);
        if (r.kind == InResult::none) return;
        pending_.erase(pending_.begin());
        if (r.kind == InResult::unplug) {
            unplugged_ = true;
            log_.push_back("UNPLUG");
            complete(d, -ENODEV, 0);
            fail_all_pending(-ENODEV);
            return;
        }
        if (r.kind == InResult::stall) {
            log_.push_back(fmt("STALL 0x%02x", unsigned(u->endpoint)));
            complete(d, -EPIPE, 0);
            continue;
        }
        const size_t n = std::min(r.bytes.size(), size_t(u->buffer_length));
        std::memcpy(u->buffer, r.bytes.data(), n);
        complete(d, 0, n);
    }
}

void EmulatedDevice::reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg, uint64_t now) {
    pump(now);
    UMockdevIoctlData* d = nullptr;
    if (!discarded_.empty()) {
        d = discarded_.front();
        discarded_.erase(discarded_.begin());
        urb_of(d)->status = -ENOENT;
        urb_of(d)->actual_length = 0;
    } else if (!done_.empty()) {
        d = done_.front();
        done_.erase(done_.begin());
    }
    if (!d) {
        umockdev_ioctl_client_complete(client, -1, unplugged_ ? ENODEV : EAGAIN);
        return;
    }
    UMockdevIoctlData* ptr = resolve(arg, 0, sizeof(void*));
    umockdev_ioctl_data_set_ptr(ptr, 0, d);
    umockdev_ioctl_data_unref(ptr);
    umockdev_ioctl_data_unref(d);
    umockdev_ioctl_client_complete(client, 0, 0);
}

// --- Testbed ---

Testbed::Testbed() {
    testbed_ = umockdev_testbed_new();
    if (!testbed_) throw std::runtime_error("umockdev_testbed_new failed");
}

Testbed::~Testbed() {
    g_object_unref(testbed_);
}

bool Testbed::in_mock_environment() {
    return umockdev_in_mock_environment();
}

std::string Testbed::root_dir() const {
    gchar* d = umockdev_testbed_get_root_dir(testbed_);
    std::string s = d ? d : "";
    g_free(d);
    return s;
}

std::string Testbed::add_device(uint8_t bus, uint8_t address, const UsbIdentity& id) {
    const std::string sys = fmt("/devices/pci0000:00/0000:00:14.0/usb%u/%u-%u", bus, bus, address);
    const std::string node = fmt("bus/usb/%03u/%03u", bus, address);
    std::string text = "P: " + sys + "\nN: " + node + "\n";
    text += "E: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DRIVER=usb\nE: DEVNAME=/dev/" + node + "\n";
    text += fmt("E: BUSNUM=%03u\nE: DEVNUM=%03u\nE: PRODUCT=%x/%x/100\n", bus, address, id.vid, id.pid);
    text += fmt("A: busnum=%u\\n\nA: devnum=%u\\n\nA: idVendor=%04x\\n\nA: idProduct=%04x\\n\n", bus, address,
                id.vid, id.pid);
    text += "A: bConfigurationValue=1\\n\nA: speed=12\\n\nA: product=" + id.product + "\\n\n";
    text += "H: descriptors=" + hex(id.descriptors) + "\n";
    GError* err = nullptr;
    if (!umockdev_testbed_add_from_string(testbed_, text.c_str(), &err)) {
        std::string m = err ? err->message : "unknown";
        g_clear_error(&err);
        throw std::runtime_error("umockdev_testbed_add_from_string: " + m);
    }
    return "/sys" + sys;
}

std::string Testbed::add(uint8_t bus, uint8_t address, const UsbIdentity& identity, EmulatedDevice& device) {
    // The handler first: the device must answer as soon as it appears (umockdev issue 173).
    const std::string devnode = fmt("/dev/bus/usb/%03u/%03u", bus, address);
    GError* err = nullptr;
    if (!umockdev_testbed_attach_ioctl(testbed_, devnode.c_str(), device.handler(), &err)) {
        std::string m = err ? err->message : "unknown";
        g_clear_error(&err);
        throw std::runtime_error("umockdev_testbed_attach_ioctl: " + m);
    }
    devnodes_.push_back(devnode);
    return add_device(bus, address, identity);
}

std::string Testbed::add_plain(uint8_t bus, uint8_t address, const UsbIdentity& identity) {
    return add_device(bus, address, identity);
}

void Testbed::remove(const std::string& sysfs_path) {
    umockdev_testbed_uevent(testbed_, sysfs_path.c_str(), "remove");
    umockdev_testbed_remove_device(testbed_, sysfs_path.c_str());
}

} // namespace fgsr::probe::test
