// `fgsr stress`: the numerical stress cases (fgsr/capture/stress.hpp) fed to the engine, with a
// report of every case (PASS/FAIL, what was checked, the stated reasons of rejected inputs, the
// drift of the long SR run). Exit status 1 when any case fails. --daemon feeds the same cases
// through fgsrd (its own or --socket's).
#pragma once

#include <CLI/CLI.hpp>

#include <cstddef>
#include <string>

namespace fgsr::cli {

struct StressCli {
    size_t sr_frames = 1000; // the full run: 100000
    bool json = false;
    bool quiet = false;
    bool reduced = false; // the test suite's case sizes (no 1920x1080 frame)
    std::string device;
    std::string filter;  // run only cases whose name contains this
    bool daemon = false; // feed the cases through fgsrd (tools/fgsr/stress_daemon.cpp)
    std::string socket;  // with daemon: an fgsrd already listening; empty: spawn one next to fgsr
};

CLI::App* add_stress_command(CLI::App& app, StressCli& o);
int stress_main(const StressCli& o);
// The --daemon run: the cases fed through fgsrd with libfgsr_client; exit status as stress_main.
int stress_daemon_main(const StressCli& o);

} // namespace fgsr::cli
