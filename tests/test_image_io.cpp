// Image file I/O: sRGB transfer, PNG and EXR round trips, and errors on malformed files.
#include <fgsr/capture/image_io.hpp>
#include <fgsr/engine/color.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace fgsr;
using namespace fgsr::capture;

namespace {

// A fresh, empty directory under the system temp dir, removed when the object dies.
struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& tag) {
        path = fs::temp_directory_path() / ("fgsr-imageio-" + tag + "-" + std::to_string(::getpid()));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

void truncate_file(const fs::path& p, double keep_fraction) {
    const auto size = fs::file_size(p);
    fs::resize_file(p, static_cast<uintmax_t>(double(size) * keep_fraction));
}

uint32_t float_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

} // namespace

TEST(ImageIo, SrgbTransferFunction) {
    EXPECT_FLOAT_EQ(srgb_encode(0.f), 0.f);
    EXPECT_FLOAT_EQ(srgb_encode(1.f), 1.f);
    EXPECT_NEAR(srgb_encode(0.5f), 0.735357f, 1e-5f);
    EXPECT_NEAR(srgb_decode(0.5f), 0.214041f, 1e-5f);
    EXPECT_FLOAT_EQ(srgb_encode(-3.f), 0.f); // clamped
    EXPECT_FLOAT_EQ(srgb_encode(7.f), 1.f);
    EXPECT_FLOAT_EQ(srgb_encode(std::numeric_limits<float>::quiet_NaN()), 0.f);
    for (int i = 0; i <= 1000; ++i) {
        const float v = float(i) / 1000.f;
        EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 2e-6f) << v;
    }
    for (int b = 0; b < 256; ++b) {
        EXPECT_EQ(srgb8_decode(uint8_t(b)), srgb_decode(float(b) / 255.f));
        // Encoding the decoded byte and rounding gives the byte back (what PNG round trips rely on).
        EXPECT_EQ(std::lround(srgb_encode(srgb8_decode(uint8_t(b))) * 255.f), b);
    }
}

TEST(ImageIo, PngRoundTripLinear) {
    TempDir tmp("png-linear");
    ImageRGBA img;
    img.width = 37;
    img.height = 11;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    std::vector<uint8_t> expect(size_t(img.width) * img.height * 4);
    for (size_t i = 0; i < img.rgba.size(); ++i) {
        const uint8_t b = uint8_t((i * 37 + i / 7) % 256);
        img.rgba[i] = (i % 4 == 3) ? 0.25f : srgb8_decode(b);
        expect[i] = (i % 4 == 3) ? 255 : b; // alpha is not stored: reads back opaque
    }
    img.rgba[0] = 5.f; // HDR clamps to 255
    expect[0] = 255;
    img.rgba[1] = -1.f; // negative clamps to 0
    expect[1] = 0;
    const fs::path p = tmp.path / "a.png";
    ASSERT_TRUE(write_png(p, img));
    auto back = read_png(p);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->width, img.width);
    EXPECT_EQ(back->height, img.height);
    EXPECT_EQ(back->rgba, expect);
}

TEST(ImageIo, PngRoundTripRawRgba8) {
    TempDir tmp("png-raw");
    Image8 img;
    img.width = 19;
    img.height = 23;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    std::mt19937 rng(7);
    for (auto& b : img.rgba) b = uint8_t(rng());
    const fs::path p = tmp.path / "raw.png";
    ASSERT_TRUE(write_png8(p, img));
    auto back = read_png(p);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->width, img.width);
    EXPECT_EQ(back->height, img.height);
    EXPECT_EQ(back->rgba, img.rgba); // bytes as stored, no gamma or alpha processing
}

TEST(ImageIo, PngErrorsNameTheFile) {
    TempDir tmp("png-errors");
    const fs::path missing = tmp.path / "missing.png";
    auto r = read_png(missing);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::io);
    EXPECT_NE(r.error().message.find("missing.png"), std::string::npos) << r.error().message;

    const fs::path text = tmp.path / "text.png";
    std::ofstream(text) << "this is not a png file at all";
    r = read_png(text);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("text.png"), std::string::npos) << r.error().message;

    Image8 img{64, 64, std::vector<uint8_t>(64 * 64 * 4)};
    std::mt19937 rng(3);
    for (auto& b : img.rgba) b = uint8_t(rng()); // incompressible, so truncation cuts pixel data
    const fs::path cut = tmp.path / "cut.png";
    ASSERT_TRUE(write_png8(cut, img));
    truncate_file(cut, 0.5);
    r = read_png(cut);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::io);
    EXPECT_NE(r.error().message.find("cut.png"), std::string::npos) << r.error().message;

    ImageRGBA bad{4, 4, std::vector<float>(3)};
    auto w = write_png(tmp.path / "bad.png", bad);
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("bad.png"), std::string::npos);
    EXPECT_FALSE(write_png(tmp.path / "no-such-dir" / "x.png", ImageRGBA{1, 1, {0, 0, 0, 1}}));
}

