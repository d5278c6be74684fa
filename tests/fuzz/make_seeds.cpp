// fgsr_fuzz_seeds OUT: writes the seeds of the binary inputs to OUT/<target>/ at build time (EXR and
// PNG files, capture files, session descriptions, ring states), so that no binary seed is committed.
// Text seeds (TOML, JSON) are committed under tests/fuzz/seeds/<target>/.
#include "fuzz_support.hpp"
#include "tiny_captures.hpp"

#include <fgsr/wire.h>

#include <cstddef>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void write_seed(const fs::path& file, uint8_t prefix_byte, bool prefix, const std::vector<uint8_t>& body) {
    std::vector<uint8_t> bytes;
    if (prefix) bytes.push_back(prefix_byte);
    bytes.insert(bytes.end(), body.begin(), body.end());
    fgsr::fuzz::write_file(file, bytes);
}

template <class T> std::vector<uint8_t> bytes_of(const T& v) {
    std::vector<uint8_t> b(sizeof(T));
    std::memcpy(b.data(), &v, sizeof(T));
    return b;
}

fgsr_session_desc base_desc() {
    fgsr_session_desc d;
    std::memset(&d, 0, sizeof(d));
    d.struct_size = sizeof(d);
    d.width = 64;
    d.height = 36;
    d.color_format = FGSR_COLOR_RGBA16F_LINEAR;
    d.output_format = FGSR_COLOR_RGBA8_SRGB;
    d.mv_format = FGSR_MV_RG16F;
    d.scale = 1.f;
    d.modes = FGSR_MODE_INTERPOLATE;
    d.far_plane = 100.f;
    return d;
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: fgsr_fuzz_seeds OUT\n";
        return 2;
    }
    const fs::path out = argv[1];
    for (const char* t : {"fuzz_exr", "fuzz_png", "fuzz_capture", "fuzz_session_desc", "fuzz_ring_drain",
                          "fuzz_layer_config", "fuzz_daemon_messages", "fuzz_session_rings"})
        fs::create_directories(out / t);

    // Captures of each layout; their files are the seeds of fuzz_capture (selector byte first, the
    // numbering of fuzz_capture.cpp) and of the image readers.
    const fs::path caps = fgsr::fuzz::scratch_dir();
    fgsr::fuzz::write_tiny_fgsr(caps / "fgsr");
    fgsr::fuzz::write_tiny_blender(caps / "blender");
    fgsr::fuzz::write_tiny_mobfgsr(caps / "mobfgsr");
    const char* files[] = {"fgsr/manifest.json",
                           "fgsr/frames/0001.exr",
                           "fgsr/gt/0000.exr",
                           "blender/capture.json",
                           "blender/in_aux/0002.exr",
                           "blender/in/0001.exr",
                           "mobfgsr/HR_Inputs/depth/0001.png"};
    for (uint8_t i = 0; i < 7; ++i)
        write_seed(out / "fuzz_capture" / ("file" + std::to_string(i)), i, true, read_all(caps / files[i]));
    write_seed(out / "fuzz_exr" / "fgsr_frame.exr", 0, false, read_all(caps / files[1]));
    write_seed(out / "fuzz_exr" / "blender_aux.exr", 0, false, read_all(caps / files[4]));
    FGSR_FUZZ_CHECK(fgsr::capture::write_exr(caps / "rgba_half.exr", fgsr::fuzz::tiny_rgba()).ok());
    FGSR_FUZZ_CHECK(fgsr::capture::write_exr(caps / "rgba_float.exr", fgsr::fuzz::tiny_rgba(),
                                             fgsr::capture::ExrPixel::float32)
                        .ok());
    write_seed(out / "fuzz_exr" / "rgba_half.exr", 0, false, read_all(caps / "rgba_half.exr"));
    write_seed(out / "fuzz_exr" / "rgba_float.exr", 0, false, read_all(caps / "rgba_float.exr"));
    write_seed(out / "fuzz_png" / "rgba8.png", 0, false, read_all(caps / files[6]));
    FGSR_FUZZ_CHECK(fgsr::capture::write_png(caps / "rgb8.png", fgsr::fuzz::tiny_rgba()).ok());
    write_seed(out / "fuzz_png" / "rgb8.png", 0, false, read_all(caps / "rgb8.png"));

    // Session descriptions: accepted ones of each kind, then one byte of reason-buffer size.
    fgsr_session_desc d = base_desc();
    write_seed(out / "fuzz_session_desc" / "interp", 0, false, bytes_of(d));
    d.modes = FGSR_MODE_SR | FGSR_MODE_EXTRAPOLATE;
    d.scale = 2.f;
    d.input_slots = 8;
    d.ring_capacity = 16;
    write_seed(out / "fuzz_session_desc" / "sr_extrap", 0, false, bytes_of(d));
    d = base_desc();
    d.flags = FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH;
    d.width = 8192;
    d.height = 2;
    d.scale = 1.5f;
    d.modes = FGSR_MODE_SR;
    write_seed(out / "fuzz_session_desc" / "colour_only_wide", 0, false, bytes_of(d));
    d = base_desc();
    d.width = 0;
    auto refused = bytes_of(d);
    refused.push_back(5); // a 5-byte reason buffer
    write_seed(out / "fuzz_session_desc" / "refused_short_reason", 0, false, refused);

    // Ring states: [log2 capacity][ring][stop after][tail][head][peer tail][fill...], heads as
    // offsets from the tail and peer tails as offsets behind the head (fuzz_ring_drain.cpp).
    struct RingSeed {
        uint8_t log2, ring, stop;
        uint64_t tail;
        int16_t head_ahead, peer_behind;
    };
    const RingSeed rings[] = {{6, 0, 255, 10, 2, 2},    {2, 1, 0, 3, 4, 4},     {12, 2, 255, 0, 4096, 0},
                              {0, 0, 255, ~0ull, 1, 1}, {3, 1, 255, 5, 95, 95}, {4, 0, 255, 7, -3, 0}};
    int n = 0;
    for (const RingSeed& r : rings) {
        // FuzzedDataProvider takes integers from the end, the last byte most significant: the fill
        // comes first, then the values in reverse order of consumption, each little-endian.
        std::vector<uint8_t> b(64);
        for (size_t i = 0; i < b.size(); ++i) b[i] = uint8_t(i * 11);
        const uint64_t values[] = {uint64_t(uint16_t(r.peer_behind)), uint64_t(uint16_t(r.head_ahead)),
                                   r.tail};
        for (uint64_t v : values)
            for (int k = 0; k < 8; ++k) b.push_back(uint8_t(v >> (8 * k)));
        b.push_back(r.stop);
        b.push_back(r.ring);
        b.push_back(r.log2);
        write_seed(out / "fuzz_ring_drain" / ("ring" + std::to_string(n++)), 0, false, b);
    }

    // The layer's configuration with the environment selector (fuzz_layer_config.cpp): executable
    // "vkcube", FGSR_MULTIPLIER=4, FGSR_MODE=extrapolate, FGSR_FPS_LIMIT=30 (the TOML text seeds
    // are committed).
    const std::string toml = "[[profile]]\nactive_in = [\"vkcube\"]\nmultiplier = 3\n";
    std::vector<uint8_t> cfg(toml.begin(), toml.end());
    for (uint8_t v : {1, 5, 19, 21, 0}) cfg.push_back(v);
    write_seed(out / "fuzz_layer_config" / "profile_env", 0, false, cfg);

    // fuzz_daemon_messages: one packet of each request the daemon takes.
    {
        fgsr_hello h;
        std::memset(&h, 0, sizeof(h));
        h.header = fgsr_msg_header_for(FGSR_MSG_HELLO, sizeof(h), 1);
        h.major = FGSR_PROTOCOL_MAJOR;
        h.minor = FGSR_PROTOCOL_MINOR;
        std::strcpy(h.name, "seed");
        write_seed(out / "fuzz_daemon_messages" / "hello", 0, false, bytes_of(h));
        fgsr_create_session c;
        std::memset(&c, 0, sizeof(c));
        c.header = fgsr_msg_header_for(FGSR_MSG_CREATE_SESSION, sizeof(c), 2);
        c.desc = base_desc();
        write_seed(out / "fuzz_daemon_messages" / "create", 0, false, bytes_of(c));
        fgsr_session_ref r;
        std::memset(&r, 0, sizeof(r));
        r.header = fgsr_msg_header_for(FGSR_MSG_STATS, sizeof(r), 3);
        r.session_id = 1;
        write_seed(out / "fuzz_daemon_messages" / "stats", 0, false, bytes_of(r));
        r.header = fgsr_msg_header_for(FGSR_MSG_DESTROY_SESSION, sizeof(r), 4);
        write_seed(out / "fuzz_daemon_messages" / "destroy", 0, false, bytes_of(r));
        fgsr_report rep;
        std::memset(&rep, 0, sizeof(rep));
        rep.header = fgsr_msg_header_for(FGSR_MSG_REPORT, FGSR_REPORT_MESSAGE_SIZE(2), 0);
        rep.session_id = 1;
        rep.count = 2;
        rep.reports[0].output_index = FGSR_REPORT_APPLICATION;
        rep.reports[1].frame_type = FGSR_FRAME_INTERPOLATED;
        std::vector<uint8_t> rb = bytes_of(rep);
        rb.resize(FGSR_REPORT_MESSAGE_SIZE(2));
        write_seed(out / "fuzz_daemon_messages" / "report", 0, false, rb);
        fgsr_probe pr;
        std::memset(&pr, 0, sizeof(pr));
        pr.header = fgsr_msg_header_for(FGSR_MSG_PROBE, FGSR_PROBE_MESSAGE_SIZE(1), 0);
        pr.count = 1;
        pr.samples[0] = {1000, 21000, FGSR_PROBE_MODE_OFF, 0};
        std::vector<uint8_t> pb = bytes_of(pr);
        pb.resize(FGSR_PROBE_MESSAGE_SIZE(1));
        write_seed(out / "fuzz_daemon_messages" / "probe", 0, false, pb);
    }
    // fuzz_session_rings: shape (2 input and 2 output slots, ring of 4, FIFO), then chunks of
    // (position u16 LE, length u8, bytes): a valid submit entry wanting one interpolation, its
    // publication, then a release of output slot 0.
    {
        const fgsr_rings_layout rl = fgsr_rings_layout_for(4);
        std::vector<uint8_t> b = {0, 0, 0x05, 0};
        auto chunk = [&](uint64_t at, const std::vector<uint8_t>& bytes) {
            b.push_back(uint8_t(at & 0xff));
            b.push_back(uint8_t(at >> 8));
            b.push_back(uint8_t(bytes.size()));
            b.insert(b.end(), bytes.begin(), bytes.end());
        };
        fgsr_submit_entry e;
        std::memset(&e, 0, sizeof(e));
        for (uint64_t k = 0; k < 3; ++k) {
            e.sequence = k + 1;
            e.input_slot = uint32_t(k % 2);
            e.interp_count = k > 0 ? 1 : 0;
            e.interp_alphas[0] = 0.5f;
            chunk(rl.submit_entries + k * sizeof(e), bytes_of(e));
            chunk(rl.submit_header, bytes_of(uint64_t(k + 1)));
            chunk(rl.completion_header + offsetof(fgsr_ring_header, tail), bytes_of(uint64_t(k + 1)));
        }
        fgsr::fuzz::write_file(out / "fuzz_session_rings" / "three_submits", b);
    }
    return 0;
}
