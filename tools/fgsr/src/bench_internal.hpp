// Private to `fgsr bench` (bench.cpp runs it, bench_report.cpp writes its outputs): the pass order
// and the progress line.
#pragma once

#include <fgsr/cli/bench.hpp>

#include <cstdio>
#include <string>

namespace fgsr::cli::bench_detail {

// Engine passes in pipeline order (the CSV columns and the bar plot's stack order).
inline constexpr const char* kPasses[] = {"sr",     "splat",  "generate", "generate_sr",
                                          "refine", "disocc", "warp",     "blend"};

inline void progress(const BenchOptions& o, const std::string& line) {
    if (o.progress) std::fprintf(stderr, "[bench] %s\n", line.c_str());
}

} // namespace fgsr::cli::bench_detail
