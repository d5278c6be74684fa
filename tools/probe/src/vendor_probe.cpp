// The fgsr vendor-bulk transport: GET_INFO, ABORT and SYNC at open, then per run SYNCs, START, the
// SAMPLE stream and DONE, SYNCs again, and the device-clock mapping (docs/PROBE.md). Every reply is
// decoded from a copy and validated (fgsr/probe/vendor_protocol.hpp); every wait is bounded.
#include "transports.hpp"

#include <fgsr/core/clock.hpp>
#include <fgsr/probe/clock_map.hpp>
#include <fgsr/probe/vendor_protocol.hpp>

#include <array>
#include <cmath>
#include <cstdio>

namespace fgsr::probe::detail {

namespace {

constexpr int kSyncExchanges = 8;
constexpr int kMaxStaleReplies = 64; // replies to earlier commands skipped before giving up
constexpr size_t kReadBytes = 512;   // a multiple of any bulk wMaxPacketSize

const char* type_name(VendorType t) {
    switch (t) {
    case VendorType::ack:
        return "ACK";
    case VendorType::info:
        return "INFO";
    case VendorType::sync_reply:
        return "SYNC";
    case VendorType::sample:
        return "SAMPLE";
    case VendorType::done:
        return "DONE";
    case VendorType::error:
        return "ERROR";
    default:
        return "command";
    }
}

class VendorProbe final : public Probe {
  public:
    VendorProbe(UsbDevice dev, const ProbeDevice& device, const OpenOptions& options)
        : dev_(std::move(dev)), device_(device), options_(options) {
        info_.protocol = Protocol::fgsr;
        info_.usb = device.label;
    }

    Result<void> setup() {
        FGSR_TRY(dev_.claim(device_.data_interface));
        info_.detached_interfaces = dev_.detached();
        drain(100); // whatever an earlier session left in the probe's queue
        const std::string what = "fgsr probe handshake";
        auto info = exchange(encode_command(VendorType::get_info, next_tag()), VendorType::info,
                             what + ": GET_INFO", options_.timeout_ms);
        if (!info) return info.error();
        info_.name = info->info.name.empty() ? "fgsr probe" : info->info.name;
        info_.firmware = vendor_firmware_text(info->info.firmware);
        info_.clock_hz = info->info.clock_hz;
        max_count_ = info->info.max_count;
        auto ack = exchange(encode_command(VendorType::abort, next_tag()), VendorType::ack, what + ": ABORT",
                            options_.timeout_ms);
        if (!ack) return ack.error();
        auto first = sync(what);
        if (!first) return first.error();
        return {};
    }

    const ProbeInfo& info() const override { return info_; }

    Result<RunResult> run(const RunOptions& o) override {
        if (o.count == 0 || o.count > std::min(kVendorMaxCount, max_count_))
            return make_error(Errc::invalid_argument,
                              "count " + std::to_string(o.count) + ": 1 to " +
                                  std::to_string(std::min(kVendorMaxCount, max_count_)) +
                                  " (this probe's max_count)");
        if (o.interval_ms < 1 || o.interval_ms > 60000)
            return make_error(Errc::invalid_argument,
                              "interval " + std::to_string(o.interval_ms) + " ms: 1 to 60000");
        if (o.threshold > 0xffff)
            return make_error(Errc::invalid_argument,
                              "threshold " + std::to_string(o.threshold) + ": 0 to 65535");
        RunResult out;
        auto r = measure(o, out);
        if (!r) {
            if (r.error().code != Errc::no_device) {
                if (stalled_) (void)dev_.clear_halt(device_.ep_in);
                (void)send(encode_command(VendorType::abort, next_tag()), "ABORT", 200);
            }
            return r.error();
        }
        return out;
    }

  private:
    struct Raw {
        VendorSample s;
        uint64_t arrived_ns;
    };

