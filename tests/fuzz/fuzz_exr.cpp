// Fuzz target: fgsr_capture_format's OpenEXR reader (read_exr, all channels and a named subset) on
// arbitrary file contents. A file that reads must give width*height values per channel, with the
// requested channels in the requested order.
#include "fuzz_support.hpp"

#include <fgsr/capture/exr_io.hpp>

#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = fgsr::fuzz::scratch_dir() / "input.exr";
    fgsr::fuzz::write_file(path, {data, size});
    const auto all = fgsr::capture::read_exr(path);
    if (all) {
        FGSR_FUZZ_CHECK(all->width > 0 && all->height > 0);
        for (const auto& ch : all->channels)
            FGSR_FUZZ_CHECK(ch.data.size() == size_t(all->width) * all->height);
    }
    const std::vector<std::string> names = {"B", "R"};
    const auto some = fgsr::capture::read_exr(path, names);
    if (some) {
        FGSR_FUZZ_CHECK(some->channels.size() == 2);
        FGSR_FUZZ_CHECK(some->channels[0].name == "B" && some->channels[1].name == "R");
        for (const auto& ch : some->channels)
            FGSR_FUZZ_CHECK(ch.data.size() == size_t(some->width) * some->height);
        if (all) FGSR_FUZZ_CHECK(all->width == some->width && all->height == some->height);
    }
    return 0;
}
