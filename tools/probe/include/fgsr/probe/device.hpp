// Finding a probe: the table of supported USB ids (kept in step with 70-fgsr-probe.rules), what a
// device's descriptors say about its protocol and endpoints, the --device selector, the list of
// connected probes, waiting for one to be plugged in (libusb hot-plug), and opening one as a Probe.
//
// A device is a candidate when its VID:PID is in known_probes() or when a selector names it (by
// VID:PID or bus/address: any CDC-ACM or fgsr-class device can then be used). Its protocol comes
// from its interfaces: a vendor interface of class ff/46/01 (docs/PROBE.md) is fgsr's protocol; a
// CDC data interface (class 0a) next to an ACM communication interface (02/02) is OSLTT's.
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/probe/probe.hpp>
#include <fgsr/probe/usb.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr::probe {

struct KnownProbe {
    uint16_t vid, pid;
    Protocol protocol;
    const char* name;
};
std::span<const KnownProbe> known_probes();

// fgsr's vendor interface: bInterfaceClass, bInterfaceSubClass, bInterfaceProtocol.
inline constexpr uint8_t kFgsrInterfaceClass = 0xff, kFgsrInterfaceSubclass = 0x46,
                         kFgsrInterfaceProtocol = 0x01;

struct ProbeDevice {
    uint16_t vid = 0, pid = 0;
    uint8_t bus = 0, address = 0;
    std::string label; // "bus 1 address 5 (1209:0001)"
    std::string name;  // known_probes() name, else "CDC-ACM device" / "fgsr-class device"
    Protocol protocol = Protocol::fgsr;
    int comm_interface = -1;    // OSLTT: the ACM communication interface (line coding, DTR)
    uint8_t data_interface = 0; // the interface with the bulk pair
    uint8_t ep_out = 0, ep_in = 0;
    uint16_t in_packet_size = 0; // wMaxPacketSize of ep_in
    std::string problem;         // why it cannot be used (empty: usable)
};

// --device: "VID:PID" (hex, "1209:0001") or "BUS/ADDRESS" (decimal, "1/5", "001/005"); empty: any.
struct DeviceSelector {
    std::optional<uint16_t> vid, pid;
    std::optional<uint8_t> bus, address;
    std::optional<Protocol> protocol; // --protocol; unset: from the descriptors
    bool names_device() const { return vid.has_value() || bus.has_value(); }
};
Result<DeviceSelector> parse_device_selector(std::string_view text);
Result<std::optional<Protocol>> parse_protocol(std::string_view text); // "auto" -> nullopt, "osltt", "fgsr"

// Reads dev's descriptors: protocol, interfaces and endpoints, or the problem. forced: --protocol.
ProbeDevice describe_device(libusb_device* dev, std::optional<Protocol> forced);

// Candidates among the connected devices (usable or not; problem says why not), in bus order.
Result<std::vector<ProbeDevice>> list_probes(UsbContext& usb, const DeviceSelector& selector);

// The one usable probe the selector picks. None: with wait_ms > 0, waits that long for one to be
// plugged in (hot-plug; `waiting` is called once when it starts to wait); more than one: an error
// that lists them. Errc::no_device when there is none.
Result<ProbeDevice> find_probe(UsbContext& usb, const DeviceSelector& selector, int wait_ms,
                               const std::function<void()>& waiting = {});

struct OpenOptions {
    int timeout_ms = 2000; // the handshake's wait for each reply
    bool progress = true;  // status lines on stderr (OSLTT: "press the probe's button")
};
// Opens, claims (detaching cdc_acm for a serial probe) and shakes hands (OSLTT: "I" -> "FW:";
// vendor: GET_INFO and the first clock synchronisation).
Result<std::unique_ptr<Probe>> open_probe(UsbContext& usb, const ProbeDevice& device,
                                          const OpenOptions& options);

} // namespace fgsr::probe