    Result<void> measure(const RunOptions& o, RunResult& out) {
        const std::string what = "fgsr probe run";
        auto before = sync(what);
        if (!before) return before.error();
        auto live_map = ClockMap::fit(*before, info_.clock_hz);
        if (!live_map) return make_error(Errc::io, what + ": " + live_map.error().message);

        const uint16_t tag = next_tag();
        auto ack = exchange(encode_start(tag, o.count, o.interval_ms, uint16_t(o.threshold)), VendorType::ack,
                            what + ": START", options_.timeout_ms);
        if (!ack) return ack.error();
        if (ack->acked != uint8_t(VendorType::start))
            return make_error(Errc::io, what + ": START answered with an ACK of another command");

        std::vector<VendorSample> raw;
        uint32_t seen = 0; // samples and misses
        bool done = false;
        while (!done) {
            const int wait_ms = int(std::min<uint32_t>(o.interval_ms, 600000)) + o.timeout_ms;
            const std::string step = seen < o.count ? "waiting for sample " + std::to_string(seen + 1) +
                                                          " of " + std::to_string(o.count)
                                                    : "waiting for DONE";
            auto m = read_reply(tag, what + ": " + step, wait_ms, &o);
            if (!m) return m.error();
            if (m->type == VendorType::sample) {
                const VendorSample& s = m->sample;
                if (seen >= o.count)
                    return make_error(Errc::io, what + ": SAMPLE " + std::to_string(s.index) + " after all " +
                                                    std::to_string(o.count) + " were received");
                if (s.index != seen)
                    return make_error(Errc::io, what + ": SAMPLE index " + std::to_string(s.index) +
                                                    ", expected " + std::to_string(seen) +
                                                    " (samples lost or repeated)");
                ++seen;
                if (s.flags & kVendorFlagNoChange) {
                    ++out.missed;
                    out.notes.push_back("click " + std::to_string(s.index + 1) + ": the probe saw no change");
                    continue;
                }
                raw.push_back(s);
                Sample live = to_sample(s, *live_map, uint32_t(raw.size() - 1));
                print_progress(o, live);
                if (o.on_sample) o.on_sample(live);
            } else if (m->type == VendorType::done) {
                if (m->done_count != o.count || seen != o.count)
                    return make_error(Errc::io, what + ": DONE reports " + std::to_string(m->done_count) +
                                                    " samples after " + std::to_string(seen) + " of " +
                                                    std::to_string(o.count) + " arrived");
                done = true;
            } else {
                return make_error(Errc::io, what + ": " + type_name(m->type) +
                                                " during the run (expected SAMPLE or DONE)");
            }
        }
        auto after = sync(what + " (after)");
        if (!after) return after.error();
        std::vector<SyncPoint> all = *before;
        all.insert(all.end(), after->begin(), after->end());
        auto map = ClockMap::fit(all, info_.clock_hz);
        if (!map) return make_error(Errc::io, what + ": " + map.error().message);
        for (size_t i = 0; i < raw.size(); ++i) out.samples.push_back(to_sample(raw[i], *map, uint32_t(i)));
        out.clock_error_ms = map->error_ns() / 1e6;
        return {};
    }

    Sample to_sample(const VendorSample& v, const ClockMap& map, uint32_t index) const {
        Sample s;
        s.index = index;
        s.latency_ms = map.ticks_to_ns(v.photon_ts - v.click_ts) / 1e6;
        s.click_ns = map.to_monotonic_ns(v.click_ts);
        s.photon_ns = s.click_ns + uint64_t(std::llround(s.latency_ms * 1e6));
        s.brightness_before = v.before;
        s.brightness_after = v.after;
        s.flags = (v.flags & kVendorFlagSaturated) ? kSampleSaturated : 0;
        return s;
    }

    Result<std::vector<SyncPoint>> sync(const std::string& what) {
        std::vector<SyncPoint> points;
        for (int i = 0; i < kSyncExchanges; ++i) {
            SyncPoint p;
            p.host_before_ns = fgsr::monotonic_ns();
            auto r = exchange(encode_command(VendorType::sync, next_tag()), VendorType::sync_reply,
                              what + ": SYNC", options_.timeout_ms);
            p.host_after_ns = fgsr::monotonic_ns();
            if (!r) return r.error();
            p.device_ticks = r->device_ts;
            if (!points.empty() && p.device_ticks < points.back().device_ticks)
                return make_error(Errc::io, what + ": SYNC timestamps go backwards (" +
                                                std::to_string(points.back().device_ticks) + " then " +
                                                std::to_string(p.device_ticks) + ")");
            points.push_back(p);
        }
        return points;
    }

