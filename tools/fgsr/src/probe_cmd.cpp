// `fgsr probe`: the command line of fgsr_probe's run (fgsr/probe/session.hpp) and the link to fgsrd
// that puts the samples on its dashboard.
#include <fgsr/cli/cli_util.hpp>
#include <fgsr/cli/probe.hpp>

#include <fgsr/client.hpp>

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>

namespace fgsr::cli {

namespace {

std::atomic<bool> g_interrupted{false};

void on_sigint(int) {
    g_interrupted.store(true);
}

constexpr const char* kFooter = R"(Protocols (docs/PROBE.md):
  osltt  OSLTT, the Open Source Latency Testing Tool (Seeed XIAO SAMD21, 2886:802f), and any
         CDC-ACM serial probe speaking its text protocol: fgsr talks to the CDC data
         interface's bulk endpoints through libusb (cdc_acm is detached while it runs and
         reattached after), 115200 8N1 with DTR; "I " -> "FW:<version>", "T " starts test
         mode, each press of the probe's button runs its click series, one
         "RES:<click delay us>,<window us>,<n>,<n ADC readings>," line per click, "X " stops.
  fgsr   fgsr's own vendor-bulk protocol, for probes anyone can build (RP2040 + TinyUSB): a
         vendor interface ff/46/01 with a bulk OUT and a bulk IN endpoint (pid.codes test id
         1209:0001 for prototypes), little-endian messages with a header {magic "FP",
         version, type, length, tag}: GET_INFO, SYNC (device timestamps mapped onto
         CLOCK_MONOTONIC by round-trip midpoints), START(count, interval_ms, threshold),
         ABORT; SAMPLE {index, click_ts, photon_ts, brightness before/after, flags}, DONE,
         ERROR {code}.
The probe is found by its USB id or interface class (--device to pick one); --wait waits for one
to be plugged in. Without access to it, install tools/probe/70-fgsr-probe.rules (udev, uaccess).
Measurement mode: --run-command starts the command once per mode with the Vulkan layer's
environment (off: FGSR_DISABLE=1; FGSR_ENABLE=1 FGSR_MODE=interpolate|extrapolate), waits
--warmup seconds, measures, stops it, and prints the distributions side by side. The command
must flash on each click: build/bin/fgsr_layer_app --frames 100000 --flash-on-click does.
Samples go to fgsrd (--socket, else the default socket) for its dashboard's click-to-photon
panel; the CSV has PresentMon's columns (MsClickToPhotonLatency) for fgsr report.)";

} // namespace

CLI::App* add_probe_command(CLI::App& app, ProbeCli& c) {
    probe::ProbeCommand& p = c.command;
    auto* cmd = app.add_subcommand(
        "probe", "Click-to-photon latency from a hardware probe over USB (OSLTT's CDC-ACM serial protocol or "
                 "fgsr's vendor-bulk protocol): per-sample latencies, p50/p90/p99, min/max, CSV");
    cmd->footer(kFooter);
    cmd->add_flag("--list", p.list, "List the connected probes (and devices named by --device) and exit");
    cmd->add_option(
        "--device", p.device,
        "The probe: VID:PID (hex, 1209:0001) or BUS/ADDRESS (decimal, as lsusb prints them, 1/5); "
        "default: the one supported probe connected");
    cmd->add_option("--protocol", p.protocol, "auto (from the USB id or interface class), osltt or fgsr")
        ->check(CLI::IsMember({"auto", "osltt", "fgsr"}))
        ->capture_default_str();
    cmd->add_option("--count,-n", p.count, "Measurements per run (per mode with --run-command)")
        ->check(CLI::Range(1, 10000))
        ->capture_default_str();
    cmd->add_option("--interval", p.interval_ms,
                    "Milliseconds between clicks (fgsr protocol; OSLTT: its own setting)")
        ->check(CLI::Range(1, 60000))
        ->capture_default_str();
    cmd->add_option(
           "--threshold", p.threshold,
           "Brightness change that counts as the photon, in sensor units (fgsr protocol; 0: the probe's "
           "default)")
        ->check(CLI::Range(0, 65535))
        ->capture_default_str();
    cmd->add_option("--timeout", p.timeout_ms,
                    "Milliseconds to wait for any reply, or for the next sample beyond its interval")
        ->check(CLI::Range(1, 600000))
        ->capture_default_str();
    cmd->add_option(
           "--start-timeout", p.start_timeout_ms,
           "OSLTT: milliseconds to wait for the first result of a series (its button is pressed by hand)")
        ->check(CLI::Range(1, 3600000))
        ->capture_default_str();
    cmd->add_option("--wait", p.wait_s, "Seconds to wait for a probe to be plugged in (hot-plug)")
        ->check(CLI::Range(0.0, 3600.0))
        ->capture_default_str();
    cmd->add_option(
        "--csv", p.csv,
        "Write every sample to this CSV file (PresentMon's columns with MsClickToPhotonLatency, then "
        "probe_* columns; fgsr report reads it)");
    cmd->add_option("--socket", c.socket,
                    "fgsrd's socket, to send the samples to its dashboard (default: $FGSR_SOCKET, else "
                    "$XDG_RUNTIME_DIR/fgsr/fgsrd.sock; no daemon: not sent, one line says so)");
    cmd->add_option(
        "--run-command", p.run_command,
        "Measurement mode: run this command (/bin/sh -c) once per mode of --modes with the layer's "
        "environment, measure each, and print the distributions side by side");
    cmd->add_option("--modes", p.modes,
                    "Modes for --run-command: off, interpolate, extrapolate (comma-separated)")
        ->capture_default_str();
    cmd->add_option("--warmup", p.warmup_s, "Seconds the command runs before each mode's measurement")
        ->check(CLI::Range(0.0, 600.0))
        ->capture_default_str();
    cmd->add_flag("--quiet", c.quiet, "No progress on stderr");
    return cmd;
}

int probe_main(ProbeCli& c) {
    c.command.progress = !c.quiet;
    std::string report;

    // fgsrd: the samples go to its dashboard when it listens; without it the run goes on.
    client::Connection daemon;
    bool sending = false;
    if (!c.command.list) {
        const fgsr_status s =
            daemon.connect(c.socket.empty() ? nullptr : c.socket.c_str(), "fgsr probe", 2000);
        sending = s == FGSR_STATUS_OK;
        if (!sending)
            std::fprintf(stderr,
                         "fgsr probe: fgsrd not reachable, %s: samples are not sent to its dashboard\n",
                         fgsr_status_string(s));
    }
    const probe::SampleSink sink = [&](probe::Mode mode, const probe::Sample& x, uint32_t pid) {
        if (!sending) return;
        fgsr_probe_sample s{};
        s.click_ns = x.click_ns;
        s.photon_ns = x.photon_ns;
        s.mode = uint32_t(mode);
        s.pid = pid;
        const fgsr_status st = daemon.report_probe_samples(&s, 1);
        if (st != FGSR_STATUS_OK) {
            std::fprintf(stderr, "fgsr probe: fgsrd refused a sample, %s: samples are no longer sent\n",
                         fgsr_status_string(st));
            sending = false;
        }
    };

    g_interrupted.store(false);
    struct sigaction sa {
    }, old_int{}, old_term{};
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    auto r = probe::run_probe_command(c.command, sink, report, &g_interrupted);
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);

    std::fputs(report.c_str(), stdout);
    std::fflush(stdout);
    if (!r) return report_error(r.error());
    return 0;
}

} // namespace fgsr::cli
