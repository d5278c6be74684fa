// The layer's counters, present records, dumps and log (report.hpp).
#include "report.hpp"

#include "lazy.hpp"

#include <fgsr/core/presentmon.hpp>
#include <fgsr/protocol.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <unistd.h>
#include <vector>

namespace fgsr::layer {

void log_line(const std::string& message) {
    std::fprintf(stderr, "fgsr layer: %s\n", message.c_str());
    std::fflush(stderr);
}

struct PresentRecord {
    PresentKind kind;
    uint64_t app_present, app_ns, intended_ns, actual_ns, call_ns, swapchain;
};

struct Report::State {
    std::mutex m;
    uint64_t app_presents = 0, presents = 0, generated = 0, dropped = 0, cpu_ns = 0;
    uint64_t displayed = 0, display_fallbacks = 0; // records completed by present wait / without
    std::vector<PresentRecord> records; // kept only with FGSR_LAYER_PRESENTS
    std::string stats_path, presents_path, dump_dir;
    LayerConfig config;
    bool present_wait = false;
};

namespace {
// Freed by release() when the layer frees its process-wide state (layer.cpp).
Lazy<Report> report;
} // namespace

Report::Report() : s_(new State) {
    if (const char* p = std::getenv("FGSR_LAYER_STATS")) s_->stats_path = p;
    if (const char* p = std::getenv("FGSR_LAYER_PRESENTS")) s_->presents_path = p;
    if (const char* p = std::getenv("FGSR_LAYER_DUMP")) s_->dump_dir = p;
}

Report::~Report() {
    delete s_;
}

Report& Report::get() {
    return report.get();
}

void Report::release() {
    report.reset();
}

void Report::app_present() {
    std::lock_guard l(s_->m);
    ++s_->app_presents;
}

void Report::present(PresentKind kind, uint64_t app_present, uint64_t app_ns, uint64_t intended_ns,
                     uint64_t actual_ns, uint64_t call_ns, uint64_t swapchain) {
    std::lock_guard l(s_->m);
    ++s_->presents;
    if (kind == PresentKind::generated) ++s_->generated;
    if (!s_->presents_path.empty() && s_->records.size() < (1u << 22))
        s_->records.push_back({kind, app_present, app_ns, intended_ns, actual_ns, call_ns, swapchain});
}

void Report::dropped(uint32_t n) {
    std::lock_guard l(s_->m);
    s_->dropped += n;
}

void Report::layer_cpu(uint64_t ns) {
    std::lock_guard l(s_->m);
    s_->cpu_ns += ns;
}

void Report::set_config(const LayerConfig& c) {
    std::lock_guard l(s_->m);
    s_->config = c;
}

void Report::set_present_wait(bool available) {
    std::lock_guard l(s_->m);
    s_->present_wait = available;
}

void Report::display_time(bool from_present_wait) {
    std::lock_guard l(s_->m);
    ++(from_present_wait ? s_->displayed : s_->display_fallbacks);
}

bool Report::dumping() const {
    return !s_->dump_dir.empty();
}

void Report::dump(const DumpInfo& info, const uint8_t* rgba8) {
    if (s_->dump_dir.empty()) return;
    char base[64];
    std::snprintf(base, sizeof(base), "/gen_%06llu_%u", static_cast<unsigned long long>(info.app_present),
                  info.index);
    const std::string stem = s_->dump_dir + base;
    if (FILE* f = std::fopen((stem + ".rgba").c_str(), "wb")) {
        std::fwrite(rgba8, 1, size_t(info.width) * info.height * 4, f);
        std::fclose(f);
    }
    if (FILE* f = std::fopen((stem + ".json").c_str(), "w")) {
        std::fprintf(f,
                     "{\"width\": %u, \"height\": %u, \"app_present\": %llu, \"index\": %u, \"alpha\": %.6f, "
                     "\"mode\": \"%s\", \"multiplier\": %u}\n",
                     info.width, info.height, static_cast<unsigned long long>(info.app_present), info.index,
                     double(info.alpha), mode_name(info.mode), info.multiplier);
        std::fclose(f);
    }
}

void Report::write_files() {
    std::lock_guard l(s_->m);
    if (!s_->stats_path.empty()) {
        if (FILE* f = std::fopen(s_->stats_path.c_str(), "w")) {
            const double cpu = s_->app_presents ? double(s_->cpu_ns) / double(s_->app_presents) : 0.0;
            std::fprintf(
                f,
                "{\"app_presents\": %llu, \"presents\": %llu, \"generated\": %llu, \"dropped\": %llu, "
                "\"mode\": \"%s\", \"motion\": \"%s\", \"multiplier\": %u, \"present_wait\": %s, "
                "\"displayed_by_present_wait\": %llu, \"present_wait_fallbacks\": %llu, "
                "\"layer_cpu_ns_per_present\": %.0f}\n",
                static_cast<unsigned long long>(s_->app_presents),
                static_cast<unsigned long long>(s_->presents), static_cast<unsigned long long>(s_->generated),
                static_cast<unsigned long long>(s_->dropped), mode_name(s_->config.mode),
                motion_name(s_->config.motion), s_->config.multiplier, s_->present_wait ? "true" : "false",
                static_cast<unsigned long long>(s_->displayed),
                static_cast<unsigned long long>(s_->display_fallbacks), cpu);
            std::fclose(f);
        }
    }
    if (!s_->presents_path.empty()) {
        if (FILE* f = std::fopen(s_->presents_path.c_str(), "w")) {
            // PresentMon's columns (fgsr/core/presentmon.hpp), a row per present in present order.
            std::string app = program_invocation_short_name ? program_invocation_short_name : "";
            std::fprintf(f, "%s\n", presentmon_header().c_str());
            std::map<uint64_t, uint64_t> previous; // per swapchain: the last present's time
            for (const PresentRecord& r : s_->records) {
                PresentRow row;
                row.application = app;
                row.process_id = uint32_t(getpid());
                row.swapchain = r.swapchain;
                row.frame_type = r.kind == PresentKind::real ? "Application"
                                 : s_->config.mode == Mode::extrapolate ? presentmon_frame_type(FGSR_FRAME_EXTRAPOLATED)
                                                                        : presentmon_frame_type(FGSR_FRAME_INTERPOLATED);
                row.time_s = double(r.actual_ns) * 1e-9;
                uint64_t& prev = previous[r.swapchain];
                if (prev != 0 && r.actual_ns >= prev) row.ms_between_presents = double(r.actual_ns - prev) * 1e-6;
                prev = r.actual_ns;
                // From the application's present of the frame involved (generated frames: the real
                // frame they were made with) to this present.
                if (r.actual_ns >= r.app_ns) row.ms_until_displayed = double(r.actual_ns - r.app_ns) * 1e-6;
                row.sequence = r.app_present; // the application's present counter
                row.intended_s = double(r.intended_ns) * 1e-9;
                row.call_s = double(r.call_ns) * 1e-9;
                std::fprintf(f, "%s\n", presentmon_row(row).c_str());
            }
            std::fclose(f);
        }
    }
}

} // namespace fgsr::layer
