// Fuzz target: the tools' PNG reader (read_png) on arbitrary file contents. A file that reads gives
// width*height*4 bytes of RGBA.
#include "fuzz_support.hpp"

#include <fgsr/capture/image_io.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = fgsr::fuzz::scratch_dir() / "input.png";
    fgsr::fuzz::write_file(path, {data, size});
    const auto img = fgsr::capture::read_png(path);
    if (img) {
        FGSR_FUZZ_CHECK(img->width > 0 && img->height > 0);
        FGSR_FUZZ_CHECK(img->rgba.size() == size_t(img->width) * img->height * 4);
    }
    return 0;
}
