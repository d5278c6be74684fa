// `fgsr stress --service --soak SECONDS`: short libfgsr_client sessions back to back (connect,
// create a session, frames, destroy, disconnect) against the scenario's own fgsrd, sampling the
// daemon's fd count, mapping count and RSS; after a warm-up, least-squares slopes per minute.
// Samples go to a CSV and, when gnuplot is installed, a PNG plot next to it.
#include "service_internal.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

namespace fgsr::stress {

namespace {

using service::FgsrdProcess;

struct Sample {
    double t = 0; // seconds since the start
    uint64_t cycles = 0;
    int fds = 0, maps = 0;
    long rss_kib = 0;
};

// Least-squares slope of y over x (0 with fewer than two distinct x).
double slope(const std::vector<double>& x, const std::vector<double>& y) {
    const size_t n = x.size();
    if (n < 2) return 0;
    double mx = 0, my = 0;
    for (size_t i = 0; i < n; ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= double(n);
    my /= double(n);
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < n; ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
    }
    return sxx > 0 ? sxy / sxx : 0;
}

// The gnuplot executable on PATH, or "".
std::string find_gnuplot() {
    const char* path = std::getenv("PATH");
    std::string p = path ? path : "/usr/bin:/bin";
    size_t start = 0;
    while (start <= p.size()) {
        const size_t end = std::min(p.find(':', start), p.size());
        const std::string candidate = p.substr(start, end - start) + "/gnuplot";
        if (end > start && access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
    }
    return "";
}

// Plots the CSV to `png` with gnuplot; "" on success, else why.
std::string plot(const std::string& csv, const std::string& png) {
    const std::string gnuplot = find_gnuplot();
    if (gnuplot.empty()) return "gnuplot not found";
    const std::string script = png + ".gp";
    {
        std::ofstream f(script);
        f << "set terminal pngcairo size 1200,800 noenhanced\n"
          << "set output '" << png << "'\n"
          << "set datafile separator ','\n"
          << "set key autotitle columnhead\n"
          << "set multiplot layout 3,1 title 'fgsrd soak: " << csv << "'\n"
          << "set xlabel 'seconds'\n"
          << "set ylabel 'RSS (KiB)'\nplot '" << csv << "' using 1:5 with lines title 'RSS KiB'\n"
          << "set ylabel 'fds'\nplot '" << csv << "' using 1:3 with lines title 'fds'\n"
          << "set ylabel 'mappings'\nplot '" << csv << "' using 1:4 with lines title 'mappings'\n"
          << "unset multiplot\n";
    }
    const pid_t pid = FgsrdProcess::spawn({gnuplot, script}, png + ".log");
    int status = -1;
    if (pid > 0) waitpid(pid, &status, 0);
    if (status != 0) { // pngcairo may be missing (gnuplot-nox): the plain png terminal
        std::ifstream in(script);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        text.replace(text.find("pngcairo"), 8, "png");
        std::ofstream(script) << text;
        const pid_t p2 = FgsrdProcess::spawn({gnuplot, script}, png + ".log");
        if (p2 > 0) waitpid(p2, &status, 0);
    }
    if (status != 0) return "gnuplot failed (see " + png + ".log)";
    unlink((png + ".log").c_str());
    return "";
}

} // namespace

ScenarioResult run_service_soak(const ServiceOptions& o) {
    service::Run r(o, "soak");
    const double duration = o.soak_seconds;
    if (!r.own_daemon_possible()) {
        r.check(false, "the soak needs its own daemon (it reads /proc/<pid>)");
        r.result.pass = false;
        return r.result;
    }
    if (!r.start()) return r.result;
    FgsrdProcess& d = *r.daemon;
    const double interval = std::clamp(duration / 120.0, 1.0, 5.0);
    const double warm = std::min(std::max(0.1 * duration, 60.0), 0.5 * duration);
    constexpr uint32_t kFrames = 8, kSide = 128;
    std::vector<Sample> samples;
    uint64_t cycles = 0, failed = 0;
    std::string first_failure;
    const uint64_t t0 = raw::now_ns();
    double next_sample = 0;
    for (;;) {
        const double t = raw::ms_since(t0) / 1000.0;
        if (t >= next_sample || t >= duration) {
            usleep(50000); // the daemon drops the last cycle's connection after our close: let it
            samples.push_back({t, cycles, d.fd_count(), d.mapping_count(), d.rss_kib()});
            next_sample += interval;
            if (o.progress)
                o.progress(fmt::format("  soak: {:.0f}/{:.0f} s, {} cycles, fds {}, maps {}, RSS {} KiB", t,
                                       duration, cycles, samples.back().fds, samples.back().maps,
                                       samples.back().rss_kib));
        }
        if (t >= duration) break;
        if (!d.running()) {
            r.check(false, "fgsrd died during the soak; its log:\n" + d.stderr_text());
            break;
        }
        const std::string why = service::library_frames(d.socket_path(), kSide, kSide, kFrames);
        ++cycles;
        if (!why.empty()) {
            ++failed;
            if (first_failure.empty()) first_failure = why;
        }
    }
    std::vector<double> x, rss, fds, maps;
    for (const Sample& s : samples)
        if (s.t >= warm) {
            x.push_back(s.t / 60.0);
            rss.push_back(double(s.rss_kib));
            fds.push_back(double(s.fds));
            maps.push_back(double(s.maps));
        }
    const double rss_slope = slope(x, rss), fd_slope = slope(x, fds), map_slope = slope(x, maps);
    constexpr double kMaxRssSlope = 256, kMaxCountSlope = 0.5; // kB/min; per minute
    r.result.metrics.update({{"seconds", duration},
                             {"warmup_s", warm},
                             {"cycles", cycles},
                             {"failed_cycles", failed},
                             {"frames_per_cycle", kFrames},
                             {"samples", samples.size()},
                             {"fitted_samples", x.size()},
                             {"rss_slope_kb_per_min", rss_slope},
                             {"fd_slope_per_min", fd_slope},
                             {"mapping_slope_per_min", map_slope}});
    if (!samples.empty())
        r.result.metrics.update({{"rss_kib_first", samples.front().rss_kib},
                                 {"rss_kib_last", samples.back().rss_kib},
                                 {"fds_last", samples.back().fds},
                                 {"maps_last", samples.back().maps}});
    if (!o.soak_csv.empty()) {
        {
            std::ofstream f(o.soak_csv);
            f << "seconds,cycles,fds,mappings,rss_kib\n";
            for (const Sample& s : samples)
                f << fmt::format("{:.2f},{},{},{},{}\n", s.t, s.cycles, s.fds, s.maps, s.rss_kib);
            f.close();
            r.check(bool(f), "cannot write " + o.soak_csv);
        } // closed before gnuplot reads it
        std::string png = o.soak_csv;
        if (png.size() > 4 && png.compare(png.size() - 4, 4, ".csv") == 0) png.resize(png.size() - 4);
        png += ".png";
        const std::string why = plot(o.soak_csv, png);
        r.result.metrics["csv"] = o.soak_csv;
        if (why.empty())
            r.result.metrics["png"] = png;
        else
            r.note("no plot: " + why);
    }
    r.check(failed == 0, fmt::format("{} of {} cycles failed, first: {}", failed, cycles, first_failure));
    r.check(x.size() >= 3, "too few samples after the warm-up for a slope");
    r.check(rss_slope <= kMaxRssSlope,
            fmt::format("RSS slope {:.1f} kB/min > {:.0f}", rss_slope, kMaxRssSlope));
    r.check(std::fabs(fd_slope) <= kMaxCountSlope, fmt::format("fd slope {:.3f}/min", fd_slope));
    r.check(std::fabs(map_slope) <= kMaxCountSlope, fmt::format("mapping slope {:.3f}/min", map_slope));
    r.result.measured = fmt::format(
        "{} cycles ({} frames of {}x{} each, {} failed) in {:.0f} s; after {:.0f} s warm-up: "
        "RSS slope {:+.1f} kB/min, fd slope {:+.3f}/min, mapping slope {:+.3f}/min; RSS "
        "{} -> {} KiB",
        cycles, kFrames, kSide, kSide, failed, duration, warm, rss_slope, fd_slope, map_slope,
        samples.empty() ? 0 : samples.front().rss_kib, samples.empty() ? 0 : samples.back().rss_kib);
    if (d.running()) {
        const int st = d.terminate(10000);
        r.check(st == 0, fmt::format("fgsrd did not exit cleanly on SIGTERM (wait status {})", st));
    }
    r.result.pass = r.failures == 0;
    r.result.seconds = raw::ms_since(t0) / 1000.0;
    return r.result;
}

} // namespace fgsr::stress
