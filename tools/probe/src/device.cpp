// Probe discovery: supported ids, descriptors to protocol and endpoints, the --device selector,
// listing, waiting for a probe through libusb hot-plug, and opening one.
#include <fgsr/probe/device.hpp>

#include "transports.hpp"

#include <libusb.h>

#include <charconv>
#include <cstdio>

namespace fgsr::probe {

namespace {

// Keep in step with 70-fgsr-probe.rules.
constexpr KnownProbe kKnown[] = {
    {0x1209, 0x0001, Protocol::fgsr, "fgsr probe (pid.codes test PID)"},
    {0x2886, 0x802f, Protocol::osltt, "OSLTT (Seeed XIAO SAMD21)"},
};

const KnownProbe* find_known(uint16_t vid, uint16_t pid) {
    for (const KnownProbe& k : kKnown)
        if (k.vid == vid && k.pid == pid) return &k;
    return nullptr;
}

struct BulkPair {
    int out = -1, in = -1;
    uint16_t in_packet = 0;
};

BulkPair bulk_pair(const libusb_interface_descriptor& alt) {
    BulkPair b;
    for (uint8_t e = 0; e < alt.bNumEndpoints; ++e) {
        const libusb_endpoint_descriptor& ep = alt.endpoint[e];
        if ((ep.bmAttributes & 0x3) != LIBUSB_TRANSFER_TYPE_BULK) continue;
        if (ep.bEndpointAddress & LIBUSB_ENDPOINT_IN) {
            if (b.in < 0) b.in = ep.bEndpointAddress, b.in_packet = ep.wMaxPacketSize;
        } else if (b.out < 0) {
            b.out = ep.bEndpointAddress;
        }
    }
    return b;
}

// What the first configuration offers (altsetting 0 of each interface).
struct Interfaces {
    int vendor = -1, comm = -1, data = -1;
    BulkPair vendor_pair, data_pair;
};

Interfaces scan(const libusb_config_descriptor& cfg) {
    Interfaces f;
    for (uint8_t i = 0; i < cfg.bNumInterfaces; ++i) {
        if (cfg.interface[i].num_altsetting < 1) continue;
        const libusb_interface_descriptor& a = cfg.interface[i].altsetting[0];
        if (a.bInterfaceClass == kFgsrInterfaceClass && a.bInterfaceSubClass == kFgsrInterfaceSubclass &&
            a.bInterfaceProtocol == kFgsrInterfaceProtocol && f.vendor < 0) {
            f.vendor = a.bInterfaceNumber;
            f.vendor_pair = bulk_pair(a);
        } else if (a.bInterfaceClass == LIBUSB_CLASS_COMM && a.bInterfaceSubClass == 0x02 && f.comm < 0) {
            f.comm = a.bInterfaceNumber;
        } else if (a.bInterfaceClass == LIBUSB_CLASS_DATA && f.data < 0) {
            f.data = a.bInterfaceNumber;
            f.data_pair = bulk_pair(a);
        }
    }
    return f;
}

std::string hex4(uint16_t v) {
    char b[8];
    std::snprintf(b, sizeof b, "%04x", unsigned(v));
    return b;
}

template <class T> bool parse_uint(std::string_view s, int base, T& out) {
    if (s.empty()) return false;
    unsigned long v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (ec != std::errc() || p != s.data() + s.size() || v > std::numeric_limits<T>::max()) return false;
    out = T(v);
    return true;
}

bool selected(const DeviceSelector& s, const ProbeDevice& d) {
    if (s.vid && (*s.vid != d.vid || *s.pid != d.pid)) return false;
    if (s.bus && (*s.bus != d.bus || *s.address != d.address)) return false;
    return true;
}

int LIBUSB_CALL on_hotplug(libusb_context*, libusb_device*, libusb_hotplug_event, void* arrived) {
    *static_cast<bool*>(arrived) = true;
    return 0; // stay registered
}

std::string list_text(const std::vector<ProbeDevice>& v) {
    std::string s;
    for (const ProbeDevice& d : v) s += (s.empty() ? "" : "; ") + d.label + " " + protocol_name(d.protocol);
    return s;
}

} // namespace

const char* protocol_name(Protocol p) {
    return p == Protocol::osltt ? "osltt" : "fgsr";
}

std::span<const KnownProbe> known_probes() {
    return kKnown;
}

Result<DeviceSelector> parse_device_selector(std::string_view text) {
    DeviceSelector s;
    if (text.empty()) return s;
    if (size_t c = text.find(':'); c != std::string_view::npos) {
        uint16_t vid = 0, pid = 0;
        if (!parse_uint(text.substr(0, c), 16, vid) || !parse_uint(text.substr(c + 1), 16, pid))
            return make_error(Errc::invalid_argument, "--device '" + std::string(text) +
                                                          "': VID:PID wants two hex numbers up to ffff");
        s.vid = vid;
        s.pid = pid;
        return s;
    }
    if (size_t c = text.find('/'); c != std::string_view::npos) {
        uint8_t bus = 0, address = 0;
        if (!parse_uint(text.substr(0, c), 10, bus) || !parse_uint(text.substr(c + 1), 10, address) ||
            address == 0)
            return make_error(Errc::invalid_argument, "--device '" + std::string(text) +
                                                          "': BUS/ADDRESS wants decimal numbers (bus 0-255, "
                                                          "address 1-255), as lsusb prints them");
        s.bus = bus;
        s.address = address;
        return s;
    }
    return make_error(Errc::invalid_argument, "--device '" + std::string(text) +
                                                  "': expected VID:PID (1209:0001) or BUS/ADDRESS (1/5)");
}

Result<std::optional<Protocol>> parse_protocol(std::string_view text) {
    if (text.empty() || text == "auto") return std::optional<Protocol>{};
    if (text == "osltt") return std::optional<Protocol>{Protocol::osltt};
    if (text == "fgsr") return std::optional<Protocol>{Protocol::fgsr};
    return make_error(Errc::invalid_argument,
                      "--protocol '" + std::string(text) + "': expected auto, osltt or fgsr");
}

ProbeDevice describe_device(libusb_device* dev, std::optional<Protocol> forced) {
    ProbeDevice p;
    libusb_device_descriptor dd{};
    libusb_get_device_descriptor(dev, &dd);
    p.vid = dd.idVendor;
    p.pid = dd.idProduct;
    p.bus = libusb_get_bus_number(dev);
    p.address = libusb_get_device_address(dev);
    p.label = device_label(dev);
    const KnownProbe* known = find_known(p.vid, p.pid);

    libusb_config_descriptor* cfg = nullptr;
    int r = libusb_get_active_config_descriptor(dev, &cfg);
    if (r != 0) r = libusb_get_config_descriptor(dev, 0, &cfg);
    if (r != 0 || !cfg) {
        p.name = known ? known->name : "USB device";
        p.problem = "cannot read its configuration descriptor: " + usb_status_text(r);
        return p;
    }
    const Interfaces f = scan(*cfg);
    libusb_free_config_descriptor(cfg);

    if (forced)
        p.protocol = *forced;
    else if (known)
        p.protocol = known->protocol;
    else
        p.protocol = f.vendor >= 0 ? Protocol::fgsr : Protocol::osltt;
    p.name = known ? known->name : p.protocol == Protocol::fgsr ? "fgsr-class device" : "CDC-ACM device";

    if (p.protocol == Protocol::fgsr) {
        if (f.vendor < 0) {
            p.problem = "no interface of class ff/46/01 (fgsr's probe protocol; docs/PROBE.md)";
            if (known)
                p.problem += ": 1209:0001 is pid.codes' shared test PID, this device uses it otherwise";
        } else if (f.vendor_pair.in < 0 || f.vendor_pair.out < 0) {
            p.problem = "interface " + std::to_string(f.vendor) + " lacks a bulk IN and a bulk OUT endpoint";
        } else {
            p.data_interface = uint8_t(f.vendor);
            p.ep_out = uint8_t(f.vendor_pair.out);
            p.ep_in = uint8_t(f.vendor_pair.in);
            p.in_packet_size = f.vendor_pair.in_packet;
        }
    } else {
        if (f.data < 0) {
            p.problem = "no CDC data interface (class 0a): not a CDC-ACM serial device";
        } else if (f.data_pair.in < 0 || f.data_pair.out < 0) {
            p.problem =
                "CDC data interface " + std::to_string(f.data) + " lacks a bulk IN and a bulk OUT endpoint";
        } else {
            p.comm_interface = f.comm;
            p.data_interface = uint8_t(f.data);
            p.ep_out = uint8_t(f.data_pair.out);
            p.ep_in = uint8_t(f.data_pair.in);
            p.in_packet_size = f.data_pair.in_packet;
        }
    }
    if (p.problem.empty() && p.in_packet_size == 0) p.problem = "bulk IN endpoint with wMaxPacketSize 0";
    return p;
}

Result<std::vector<ProbeDevice>> list_probes(UsbContext& usb, const DeviceSelector& selector) {
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(usb.get(), &list);
    if (n < 0) return make_error(Errc::io, "cannot list USB devices: " + usb_status_text(int(n)));
    std::vector<ProbeDevice> out;
    for (ssize_t i = 0; i < n; ++i) {
        libusb_device* dev = list[i];
        libusb_device_descriptor dd{};
        if (libusb_get_device_descriptor(dev, &dd) != 0) continue;
        ProbeDevice d = describe_device(dev, selector.protocol);
        const bool known = find_known(dd.idVendor, dd.idProduct) != nullptr;
        const bool fgsr_class = d.protocol == Protocol::fgsr && d.problem.empty();
        if (!selected(selector, d)) continue;
        if (!known && !fgsr_class && !selector.names_device()) continue;
        out.push_back(std::move(d));
    }
    libusb_free_device_list(list, 1);
    std::sort(out.begin(), out.end(), [](const ProbeDevice& a, const ProbeDevice& b) {
        return a.bus != b.bus ? a.bus < b.bus : a.address < b.address;
    });
    return out;
}

Result<ProbeDevice> find_probe(UsbContext& usb, const DeviceSelector& selector, int wait_ms,
                               const std::function<void()>& waiting) {
    const auto deadline = detail::Clock::now() + std::chrono::milliseconds(std::max(0, wait_ms));
    bool arrived = false, registered = false, told = false;
    libusb_hotplug_callback_handle hotplug{};
    std::optional<Result<ProbeDevice>> result;
    while (!result) {
        auto all = list_probes(usb, selector);
        if (!all) {
            result.emplace(all.error());
            break;
        }
        std::vector<ProbeDevice> usable;
        std::string unusable;
        for (ProbeDevice& d : *all) {
            if (d.problem.empty())
                usable.push_back(d);
            else
                unusable += "; " + d.label + ": " + d.problem;
        }
        if (usable.size() == 1) {
            result.emplace(usable[0]);
        } else if (usable.size() > 1) {
            result.emplace(make_error(Errc::invalid_argument,
                                      std::to_string(usable.size()) + " probes found (" + list_text(usable) +
                                          "): pick one with --device VID:PID or BUS/ADDRESS"));
        } else if (detail::ms_left(deadline) == 0) {
            std::string what = "no supported probe found";
            if (selector.vid) what += " with id " + hex4(*selector.vid) + ":" + hex4(*selector.pid);
            if (selector.bus)
                what += " at bus " + std::to_string(*selector.bus) + " address " +
                        std::to_string(*selector.address);
            if (!unusable.empty()) what += " (unusable" + unusable + ")";
            what += wait_ms > 0 ? " within " + std::to_string(wait_ms) + " ms" : "";
            what += "; supported: fgsr's vendor protocol (class ff/46/01, 1209:0001) and OSLTT (2886:802f, "
                    "CDC-ACM); plug one in (--wait SECONDS waits for it) or name another with --device";
            result.emplace(make_error(Errc::no_device, what));
        } else {
            if (!told && waiting) waiting();
            told = true;
            if (!registered && libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) {
                const int r = libusb_hotplug_register_callback(
                    usb.get(), LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED, LIBUSB_HOTPLUG_ENUMERATE,
                    LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, on_hotplug,
                    &arrived, &hotplug);
                registered = r == 0;
            }
            // Hot-plug wakes the wait at once; without it (or to catch a rescan) look every 250 ms.
            arrived = false;
            const auto slice_end = detail::Clock::now() + std::chrono::milliseconds(250);
            while (!arrived && detail::ms_left(deadline) > 0 && detail::Clock::now() < slice_end)
                usb.handle_events(std::min(50, detail::ms_left(deadline)));
        }
    }
    if (registered) libusb_hotplug_deregister_callback(usb.get(), hotplug);
    return std::move(*result);
}

Result<std::unique_ptr<Probe>> open_probe(UsbContext& usb, const ProbeDevice& device,
                                          const OpenOptions& options) {
    if (!device.problem.empty())
        return make_error(Errc::unsupported,
                          "the device at " + device.label + " cannot be used: " + device.problem);
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(usb.get(), &list);
    if (n < 0) return make_error(Errc::io, "cannot list USB devices: " + usb_status_text(int(n)));
    libusb_device* match = nullptr;
    for (ssize_t i = 0; i < n && !match; ++i)
        if (libusb_get_bus_number(list[i]) == device.bus &&
            libusb_get_device_address(list[i]) == device.address)
            match = list[i];
    Result<UsbDevice> dev =
        match ? UsbDevice::open(match)
              : Result<UsbDevice>(
                    make_error(Errc::no_device, "the probe at " + device.label + " is gone (unplugged)"));
    libusb_free_device_list(list, 1);
    if (!dev) return dev.error();
    if (device.protocol == Protocol::osltt) return detail::open_osltt(std::move(*dev), device, options);
    return detail::open_vendor(std::move(*dev), device, options);
}

namespace detail {

void print_progress(const RunOptions& o, const Sample& s) {
    if (!o.progress) return;
    std::fprintf(stderr, "%ssample %u/%u: %.3f ms\n", o.progress_prefix.c_str(), s.index + 1, o.count,
                 s.latency_ms);
}

} // namespace detail

} // namespace fgsr::probe
