// `fgsr probe` behind its command line: list, find (hot-plug wait), open, measure, report, CSV.
#include <fgsr/probe/session.hpp>

#include <fgsr/probe/device.hpp>
#include <fgsr/probe/modes.hpp>

#include <cstdio>

namespace fgsr::probe {

namespace {

std::string line(const char* format, auto... args) {
    char b[256];
    std::snprintf(b, sizeof b, format, args...);
    return b;
}

std::string describe(const ProbeInfo& i) {
    std::string s = "probe: " + i.name + " (" + protocol_name(i.protocol) + " protocol), firmware " +
                    i.firmware + ", at " + i.usb;
    if (i.clock_hz > 0) s += line(", clock %.0f Hz", i.clock_hz);
    if (!i.detached_interfaces.empty()) {
        s += "; kernel driver detached from interface";
        s += i.detached_interfaces.size() > 1 ? "s" : "";
        for (size_t k = 0; k < i.detached_interfaces.size(); ++k)
            s += (k ? ", " : " ") + std::to_string(i.detached_interfaces[k]);
        s += " (reattached when done)";
    }
    return s + "\n";
}

std::string samples_text(const std::vector<Sample>& samples) {
    std::string s = "sample  latency_ms  brightness\n";
    for (const Sample& x : samples)
        s += line("%6u  %10.3f  %u -> %u\n", x.index + 1, x.latency_ms, x.brightness_before,
                  x.brightness_after);
    return s;
}

std::string notes_text(const RunResult& r) {
    std::string s;
    if (r.missed) s += line("missed: %u clicks without a brightness change\n", r.missed);
    if (r.clock_error_ms > 0)
        s += line("clock mapping: within %.3f ms of CLOCK_MONOTONIC\n", r.clock_error_ms);
    for (const std::string& n : r.notes) s += "note: " + n + "\n";
    return s;
}

Result<void> list_command(UsbContext& usb, const DeviceSelector& selector, std::string& report) {
    auto list = list_probes(usb, selector);
    if (!list) return list.error();
    if (list->empty()) {
        report +=
            "no probe connected (supported: fgsr's vendor protocol, class ff/46/01 or 1209:0001; OSLTT, "
            "2886:802f)\n";
        return {};
    }
    for (const ProbeDevice& d : *list) {
        report += d.label + "  " + d.name + "  protocol " + protocol_name(d.protocol);
        if (d.problem.empty())
            report += line("  interface %u, endpoints out 0x%02x in 0x%02x", unsigned(d.data_interface),
                           unsigned(d.ep_out), unsigned(d.ep_in));
        else
            report += "  unusable: " + d.problem;
        report += "\n";
    }
    return {};
}

} // namespace

Result<void> run_probe_command(const ProbeCommand& c, const SampleSink& sink, std::string& report,
                               const std::atomic<bool>* cancel) {
    auto selector = parse_device_selector(c.device);
    if (!selector) return selector.error();
    auto protocol = parse_protocol(c.protocol);
    if (!protocol) return protocol.error();
    selector->protocol = *protocol;
    std::vector<Mode> modes;
    if (!c.run_command.empty()) {
        auto m = parse_modes(c.modes);
        if (!m) return m.error();
        modes = std::move(*m);
    }
    if (!(c.wait_s >= 0 && c.wait_s <= 3600))
        return make_error(Errc::invalid_argument, "--wait " + std::to_string(c.wait_s) + " s: 0 to 3600");
    if (c.timeout_ms < 1 || c.timeout_ms > 600000)
        return make_error(Errc::invalid_argument,
                          "--timeout " + std::to_string(c.timeout_ms) + " ms: 1 to 600000");

    auto usb = UsbContext::create();
    if (!usb) return usb.error();
    if (c.list) return list_command(*usb, *selector, report);

    auto device = find_probe(*usb, *selector, int(c.wait_s * 1000), [&] {
        if (c.progress)
            std::fprintf(stderr, "fgsr probe: no probe yet, waiting up to %.0f s for one\n", c.wait_s);
    });
    if (!device) return device.error();
    OpenOptions oo;
    oo.timeout_ms = c.timeout_ms;
    oo.progress = c.progress;
    auto probe = open_probe(*usb, *device, oo);
    if (!probe) return probe.error();
    report += describe((*probe)->info());

    RunOptions ro;
    ro.count = c.count;
    ro.interval_ms = c.interval_ms;
    ro.threshold = c.threshold;
    ro.timeout_ms = c.timeout_ms;
    ro.start_timeout_ms = c.start_timeout_ms;
    ro.progress = c.progress;
    ro.cancel = cancel;

    std::vector<CsvRun> csv;
    if (c.run_command.empty()) {
        ro.on_sample = [&](const Sample& s) {
            if (sink) sink(Mode::unknown, s, 0);
        };
        auto r = (*probe)->run(ro);
        if (!r) return r.error();
        report += samples_text(r->samples);
        report += summary_line(summarize(r->samples)) + "\n";
        report += notes_text(*r);
        if (!c.csv.empty()) {
            CsvRun run;
            run.samples = r->samples;
            csv.push_back(run);
            FGSR_TRY(write_csv(c.csv, csv));
            report += "samples written to " + c.csv + "\n";
        }
        return {};
    }

    MeasureOptions mo;
    mo.command = c.run_command;
    mo.modes = modes;
    mo.warmup_s = c.warmup_s;
    mo.run = ro;
    mo.on_sample = sink;
    auto runs = run_modes(**probe, mo);
    if (!runs) return runs.error();
    std::vector<ModeColumn> columns;
    std::string application = c.run_command.substr(0, c.run_command.find(' '));
    application = application.substr(application.rfind('/') + 1);
    for (const ModeRun& m : *runs) {
        report +=
            std::string(mode_name(m.mode)) + ":\n" + samples_text(m.result.samples) + notes_text(m.result);
        columns.push_back(ModeColumn{m.mode, m.summary, m.result.missed});
        CsvRun run;
        run.mode = m.mode;
        run.pid = m.pid;
        run.application = application;
        run.samples = m.result.samples;
        csv.push_back(run);
    }
    report += modes_table(columns);
    if (!c.csv.empty()) {
        FGSR_TRY(write_csv(c.csv, csv));
        report += "samples written to " + c.csv + "\n";
    }
    return {};
}

} // namespace fgsr::probe
