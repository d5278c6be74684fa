// `fgsr replay`: streams a capture through fgsrd with libfgsr_client, writes the outputs and the
// per-frame telemetry, and scores the outputs with eval's code (halfway_targets, score_image,
// finish_means) when the capture has references. `fgsr eval --socket` runs the same code.
#pragma once

#include <fgsr/cli/eval.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fgsr::cli {

struct ReplayOptions {
    std::string capture = "builtin"; // capture directory, or "builtin" (eval's synthetic scene)
    EvalMode mode = EvalMode::interp;
    std::string socket;                             // empty: $FGSR_SOCKET, else the default path
    double fps = 0;                                 // 0: as fast as possible; else submits paced at fps
    std::optional<std::filesystem::path> out;       // outputs as eval --out writes them for "fgsr"
    std::optional<std::filesystem::path> telemetry; // PresentMon-style CSV, one row per present
    float alpha = 0.5f;
    int max_frames = 0; // 0: all
    bool prefer_lr = false;
    bool progress = true;
    bool mailbox = false;     // queue policy mailbox instead of fifo
    bool closed_loop = false; // wait for each submit's last completion before the next (benchmark)
    Params params; // t_depth, t_bright, sr_a, sr_b, dilate_mvs, mvs_contain_jitter, correct_vectors are sent
};

struct ReplaySummary {
    std::string capture, mode, device;
    size_t submitted = 0, outputs = 0, dropped = 0, rejected = 0;
    double wall_s = 0;
    double latency_p50_ms = 0, latency_p99_ms = 0; // client-observed: submit to completion seen
    double overhead_p50_ms = 0,
           overhead_p99_ms = 0; // client-observed minus the daemon's work (start->complete)
    // Medians of the overhead's steps (us): wake = dequeue - submit (the daemon's I/O thread read
    // the submit), hand-off = start - dequeue (to the lane), return = seen - complete (completion
    // published to fgsr_wait returning it). The lane's hand-back to the I/O thread is inside
    // start..complete.
    double wake_p50_us = 0, handoff_p50_us = 0, return_p50_us = 0;
    uint64_t client_wait_cpu_ns = 0; // this thread's CPU time in fgsr_wait and fgsr_acquire_input
    double daemon_latency_p50_ms = 0, daemon_latency_p99_ms = 0; // from the daemon's stats
    uint64_t daemon_bytes_copied = 0;
    uint64_t client_bytes_copied = 0;  // planes written into input slots + outputs read back
    std::optional<EvalReport> metrics; // when the capture has references for the mode
};

Result<ReplaySummary> run_replay(const ReplayOptions& options);
std::string replay_summary_text(const ReplaySummary& s);

// `fgsr replay --bench` (replay_bench.cpp): the service overhead with one frame in flight, at each
// size, with spinning off and on in the same run (two fgsrd it starts, or the one at `socket`,
// where only the client's spin changes), the CPU time it costs, medians of `runs` runs. Prints,
// asserts nothing.
struct ReplayBenchOptions {
    std::string socket;                                               // empty: start its own fgsrd
    std::vector<std::pair<uint32_t, uint32_t>> sizes = {{64, 64}, {1280, 720}}; // width, height
    int frames = 60;                                                  // submits per run
    int runs = 3;
    uint32_t spin_us = 1000; // fgsrd --spin-us and FGSR_WAIT_SPIN_US of the "on" configuration
    bool progress = true;
};
Result<void> run_replay_bench(const ReplayBenchOptions& options);
// "WxH[,WxH...]" -> sizes; an error names the bad item.
Result<std::vector<std::pair<uint32_t, uint32_t>>> parse_bench_sizes(const std::string& text);

} // namespace fgsr::cli
