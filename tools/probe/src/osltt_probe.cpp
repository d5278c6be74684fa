// The OSLTT transport: a CDC-ACM serial probe driven through libusb on its data interface's bulk
// endpoints (cdc_acm detached while it runs, reattached after), speaking the text protocol of
// fgsr/probe/osltt.hpp. Commands are two bytes ("I ", "X ", "T "): the firmware reads its input two
// bytes at a time, so single letters sent back to back would merge (docs/PROBE.md).
#include "transports.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/probe/osltt.hpp>

#include <cmath>
#include <cstdio>
#include <optional>

namespace fgsr::probe::detail {

namespace {

constexpr uint8_t kCdcRequestOut = 0x21; // class request to an interface, host to device
constexpr uint8_t kSetLineCoding = 0x20, kSetControlLineState = 0x22;
constexpr uint16_t kDtrRts = 0x3;
constexpr size_t kReadChunk = 4096; // a multiple of any bulk wMaxPacketSize

std::string shown(const std::string& s) {
    return s.size() <= 60 ? s : s.substr(0, 60) + "...";
}

class OslttProbe final : public Probe {
  public:
    OslttProbe(UsbDevice dev, const ProbeDevice& device, const OpenOptions& options)
        : dev_(std::move(dev)), device_(device), options_(options), buffer_(kReadChunk) {
        info_.name = "OSLTT";
        info_.protocol = Protocol::osltt;
        info_.usb = device.label;
    }

    Result<void> setup() {
        if (device_.comm_interface >= 0) FGSR_TRY(dev_.claim(uint8_t(device_.comm_interface)));
        if (int(device_.data_interface) != device_.comm_interface)
            FGSR_TRY(dev_.claim(device_.data_interface));
        info_.detached_interfaces = dev_.detached();
        if (device_.comm_interface >= 0) {
            // 115200 baud, 1 stop bit, no parity, 8 data bits; then DTR (the firmware waits for it).
            const uint8_t coding[7] = {0x00, 0xc2, 0x01, 0x00, 0, 0, 8};
            UsbIo io = dev_.control_out(kCdcRequestOut, kSetLineCoding, 0, uint16_t(device_.comm_interface),
                                        coding, options_.timeout_ms);
            if (!io.ok() && io.failure() != UsbFailure::stall)
                return usb_io_error(io, "OSLTT: setting the line coding", options_.timeout_ms);
            io = dev_.control_out(kCdcRequestOut, kSetControlLineState, kDtrRts,
                                  uint16_t(device_.comm_interface), {}, options_.timeout_ms);
            if (!io.ok()) return usb_io_error(io, "OSLTT: raising DTR", options_.timeout_ms);
        }
        // Leave whatever mode a previous session left it in, then identify.
        FGSR_TRY(send("X ", "OSLTT handshake"));
        FGSR_TRY(send("I ", "OSLTT handshake"));
        const auto deadline = Clock::now() + std::chrono::milliseconds(options_.timeout_ms);
        size_t other = 0;
        std::string last;
        while (true) {
            auto line = read_line(deadline, nullptr, "OSLTT handshake");
            if (!line) return line.error();
            if (!*line) {
                std::string m = "OSLTT handshake: no 'FW:' reply to 'I' within " +
                                std::to_string(options_.timeout_ms) + " ms";
                m += other ? " (" + std::to_string(other) + " other lines, the last '" + shown(last) + "')"
                           : " (the probe sent nothing: is it an OSLTT, and is its firmware running?)";
                return make_error(Errc::io, m);
            }
            if (auto fw = parse_osltt_firmware(**line)) {
                info_.firmware = *fw;
                break;
            }
            ++other;
            last = **line;
        }
        // The older firmware asks for settings after "FW:"; "X " ends that dialogue.
        FGSR_TRY(send("X ", "OSLTT handshake"));
        return {};
    }

    const ProbeInfo& info() const override { return info_; }

    Result<RunResult> run(const RunOptions& o) override {
        if (o.count == 0 || o.count > 10000)
            return make_error(Errc::invalid_argument, "count " + std::to_string(o.count) + ": 1 to 10000");
        RunResult out;
        auto r = measure(o, out);
        // Leave test mode whatever happened (best effort: the probe may be gone).
        if (stalled_) (void)dev_.clear_halt(device_.ep_in);
        (void)send("X ", "OSLTT: leaving test mode");
        if (!r) return r.error();
        return out;
    }

