// What the fuzz targets share: a private scratch folder (on /dev/shm when it exists, so that the
// readers that take a path cost no disk I/O), writing an input there, and the check that stops a
// run. Header-only (fgsr_fuzz_support).
//
// Contract for a target: LLVMFuzzerTestOneInput must accept every input (errors are values, never
// a crash); a property the code promises is checked with FGSR_FUZZ_CHECK, which aborts with the
// failed condition so that libFuzzer records the input as a finding. Not thread-safe.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <system_error>
#include <unistd.h>

#define FGSR_FUZZ_CHECK(cond)                                                                                \
    do {                                                                                                     \
        if (!(cond)) {                                                                                       \
            std::fprintf(stderr, "fuzz check failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__);              \
            std::abort();                                                                                    \
        }                                                                                                    \
    } while (0)

namespace fgsr::fuzz {

// This process's scratch folder, created on first use and removed at exit.
inline const std::filesystem::path& scratch_dir() {
    static const std::filesystem::path dir = [] {
        std::error_code ec;
        const std::filesystem::path root = std::filesystem::is_directory("/dev/shm", ec)
                                               ? std::filesystem::path("/dev/shm")
                                               : std::filesystem::temp_directory_path();
        std::filesystem::path d = root / ("fgsr-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        std::atexit([] {
            std::error_code ec2;
            std::filesystem::remove_all(scratch_dir(), ec2);
        });
        return d;
    }();
    return dir;
}

// Writes `bytes` to `path` (replacing it); aborts when that fails (the scratch folder is ours).
inline void write_file(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.close();
    FGSR_FUZZ_CHECK(out.good());
}

} // namespace fgsr::fuzz
