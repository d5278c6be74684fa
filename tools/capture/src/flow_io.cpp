// Middlebury .flo reading and writing (fgsr/capture/flow_io.hpp).
#include <fgsr/capture/flow_io.hpp>

#include <fgsr/core/types.hpp>

#include <bit>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

namespace fgsr::capture {

static_assert(std::endian::native == std::endian::little, ".flo files are little-endian; so is this reader");

namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

} // namespace

Result<FlowField> read_flo(const std::filesystem::path& path) {
    std::error_code ec;
    const uintmax_t file_size = std::filesystem::file_size(path, ec);
    if (ec) return make_error(Errc::io, "cannot read flow file " + path.string() + ": " + ec.message());
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) return make_error(Errc::io, "cannot open flow file " + path.string());
    unsigned char header[12];
    if (file_size < sizeof header || std::fread(header, 1, sizeof header, f.get()) != sizeof header)
        return make_error(Errc::io, "flow file " + path.string() +
                                        " is truncated: " + std::to_string(file_size) +
                                        " bytes, shorter than the 12-byte header");
    float magic = 0;
    int32_t w = 0, h = 0;
    std::memcpy(&magic, header, 4);
    std::memcpy(&w, header + 4, 4);
    std::memcpy(&h, header + 8, 4);
    if (magic != kFloMagic)
        return make_error(Errc::io, "flow file " + path.string() + " has magic " + std::to_string(magic) +
                                        ", not 202021.25 (not a Middlebury .flo file)");
    if (w < 1 || h < 1 || uint32_t(w) > kMaxFrameSide || uint32_t(h) > kMaxFrameSide)
        return make_error(Errc::io, "flow file " + path.string() + " declares a " + std::to_string(w) + "x" +
                                        std::to_string(h) + " field; sides must be in [1, " +
                                        std::to_string(kMaxFrameSide) + "]");
    FlowField out;
    out.width = uint32_t(w);
    out.height = uint32_t(h);
    const uintmax_t expected = 12 + uintmax_t(out.width) * out.height * 8;
    if (file_size != expected)
        return make_error(Errc::io, "flow file " + path.string() + " holds " + std::to_string(file_size) +
                                        " bytes; a " + std::to_string(w) + "x" + std::to_string(h) +
                                        " field needs " + std::to_string(expected) +
                                        (file_size < expected ? " (truncated)" : " (trailing bytes)"));
    out.xy.resize(size_t(out.width) * out.height * 2);
    if (std::fread(out.xy.data(), sizeof(float), out.xy.size(), f.get()) != out.xy.size())
        return make_error(Errc::io, "cannot read the vectors of flow file " + path.string());
    return out;
}

Result<FlowField> read_flo(const std::filesystem::path& path, uint32_t width, uint32_t height) {
    auto flow = read_flo(path);
    if (!flow) return flow.error();
    if (flow->width != width || flow->height != height)
        return make_error(Errc::size_mismatch, "flow file " + path.string() + " holds a " +
                                                   std::to_string(flow->width) + "x" +
                                                   std::to_string(flow->height) + " field; the frames are " +
                                                   std::to_string(width) + "x" + std::to_string(height));
    return flow;
}

Result<void> write_flo(const std::filesystem::path& path, const FlowField& flow) {
    if (flow.width == 0 || flow.height == 0 || flow.width > kMaxFrameSide || flow.height > kMaxFrameSide)
        return make_error(Errc::invalid_argument, "cannot write a " + std::to_string(flow.width) + "x" +
                                                      std::to_string(flow.height) + " flow field");
    if (flow.xy.size() != size_t(flow.width) * flow.height * 2)
        return make_error(Errc::invalid_argument, "flow field " + std::to_string(flow.width) + "x" +
                                                      std::to_string(flow.height) + " holds " +
                                                      std::to_string(flow.xy.size()) + " floats, expected " +
                                                      std::to_string(size_t(flow.width) * flow.height * 2));
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) return make_error(Errc::io, "cannot create flow file " + path.string());
    const int32_t w = int32_t(flow.width), h = int32_t(flow.height);
    bool ok = std::fwrite(&kFloMagic, 4, 1, f.get()) == 1 && std::fwrite(&w, 4, 1, f.get()) == 1 &&
              std::fwrite(&h, 4, 1, f.get()) == 1 &&
              std::fwrite(flow.xy.data(), sizeof(float), flow.xy.size(), f.get()) == flow.xy.size();
    ok = std::fclose(f.release()) == 0 && ok;
    if (!ok) return make_error(Errc::io, "cannot write flow file " + path.string());
    return {};
}

} // namespace fgsr::capture