  private:
    Result<void> measure(const RunOptions& o, RunResult& out) {
        FGSR_TRY(send("T ", "OSLTT: entering test mode"));
        if (o.progress)
            std::fprintf(stderr,
                         "%sOSLTT: press the probe's button to start its click series (%u results wanted)\n",
                         o.progress_prefix.c_str(), o.count);
        const std::string what = "OSLTT measurement";
        size_t unknown = 0;
        bool first = true;
        while (out.samples.size() < o.count) {
            const int wait_ms = first ? std::max(o.timeout_ms, o.start_timeout_ms) : o.timeout_ms;
            const auto deadline = Clock::now() + std::chrono::milliseconds(wait_ms);
            auto line = read_line(deadline, &o,
                                  what + ", waiting for result " + std::to_string(out.samples.size() + 1) +
                                      " of " + std::to_string(o.count));
            if (!line) return line.error();
            if (!*line)
                return make_error(Errc::io, what + ": no result within " + std::to_string(wait_ms) +
                                                " ms after " + std::to_string(out.samples.size()) + " of " +
                                                std::to_string(o.count) +
                                                (first ? " (was the probe's button pressed?)" : ""));
            const std::string& l = **line;
            if (l.rfind("RES:", 0) == 0) {
                const uint64_t arrived_ns = fgsr::monotonic_ns();
                auto res = parse_osltt_result(l);
                if (!res) return make_error(Errc::io, what + ": " + res.error().message);
                first = false;
                if (res->trigger_index == 0) {
                    ++out.missed;
                    out.notes.push_back("click " + std::to_string(out.samples.size() + out.missed) +
                                        ": no brightness change within the " +
                                        std::to_string(res->window_us) + " us window");
                    if (out.missed > std::max<uint32_t>(5, o.count))
                        return make_error(
                            Errc::io, what + ": the probe saw no change after " + std::to_string(out.missed) +
                                          " clicks: is the sensor on the area that flashes, and "
                                          "does the application flash on each click?");
                    continue;
                }
                Sample s;
                s.index = uint32_t(out.samples.size());
                s.latency_ms = res->latency_ms;
                const uint64_t back_ns = (uint64_t(res->click_delay_us) + res->window_us) * 1000;
                s.click_ns = arrived_ns > back_ns ? arrived_ns - back_ns : 0;
                s.photon_ns = s.click_ns + uint64_t(std::llround(res->latency_ms * 1e6));
                s.brightness_before = res->baseline;
                s.brightness_after = res->level_after;
                out.samples.push_back(s);
                print_progress(o, s);
                if (o.on_sample) o.on_sample(s);
            } else if (l == "AUTO FINISHED" || l == "SINGLE FIRE") {
                if (o.progress)
                    std::fprintf(stderr,
                                 "%sOSLTT: series finished with %zu of %u results: press the button again\n",
                                 o.progress_prefix.c_str(), out.samples.size(), o.count);
                first = true;
            } else if (l.rfind("RESULT:", 0) != 0) {
                ++unknown; // the firmware's chatter: tolerated, counted
            }
        }
        if (unknown) out.notes.push_back(std::to_string(unknown) + " unknown lines from the probe ignored");
        return {};
    }

    Result<void> send(std::string_view text, const std::string& what) {
        const std::span<const uint8_t> bytes(reinterpret_cast<const uint8_t*>(text.data()), text.size());
        const UsbIo io = dev_.bulk_write(device_.ep_out, bytes, options_.timeout_ms);
        if (!io.ok())
            return usb_io_error(io, what + ": sending '" + std::string(text.substr(0, 1)) + "'",
                                options_.timeout_ms);
        if (io.bytes != bytes.size())
            return make_error(Errc::io, what + ": the probe took " + std::to_string(io.bytes) + " of " +
                                            std::to_string(bytes.size()) + " bytes");
        return {};
    }

    // The next line, or nullopt when the deadline passes first. Reads in short slices so that a
    // cancel request is seen within 100 ms.
    Result<std::optional<std::string>> read_line(Clock::time_point deadline, const RunOptions* o,
                                                 const std::string& what) {
        while (true) {
            if (auto l = reader_.next_line()) return std::optional<std::string>(std::move(*l));
            if (o && cancelled(*o)) return make_error(Errc::io, what + ": interrupted");
            const int left = ms_left(deadline);
            if (left == 0) return std::optional<std::string>{};
            const int slice = std::min(left, 100);
            const UsbIo io = dev_.bulk_read(device_.ep_in, buffer_, slice);
            if (io.bytes)
                if (auto f = reader_.feed(std::span<const uint8_t>(buffer_.data(), io.bytes)); !f)
                    return make_error(Errc::io, what + ": " + f.error().message);
            if (!io.ok() && io.failure() != UsbFailure::timeout) {
                stalled_ = io.failure() == UsbFailure::stall;
                return usb_io_error(io, what, slice);
            }
        }
    }

    UsbDevice dev_;
    ProbeDevice device_;
    OpenOptions options_;
    ProbeInfo info_;
    LineReader reader_;
    std::vector<uint8_t> buffer_;
    bool stalled_ = false;
};

} // namespace

Result<std::unique_ptr<Probe>> open_osltt(UsbDevice dev, const ProbeDevice& device,
                                          const OpenOptions& options) {
    auto p = std::make_unique<OslttProbe>(std::move(dev), device, options);
    FGSR_TRY(p->setup());
    return std::unique_ptr<Probe>(std::move(p));
}

} // namespace fgsr::probe::detail
