// OpenEXR (Imf C++ API) readers and writers of fgsr_capture_format. OpenEXR throws: every call is
// wrapped and turned into an Errc::io error naming the file.
#include <fgsr/capture/format_util.hpp>

#include <fgsr/capture/exr_io.hpp>

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>

#include <algorithm>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

namespace fgsr::capture {

namespace fs = std::filesystem;

namespace {

using detail::consistent;
using detail::io_error;

// EXR

void init_exr_threads() {
    static std::once_flag once;
    std::call_once(once, [] {
        const unsigned n = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
        Imf::setGlobalThreadCount(int(n));
    });
}

Result<ExrImage> read_exr_impl(const fs::path& path, const std::vector<std::string>* names) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return io_error(path, "file not found");
    init_exr_threads();
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        const Imath::Box2i dw = header.dataWindow();
        const Imath::Box2i disp = header.displayWindow();
        if (dw != disp)
            return make_error(Errc::unsupported, path.string() + ": data window differs from display window");
        const int64_t w = int64_t(dw.max.x) - dw.min.x + 1;
        const int64_t h = int64_t(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0 || w > (1 << 16) || h > (1 << 16))
            return io_error(path, "invalid image size " + std::to_string(w) + "x" + std::to_string(h));

        ExrImage img;
        img.width = uint32_t(w);
        img.height = uint32_t(h);
        std::vector<std::string> wanted;
        if (names) {
            wanted = *names;
        } else {
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
                wanted.emplace_back(it.name());
        }
        img.channels.resize(wanted.size());
        Imf::FrameBuffer fb;
        const size_t count = size_t(w) * size_t(h);
        for (size_t i = 0; i < wanted.size(); ++i) {
            const Imf::Channel* ch = header.channels().findChannel(wanted[i]);
            if (!ch) return io_error(path, "missing channel '" + wanted[i] + "'");
            if (ch->xSampling != 1 || ch->ySampling != 1)
                return make_error(Errc::unsupported,
                                  path.string() + ": subsampled channel '" + wanted[i] + "'");
            ExrChannel& out = img.channels[i];
            out.name = wanted[i];
            if (ch->type == Imf::HALF) {
                out.type = ExrPixel::half;
            } else if (ch->type == Imf::FLOAT) {
                out.type = ExrPixel::float32;
            } else {
                return make_error(Errc::unsupported, path.string() + ": channel '" + wanted[i] + "' is UINT");
            }
            out.data.assign(count, 0.f);
            // Base pointer so that (x, y) of the data window lands at index (y-min.y)*w + (x-min.x).
            char* base = reinterpret_cast<char*>(out.data.data()) -
                         (int64_t(dw.min.x) + int64_t(dw.min.y) * w) * int64_t(sizeof(float));
            fb.insert(wanted[i], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(w)));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        return img;
    } catch (const std::exception& e) {
        return io_error(path, std::string("OpenEXR: ") + e.what());
    } catch (...) {
        return io_error(path, "OpenEXR: unknown error");
    }
}

} // namespace

const ExrChannel* ExrImage::find(std::string_view name) const {
    for (const auto& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

Result<ExrImage> read_exr(const fs::path& path) {
    return read_exr_impl(path, nullptr);
}

Result<ExrImage> read_exr(const fs::path& path, const std::vector<std::string>& names) {
    return read_exr_impl(path, &names);
}

Result<void> write_exr(const fs::path& path, const ExrImage& img) {
    if (img.width == 0 || img.height == 0 || img.channels.empty())
        return make_error(Errc::invalid_argument, path.string() + ": empty image");
    const size_t count = size_t(img.width) * img.height;
    for (const auto& c : img.channels) {
        if (c.data.size() != count)
            return make_error(Errc::size_mismatch, path.string() + ": channel '" + c.name + "' has " +
                                                       std::to_string(c.data.size()) + " values, expected " +
                                                       std::to_string(count));
        if (c.name.empty()) return make_error(Errc::invalid_argument, path.string() + ": unnamed channel");
    }
    init_exr_threads();
    try {
        Imf::Header header(int(img.width), int(img.height));
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer fb;
        // Output slices must match the channel type: half channels get a converted copy
        // (round to nearest; exact for values that came from a half).
        std::vector<std::vector<Imath::half>> halves;
        halves.reserve(img.channels.size());
        for (const auto& c : img.channels) {
            if (c.type == ExrPixel::half) {
                header.channels().insert(c.name, Imf::Channel(Imf::HALF));
                auto& h = halves.emplace_back(count);
                for (size_t i = 0; i < count; ++i) h[i] = Imath::half(c.data[i]);
                fb.insert(c.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(h.data()),
                                             sizeof(Imath::half), sizeof(Imath::half) * img.width));
            } else {
                header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
                fb.insert(c.name,
                          Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.data.data())),
                                     sizeof(float), sizeof(float) * img.width));
            }
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(fb);
        file.writePixels(int(img.height));
        return {};
    } catch (const std::exception& e) {
        return io_error(path, std::string("OpenEXR: ") + e.what());
    } catch (...) {
        return io_error(path, "OpenEXR: unknown error");
    }
}

Result<void> write_exr(const fs::path& path, const ImageRGBA& img, ExrPixel type) {
    if (!consistent(img))
        return make_error(Errc::invalid_argument, path.string() + ": empty or inconsistent image");
    ExrImage e;
    e.width = img.width;
    e.height = img.height;
    const size_t n = size_t(img.width) * img.height;
    const char* names[4] = {"R", "G", "B", "A"};
    for (size_t c = 0; c < 4; ++c) {
        ExrChannel ch;
        ch.name = names[c];
        ch.type = type;
        ch.data.resize(n);
        for (size_t i = 0; i < n; ++i) ch.data[i] = img.rgba[i * 4 + c];
        e.channels.push_back(std::move(ch));
    }
    return write_exr(path, e);
}

} // namespace fgsr::capture