TEST(ImageIo, ExrHalfRgbaRoundTrip) {
    TempDir tmp("exr-half");
    ImageRGBA img;
    img.width = 13;
    img.height = 9;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    for (size_t i = 0; i < img.rgba.size(); ++i)
        img.rgba[i] = float(int(i % 301) - 100) / 64.f; // exact in half
    img.rgba[5] = 1000.25f;                             // -> 1000 (rounded)
    const fs::path p = tmp.path / "half.exr";
    ASSERT_TRUE(write_exr(p, img));
    auto back = read_exr(p);
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->width, img.width);
    ASSERT_EQ(back->height, img.height);
    ASSERT_EQ(back->channels.size(), 4u);
    const char* names[4] = {"R", "G", "B", "A"};
    for (size_t c = 0; c < 4; ++c) {
        const ExrChannel* ch = back->find(names[c]);
        ASSERT_NE(ch, nullptr) << names[c];
        EXPECT_EQ(ch->type, ExrPixel::half);
        for (size_t i = 0; i < size_t(img.width) * img.height; ++i) {
            const float v = img.rgba[i * 4 + c];
            const float expect = (i * 4 + c == 5) ? 1000.f : v;
            EXPECT_EQ(ch->data[i], expect) << "channel " << names[c] << " pixel " << i;
        }
    }
}

TEST(ImageIo, ExrMultichannelRoundTripIsBitExact) {
    TempDir tmp("exr-multi");
    ExrImage img;
    img.width = 21;
    img.height = 17;
    const size_t n = size_t(img.width) * img.height;
    std::mt19937 rng(11);
    ExrChannel f32{"Layer.Depth.Z", ExrPixel::float32, std::vector<float>(n)};
    for (auto& v : f32.data) {
        uint32_t u = rng();
        std::memcpy(&v, &u, 4); // arbitrary bit patterns, NaNs included
    }
    f32.data[0] = std::numeric_limits<float>::infinity();
    f32.data[1] = -0.f;
    ExrChannel h16{"Layer.Vector.X", ExrPixel::half, std::vector<float>(n)};
    for (size_t i = 0; i < n; ++i) h16.data[i] = float(int(i) - 150) * 0.125f;
    img.channels = {f32, h16};
    const fs::path p = tmp.path / "multi.exr";
    ASSERT_TRUE(write_exr(p, img));

    auto back = read_exr(p, {"Layer.Vector.X", "Layer.Depth.Z"}); // order as requested
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->channels.size(), 2u);
    EXPECT_EQ(back->channels[0].name, "Layer.Vector.X");
    EXPECT_EQ(back->channels[0].type, ExrPixel::half);
    EXPECT_EQ(back->channels[1].type, ExrPixel::float32);
    for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(float_bits(back->channels[1].data[i]), float_bits(f32.data[i])) << i;
        ASSERT_EQ(back->channels[0].data[i], h16.data[i]) << i;
    }
}

TEST(ImageIo, ExrErrorsNameTheFile) {
    TempDir tmp("exr-errors");
    auto r = read_exr(tmp.path / "nothing.exr");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Errc::io);
    EXPECT_NE(r.error().message.find("nothing.exr"), std::string::npos) << r.error().message;

    ImageRGBA img{64, 48, std::vector<float>(64 * 48 * 4)};
    std::mt19937 rng(5);
    for (auto& v : img.rgba) v = float(rng() % 4096) / 1024.f;
    const fs::path good = tmp.path / "good.exr";
    ASSERT_TRUE(write_exr(good, img));

    auto m = read_exr(good, {"R", "ViewLayer.Depth.Z"});
    ASSERT_FALSE(m);
    EXPECT_EQ(m.error().code, Errc::io);
    EXPECT_NE(m.error().message.find("good.exr"), std::string::npos) << m.error().message;
    EXPECT_NE(m.error().message.find("ViewLayer.Depth.Z"), std::string::npos) << m.error().message;

    const fs::path cut = tmp.path / "cut.exr";
    fs::copy_file(good, cut);
    truncate_file(cut, 0.6);
    auto t = read_exr(cut);
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().code, Errc::io);
    EXPECT_NE(t.error().message.find("cut.exr"), std::string::npos) << t.error().message;

    const fs::path header_only = tmp.path / "tiny.exr";
    fs::copy_file(good, header_only);
    fs::resize_file(header_only, 10);
    auto h = read_exr(header_only);
    ASSERT_FALSE(h);
    EXPECT_NE(h.error().message.find("tiny.exr"), std::string::npos) << h.error().message;

    const fs::path text = tmp.path / "text.exr";
    std::ofstream(text) << "not an exr";
    auto x = read_exr(text);
    ASSERT_FALSE(x);
    EXPECT_NE(x.error().message.find("text.exr"), std::string::npos) << x.error().message;

    ExrImage bad;
    bad.width = 4;
    bad.height = 4;
    bad.channels.push_back(ExrChannel{"R", ExrPixel::half, std::vector<float>(15)});
    auto w = write_exr(tmp.path / "bad.exr", bad);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error().code, Errc::size_mismatch);
    EXPECT_NE(w.error().message.find("bad.exr"), std::string::npos) << w.error().message;
}