    // Sends a command and reads its reply (of type `want`, with the command's tag).
    Result<VendorReply> exchange(const std::vector<uint8_t>& command, VendorType want,
                                 const std::string& what, int timeout_ms) {
        const uint16_t tag = uint16_t(command[6] | command[7] << 8);
        FGSR_TRY(send(command, what, timeout_ms));
        auto r = read_reply(tag, what, timeout_ms, nullptr);
        if (!r) return r.error();
        if (r->type != want)
            return make_error(Errc::io, what + ": the probe answered with " + type_name(r->type) +
                                            " (expected " + type_name(want) + ")");
        return r;
    }

    Result<void> send(const std::vector<uint8_t>& bytes, const std::string& what, int timeout_ms) {
        const UsbIo io = dev_.bulk_write(device_.ep_out, bytes, timeout_ms);
        if (!io.ok()) return usb_io_error(io, what + " (sending)", timeout_ms);
        if (io.bytes != bytes.size())
            return make_error(Errc::io, what + ": the probe took " + std::to_string(io.bytes) + " of " +
                                            std::to_string(bytes.size()) + " bytes");
        return {};
    }

    // The next reply carrying `tag` within timeout_ms; replies to earlier commands are skipped (a
    // bounded number); ERROR with the tag becomes an error.
    Result<VendorReply> read_reply(uint16_t tag, const std::string& what, int timeout_ms,
                                   const RunOptions* o) {
        const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
        int stale = 0;
        std::array<uint8_t, kReadBytes> buf{};
        while (true) {
            if (o && cancelled(*o)) return make_error(Errc::io, what + ": interrupted");
            const int left = ms_left(deadline);
            if (left == 0)
                return make_error(
                    Errc::io, what + ": no reply within " + std::to_string(timeout_ms) + " ms" +
                                  (answered_ ? "" : " (the probe sent nothing: is its firmware running?)"));
            const UsbIo io = dev_.bulk_read(device_.ep_in, buf, std::min(left, 100));
            if (io.failure() == UsbFailure::timeout && io.bytes == 0) continue;
            if (!io.ok()) {
                stalled_ = io.failure() == UsbFailure::stall;
                return usb_io_error(io, what, timeout_ms);
            }
            if (io.bytes == 0) continue; // a zero-length packet
            answered_ = true;
            auto r = decode_reply(std::span<const uint8_t>(buf.data(), io.bytes));
            if (!r) return make_error(Errc::io, what + ": " + r.error().message);
            if (r->tag != tag) {
                if (++stale > kMaxStaleReplies)
                    return make_error(Errc::io, what + ": more than " + std::to_string(kMaxStaleReplies) +
                                                    " replies to other commands (tag " +
                                                    std::to_string(r->tag) + ", expected " +
                                                    std::to_string(tag) + ")");
                continue;
            }
            if (r->type == VendorType::error)
                return make_error(Errc::io, what + ": " + vendor_error_text(r->error_code, r->error_detail));
            return r;
        }
    }

    void drain(int total_ms) {
        const auto deadline = Clock::now() + std::chrono::milliseconds(total_ms);
        std::array<uint8_t, kReadBytes> buf{};
        while (ms_left(deadline) > 0) {
            const UsbIo io = dev_.bulk_read(device_.ep_in, buf, std::min(20, ms_left(deadline)));
            if (!io.ok()) return; // a timeout: empty (other failures surface at the next exchange)
        }
    }

    uint16_t next_tag() { return ++tag_ == 0 ? ++tag_ : tag_; }

    UsbDevice dev_;
    ProbeDevice device_;
    OpenOptions options_;
    ProbeInfo info_;
    uint32_t max_count_ = 0;
    uint16_t tag_ = 0;
    bool answered_ = false, stalled_ = false;
};

} // namespace

Result<std::unique_ptr<Probe>> open_vendor(UsbDevice dev, const ProbeDevice& device,
                                           const OpenOptions& options) {
    auto p = std::make_unique<VendorProbe>(std::move(dev), device, options);
    FGSR_TRY(p->setup());
    return std::unique_ptr<Probe>(std::move(p));
}

} // namespace fgsr::probe::detail
