// USB devices emulated at the usbdevfs level with umockdev, for fgsr_probe's tests and
// fgsr_probe_emulator. A Testbed owns a UMockdevTestbed (sysfs, udev and /dev redirected for this
// process and the children it starts with its environment); add() puts a device on the bus: its
// sysfs node (idVendor, idProduct, busnum, devnum, the binary descriptors attribute) and its
// /dev/bus/usb/BBB/DDD node, whose ioctls an EmulatedDevice answers, the way the kernel's usbfs
// would: capabilities, GETDRIVER, claiming (EBUSY while a kernel driver holds the interface), the
// USBDEVFS_DISCONNECT / CONNECT of driver detach and reattach, URB submit, reap, discard, clear halt.
// The device side is a Gadget: it answers control requests, takes bulk OUT data and produces bulk
// IN data (or a stall, or vanishes), at the time the host asks (now_ns, CLOCK_MONOTONIC).
//
// Threads: umockdev calls the handler on its own thread; EmulatedDevice serialises everything
// (gadget calls included) with one mutex, so tests read its state (log, drivers) safely.
#pragma once

#include <umockdev.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace fgsr::probe::test {

struct Setup {
    uint8_t request_type, request;
    uint16_t value, index, length;
};

// What a bulk IN transfer gets.
struct InResult {
    enum Kind { none, data, stall, unplug } kind = none; // none: nothing yet (the URB stays pending)
    std::vector<uint8_t> bytes;
};

class Gadget {
  public:
    virtual ~Gadget() = default;
    // A control transfer with an OUT (or no) data stage; false stalls it.
    virtual bool control(const Setup& setup, std::span<const uint8_t> data, uint64_t now_ns) = 0;
    // A bulk OUT transfer; false stalls it.
    virtual bool bulk_out(uint8_t endpoint, std::span<const uint8_t> data, uint64_t now_ns) = 0;
    // A bulk IN transfer of at most max_bytes, asked at now_ns.
    virtual InResult bulk_in(uint8_t endpoint, size_t max_bytes, uint64_t now_ns) = 0;
};

// Kernel drivers bound to the interfaces at the start: interface -> driver name. Interfaces in
// one group (cdc_acm's communication and data interfaces) are unbound and bound together, as the
// real driver does.
struct DriverBinding {
    std::map<uint8_t, std::string> drivers;
    std::vector<std::vector<uint8_t>> groups;
};

class EmulatedDevice {
  public:
    EmulatedDevice(std::unique_ptr<Gadget> gadget, DriverBinding binding);
    ~EmulatedDevice();
    EmulatedDevice(const EmulatedDevice&) = delete;
    EmulatedDevice& operator=(const EmulatedDevice&) = delete;

    UMockdevIoctlBase* handler() const { return handler_; }
    // Every usbfs request handled, in order: "GETDRIVER 0 cdc_acm", "DISCONNECT 0", "CLAIM 1",
    // "SUBMIT bulk 0x81 4096", ... (not REAP, which libusb polls for).
    std::vector<std::string> log() const;
    // The driver bound to an interface now ("" none).
    std::string driver(uint8_t interface) const;
    size_t ioctl_count() const;
    // Unplugs the device now: pending transfers fail with -ENODEV, new requests with ENODEV.
    void unplug();
    bool unplugged() const;
    template <class G> G& gadget() { return static_cast<G&>(*gadget_); }
    std::mutex& mutex() const { return mutex_; }

  private:
    struct Urb {
        UMockdevIoctlData* data; // the client's usbdevfs_urb (resolved), with its buffer
    };
    static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self);
    void handle(UMockdevIoctlClient* client);
    void submit(UMockdevIoctlClient* client, UMockdevIoctlData* arg, uint64_t now);
    void reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg, uint64_t now);
    void pump(uint64_t now);
    void complete(UMockdevIoctlData* urb, int status, size_t actual);
    void fail_all_pending(int status);
    void bind_group(uint8_t interface, bool bind);

    std::unique_ptr<Gadget> gadget_;
    DriverBinding binding_;
    std::map<uint8_t, std::string> bound_;
    std::vector<uint8_t> claimed_;
    UMockdevIoctlBase* handler_ = nullptr;
    mutable std::mutex mutex_;
    std::vector<UMockdevIoctlData*> pending_, done_, discarded_;
    std::vector<std::string> log_;
    size_t ioctls_ = 0;
    bool unplugged_ = false;
};

// The bytes of a device: descriptors as libusb reads them from sysfs.
struct UsbIdentity {
    uint16_t vid, pid;
    std::vector<uint8_t> descriptors; // device descriptor, then the configuration and everything in it
    std::string product;              // sysfs "product"
};

class Testbed {
  public:
    Testbed();
    ~Testbed();
    Testbed(const Testbed&) = delete;
    Testbed& operator=(const Testbed&) = delete;

    // Whether this process's file accesses go to the testbed (the preload library is in effect).
    static bool in_mock_environment();
    // Adds a device at bus/address with `device` answering its node; returns its sysfs path.
    std::string add(uint8_t bus, uint8_t address, const UsbIdentity& identity, EmulatedDevice& device);
    // A device with no ioctl emulation (enumeration only).
    std::string add_plain(uint8_t bus, uint8_t address, const UsbIdentity& identity);
    // Removes it from sysfs with a "remove" uevent (libusb's hot-plug sees it leave).
    void remove(const std::string& sysfs_path);
    std::string root_dir() const;

  private:
    std::string add_device(uint8_t bus, uint8_t address, const UsbIdentity& identity);
    UMockdevTestbed* testbed_ = nullptr;
    std::vector<std::string> devnodes_;
};

} // namespace fgsr::probe::test
