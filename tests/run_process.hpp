// Runs a command line and collects its stdout (stderr goes to the test log); for end-to-end tests
// of the fgsr binary. Also counts this process's open fds (leak checks).
#pragma once

#include <array>
#include <cstdio>
#include <dirent.h>
#include <string>

namespace fgsr::test {

struct ProcessRun {
    int status = -1; // pclose() status; 0 = success
    std::string out;
};

inline ProcessRun run_process(const std::string& command) {
    ProcessRun r;
    FILE* p = popen(command.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
    r.status = pclose(p);
    return r;
}

// Open fds of this process (/proc/self/fd, without the directory stream's own), or -1.
inline int count_fds() {
    int n = 0;
    DIR* d = opendir("/proc/self/fd");
    if (!d) return -1;
    while (dirent* e = readdir(d))
        if (e->d_name[0] != '.') ++n;
    closedir(d);
    return n - 1;
}

} // namespace fgsr::test
