// The session description's one rule set and the pool layout (fgsr_session_desc_normalize,
// fgsr_pool_layout_for in fgsr/wire.h), and the ring helpers (fgsr_ring_*, fgsr/ipc/ring.hpp).
// Layout properties are computed here independently (alignment, disjointness, sizes), not copied
// from the function under test.
#include <fgsr/ipc/ring.hpp>
#include <fgsr/protocol.h>
#include <fgsr/wire.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace {

fgsr_session_desc base_desc() {
    fgsr_session_desc d{};
    d.struct_size = sizeof(d);
    d.width = 64;
    d.height = 32;
    d.color_format = FGSR_COLOR_RGBA16F_LINEAR;
    d.mv_format = FGSR_MV_RG16F;
    d.depth_kind = FGSR_DEPTH_LINEAR;
    d.scale = 2.f;
    d.modes = FGSR_MODE_SR | FGSR_MODE_INTERPOLATE;
    d.output_format = FGSR_COLOR_RGBA8_SRGB;
    return d;
}

struct Outcome {
    fgsr_status status;
    std::string reason;
    fgsr_session_desc desc;
};

Outcome check(const std::function<void(fgsr_session_desc&)>& edit) {
    fgsr_session_desc in = base_desc();
    edit(in);
    Outcome o{};
    char reason[128] = "unset";
    o.status = fgsr_session_desc_normalize(&in, &o.desc, reason, sizeof(reason));
    o.reason = reason;
    return o;
}

void expect_ok(const std::function<void(fgsr_session_desc&)>& edit, const char* what) {
    const Outcome o = check(edit);
    EXPECT_EQ(o.status, FGSR_STATUS_OK) << what << ": " << o.reason;
    EXPECT_TRUE(o.reason.empty()) << what;
}

void expect_refused(const std::function<void(fgsr_session_desc&)>& edit, const char* what) {
    const Outcome o = check(edit);
    EXPECT_EQ(o.status, FGSR_STATUS_INVALID_ARGUMENT) << what;
    EXPECT_FALSE(o.reason.empty()) << what;
}

uint64_t color_bpp(uint32_t f) {
    return f == FGSR_COLOR_RGBA8_SRGB ? 4 : f == FGSR_COLOR_RGBA16F_LINEAR ? 8 : 16;
}
uint64_t mv_bpp(uint32_t f) {
    return f == FGSR_MV_RG16F ? 4 : 8;
}

} // namespace

TEST(SessionDesc, DefaultsAreAppliedOnce) {
    const Outcome o = check([](fgsr_session_desc&) {});
    ASSERT_EQ(o.status, FGSR_STATUS_OK) << o.reason;
    EXPECT_EQ(o.desc.input_slots, 3u);
    EXPECT_EQ(o.desc.output_slots, 4u);
    EXPECT_EQ(o.desc.ring_capacity, 64u);
    EXPECT_EQ(o.desc.struct_size, 128u);
    // Values that are given stay.
    const Outcome g = check([](fgsr_session_desc& d) {
        d.input_slots = 5;
        d.output_slots = 7;
        d.ring_capacity = 8;
        d.struct_size = 200; // a newer sender
    });
    ASSERT_EQ(g.status, FGSR_STATUS_OK) << g.reason;
    EXPECT_EQ(g.desc.input_slots, 5u);
    EXPECT_EQ(g.desc.output_slots, 7u);
    EXPECT_EQ(g.desc.ring_capacity, 8u);
    EXPECT_EQ(g.desc.struct_size, 128u);
}

TEST(SessionDesc, SizeBoundaries) {
    expect_ok([](fgsr_session_desc& d) { d.width = d.height = 1; }, "1x1");
    // base_desc() upscales by 2: the largest input side at that scale is 8192.
    expect_ok(
        [](fgsr_session_desc& d) {
            d.width = 16384;
            d.height = 8;
            d.scale = 1.f;
            d.modes = FGSR_MODE_INTERPOLATE;
        },
        "16384 wide");
    expect_ok(
        [](fgsr_session_desc& d) {
            d.height = 16384;
            d.width = 8;
            d.scale = 1.f;
            d.modes = FGSR_MODE_INTERPOLATE;
        },
        "16384 high");
    expect_ok([](fgsr_session_desc& d) { d.width = 8192; }, "8192 wide at scale 2");
    // The outputs are bounded by FGSR_MAX_FRAME_SIDE too (protocol.h; the engine refuses larger
    // ones): found by tests/fuzz/fuzz_session_desc (64x10020 at scale 2 was accepted).
    expect_refused([](fgsr_session_desc& d) { d.width = 8193; }, "8193 wide at scale 2 (16386 out)");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.width = 64;
            d.height = 10020;
        },
        "64x10020 at scale 2");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.width = 4097;
            d.scale = 4.f;
        },
        "4097 wide at scale 4");
    expect_ok(
        [](fgsr_session_desc& d) {
            d.width = 10922; // 16383 at scale 1.5
            d.scale = 1.5f;
        },
        "10922 wide at scale 1.5");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.width = 10923; // 16384.5 rounds to 16385
            d.scale = 1.5f;
        },
        "10923 wide at scale 1.5");
    expect_refused([](fgsr_session_desc& d) { d.width = 0; }, "width 0");
    expect_refused([](fgsr_session_desc& d) { d.height = 0; }, "height 0");
    expect_refused([](fgsr_session_desc& d) { d.width = 16385; }, "width 16385");
    expect_refused([](fgsr_session_desc& d) { d.height = 16385; }, "height 16385");
    expect_refused([](fgsr_session_desc& d) { d.struct_size = 127; }, "struct_size 127");
    // Each pool at most 2 GiB: 16384 x 8192 RGBA32F at scale 1 is exactly 2 GiB per input colour
    // plane, so the input slot is larger.
    expect_refused(
        [](fgsr_session_desc& d) {
            d.width = 16384;
            d.height = 8192;
            d.color_format = FGSR_COLOR_RGBA32F_LINEAR;
            d.scale = 1.f;
            d.modes = FGSR_MODE_INTERPOLATE;
            d.input_slots = 1;
        },
        "input pool over 2 GiB");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.width = 8192;
            d.height = 8192;
            d.color_format = FGSR_COLOR_RGBA8_SRGB;
            d.output_format = FGSR_COLOR_RGBA32F_LINEAR;
            d.output_slots = 1;
            d.input_slots = 1;
            d.scale = 2.f; // 16384^2 * 16 bytes = 4 GiB
        },
        "output pool over 2 GiB");
    expect_ok(
        [](fgsr_session_desc& d) {
            d.width = 4096;
            d.height = 4096;
            d.color_format = FGSR_COLOR_RGBA8_SRGB;
            d.scale = 1.f;
            d.modes = FGSR_MODE_INTERPOLATE;
            d.input_slots = 1;
            d.output_slots = 1;
        },
        "4096 square, one slot each");
}

TEST(SessionDesc, SlotsAndRingCapacity) {
    expect_ok(
        [](fgsr_session_desc& d) {
            d.input_slots = 64;
            d.output_slots = 64;
            d.ring_capacity = 64;
        },
        "64 slots");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.input_slots = 65;
            d.ring_capacity = 128;
        },
        "65 input slots");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.output_slots = 65;
            d.ring_capacity = 128;
        },
        "65 output slots");
    expect_refused([](fgsr_session_desc& d) { d.ring_capacity = 48; }, "ring 48");
    expect_refused([](fgsr_session_desc& d) { d.ring_capacity = 2; },
                   "ring below the 4 default output slots");
    expect_ok([](fgsr_session_desc& d) { d.ring_capacity = 4; }, "ring = output slots");
    expect_refused(
        [](fgsr_session_desc& d) {
            d.input_slots = 9;
            d.ring_capacity = 8;
        },
        "ring below input slots");
    expect_ok([](fgsr_session_desc& d) { d.ring_capacity = 4096; }, "ring 4096");
    expect_refused([](fgsr_session_desc& d) { d.ring_capacity = 8192; }, "ring 8192");
}

TEST(SessionDesc, ScaleIsOneOfTheEngineScales) {
    for (float s : {1.f, 1.5f, 2.f, 3.f, 4.f}) {
        const Outcome o = check([s](fgsr_session_desc& d) {
            d.scale = s;
            d.modes = s > 1.f ? FGSR_MODE_SR : FGSR_MODE_INTERPOLATE;
        });
        EXPECT_EQ(o.status, FGSR_STATUS_OK) << s << ": " << o.reason;
    }
    // The client used to accept anything in [1, 4]; fgsrd never did. One rule now: the daemon's.
    for (float s : {0.f, 0.5f, 0.999f, 1.25f, 2.5f, 3.5f, 3.999f, 4.001f, 5.f, -2.f, NAN, INFINITY}) {
        const Outcome o = check([s](fgsr_session_desc& d) {
            d.scale = s;
            d.modes = FGSR_MODE_INTERPOLATE;
        });
        EXPECT_EQ(o.status, FGSR_STATUS_INVALID_ARGUMENT) << s;
    }
    expect_refused(
        [](fgsr_session_desc& d) {
            d.scale = 1.f;
            d.modes = FGSR_MODE_SR;
        },
        "SR at scale 1");
}

TEST(SessionDesc, FormatsModesFlagsAndFloats) {
    for (uint32_t f = 0; f <= 2; ++f) {
        expect_ok([f](fgsr_session_desc& d) { d.color_format = f; }, "colour format");
        expect_ok([f](fgsr_session_desc& d) { d.output_format = f; }, "output format");
        expect_ok([f](fgsr_session_desc& d) { d.depth_kind = f; }, "depth kind");
    }
    for (uint32_t f = 0; f <= 1; ++f) {
        expect_ok([f](fgsr_session_desc& d) { d.mv_format = f; }, "mv format");
        expect_ok([f](fgsr_session_desc& d) { d.mv_units = f; }, "mv units");
        expect_ok([f](fgsr_session_desc& d) { d.mv_direction = f; }, "mv direction");
        expect_ok([f](fgsr_session_desc& d) { d.queue_policy = f; }, "queue policy");
    }
    expect_refused([](fgsr_session_desc& d) { d.color_format = 3; }, "colour format 3");
    expect_refused([](fgsr_session_desc& d) { d.output_format = 3; }, "output format 3");
    expect_refused([](fgsr_session_desc& d) { d.mv_format = 2; }, "mv format 2");
    expect_refused([](fgsr_session_desc& d) { d.depth_kind = 3; }, "depth kind 3");
    expect_refused([](fgsr_session_desc& d) { d.mv_units = 2; }, "mv units 2");
    expect_refused([](fgsr_session_desc& d) { d.mv_direction = 2; }, "mv direction 2");
    expect_refused([](fgsr_session_desc& d) { d.queue_policy = 2; }, "queue policy 2");
    expect_refused([](fgsr_session_desc& d) { d.modes = 0; }, "no modes");
    expect_refused([](fgsr_session_desc& d) { d.modes = 0x8; }, "unknown mode");
    expect_ok([](fgsr_session_desc& d) { d.flags = 0x1f; }, "every known flag");
    expect_ok(
        [](fgsr_session_desc& d) {
            d.flags = FGSR_SESSION_CORRECT_MVS;
            d.scale = 1.f;
            d.modes = FGSR_MODE_INTERPOLATE;
        },
        "vectors corrected by colour");
    expect_refused([](fgsr_session_desc& d) { d.flags = FGSR_SESSION_CORRECT_MVS; },
                   "corrected vectors with SR");
    expect_refused([](fgsr_session_desc& d) { d.flags = 0x400; }, "unknown flag");
    expect_refused([](fgsr_session_desc& d) { d.reserved[9] = 1; }, "reserved");
    expect_ok([](fgsr_session_desc& d) { d.far_plane = INFINITY; }, "infinite far plane");
    expect_refused([](fgsr_session_desc& d) { d.far_plane = NAN; }, "NaN far plane");
    expect_refused([](fgsr_session_desc& d) { d.near_plane = INFINITY; }, "infinite near plane");
    expect_refused([](fgsr_session_desc& d) { d.near_plane = NAN; }, "NaN near plane");
    expect_ok(
        [](fgsr_session_desc& d) {
            d.t_depth = 0.5f;
            d.t_bright = 0.f;
            d.sr_a = 2.f;
            d.sr_b = 0.25f;
        },
        "tuning values");
    expect_refused([](fgsr_session_desc& d) { d.t_depth = -0.5f; }, "negative t_depth");
    expect_refused([](fgsr_session_desc& d) { d.t_bright = NAN; }, "NaN t_bright");
    expect_refused([](fgsr_session_desc& d) { d.sr_a = INFINITY; }, "infinite sr_a");
    expect_refused([](fgsr_session_desc& d) { d.sr_b = -1.f; }, "negative sr_b");
}

TEST(SessionDesc, ReasonFitsTheBuffer) {
    fgsr_session_desc in = base_desc(), out{};
    in.width = 0;
    char small[8];
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &out, small, sizeof(small)), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_LT(std::strlen(small), sizeof(small));
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &out, nullptr, 0), FGSR_STATUS_INVALID_ARGUMENT);
}

TEST(PoolLayout, PropertiesHoldForASweep) {
    const uint32_t sides[] = {1, 2, 3, 7, 31, 64, 100, 1023, 1080, 1920, 4095};
    // Scales as twice the scale, so that the expected output size is exact integer arithmetic:
    // round half away from zero of w * k / 2.
    const uint32_t twice_scales[] = {2, 3, 4, 6, 8};
    size_t checked = 0;
    for (uint32_t w : sides)
        for (uint32_t h : {1u, 5u, 270u, 1080u})
            for (uint32_t cf = 0; cf <= 2; ++cf)
                for (uint32_t mf = 0; mf <= 1; ++mf)
                    for (uint32_t k : twice_scales) {
                        fgsr_session_desc in = base_desc();
                        in.width = w;
                        in.height = h;
                        in.color_format = cf;
                        in.mv_format = mf;
                        in.output_format = (cf + mf) % 3;
                        in.scale = float(k) / 2.f;
                        in.modes = k > 2 ? FGSR_MODE_SR : FGSR_MODE_EXTRAPOLATE;
                        in.input_slots = 1 + (w % 5);
                        in.output_slots = 1 + (h % 7);
                        fgsr_session_desc d{};
                        char reason[128];
                        if (fgsr_session_desc_normalize(&in, &d, reason, sizeof(reason)) != FGSR_STATUS_OK) {
                            // Only the 2 GiB pool limit may refuse these.
                            const uint64_t ow = (uint64_t(w) * k + 1) / 2, oh = (uint64_t(h) * k + 1) / 2;
                            EXPECT_GT(ow * oh * color_bpp(in.output_format) * in.output_slots,
                                      (1ull << 31) - 8 * 4096)
                                << w << "x" << h << ": " << reason;
                            continue;
                        }
                        const fgsr_pool_layout l = fgsr_pool_layout_for(&d);
                        const std::string at = std::to_string(w) + "x" + std::to_string(h) + " cf " +
                                               std::to_string(cf) + " mf " + std::to_string(mf) + " k " +
                                               std::to_string(k);
                        const uint64_t A = FGSR_PLANE_ALIGNMENT;
                        EXPECT_EQ(l.input_slot_count, in.input_slots) << at;
                        EXPECT_EQ(l.output_slot_count, in.output_slots) << at;
                        EXPECT_EQ(l.ring_capacity, 64u) << at;
                        EXPECT_EQ(l.output_width, (w * k + 1) / 2) << at;
                        EXPECT_EQ(l.output_height, (h * k + 1) / 2) << at;
                        EXPECT_EQ(l.input_slot_stride % A, 0u) << at;
                        EXPECT_EQ(l.output_slot_stride % A, 0u) << at;
                        EXPECT_GT(l.input_slot_stride, 0u) << at;
                        EXPECT_GT(l.output_slot_stride, 0u) << at;
                        EXPECT_EQ(l.input_pool_size, l.input_slot_stride * l.input_slot_count) << at;
                        EXPECT_EQ(l.output_pool_size, l.output_slot_stride * l.output_slot_count) << at;
                        struct P {
                            const fgsr_plane& p;
                            uint64_t w, h, bpp;
                            uint32_t format;
                            uint64_t stride;
                        } planes[] = {{l.color, w, h, color_bpp(cf), cf, l.input_slot_stride},
                                      {l.depth, w, h, 4, 0, l.input_slot_stride},
                                      {l.mv, w, h, mv_bpp(mf), mf, l.input_slot_stride},
                                      {l.output, l.output_width, l.output_height, color_bpp(in.output_format),
                                       in.output_format, l.output_slot_stride}};
                        for (const P& p : planes) {
                            EXPECT_EQ(p.p.offset % A, 0u) << at;
                            EXPECT_EQ(p.p.format, p.format) << at;
                            EXPECT_GE(uint64_t(p.p.row_pitch), p.w * p.bpp) << at;
                            EXPECT_GE(p.p.size, uint64_t(p.p.row_pitch) * p.h) << at;
                            EXPECT_LE(p.p.offset + p.p.size, p.stride) << at;
                        }
                        auto disjoint = [](const fgsr_plane& a, const fgsr_plane& b) {
                            return a.offset + a.size <= b.offset || b.offset + b.size <= a.offset;
                        };
                        EXPECT_TRUE(disjoint(l.color, l.depth)) << at;
                        EXPECT_TRUE(disjoint(l.color, l.mv)) << at;
                        EXPECT_TRUE(disjoint(l.depth, l.mv)) << at;
                        // The rings memfd holds three headers and 64 entries of each kind.
                        EXPECT_EQ(l.rings_size % 4096, 0u) << at;
                        EXPECT_GE(l.rings_size,
                                  3 * sizeof(fgsr_ring_header) +
                                      64 * (sizeof(fgsr_submit_entry) + sizeof(fgsr_completion_entry) +
                                            sizeof(fgsr_release_entry)))
                            << at;
                        EXPECT_EQ(l.reserved, 0u) << at;
                        ++checked;
                    }
    EXPECT_GT(checked, 1000u);
}

// Colour-only sessions (FGSR_SESSION_NO_MVS / NO_DEPTH, minor 2): the absent planes take no space,
// and the slot is exactly as large as the planes that remain need.
TEST(PoolLayout, ColourOnlySessionsHaveNoAbsentPlanes) {
    const uint64_t A = FGSR_PLANE_ALIGNMENT;
    for (uint32_t w : {1u, 33u, 1280u})
        for (uint32_t h : {1u, 17u, 720u})
            for (uint32_t flags : {0u, FGSR_SESSION_NO_MVS, FGSR_SESSION_NO_DEPTH,
                                   FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH}) {
                fgsr_session_desc in = base_desc();
                in.width = w;
                in.height = h;
                in.color_format = FGSR_COLOR_RGBA8_SRGB;
                in.mv_format = FGSR_MV_RG32F;
                in.flags = flags;
                fgsr_session_desc d{};
                char reason[128];
                ASSERT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof(reason)), FGSR_STATUS_OK)
                    << reason;
                const fgsr_pool_layout l = fgsr_pool_layout_for(&d);
                const std::string at =
                    std::to_string(w) + "x" + std::to_string(h) + " flags " + std::to_string(flags);
                const uint64_t color = (uint64_t(w) * h * 4 + A - 1) / A * A;
                const uint64_t depth =
                    (flags & FGSR_SESSION_NO_DEPTH) ? 0 : (uint64_t(w) * h * 4 + A - 1) / A * A;
                const uint64_t mv = (flags & FGSR_SESSION_NO_MVS) ? 0 : (uint64_t(w) * h * 8 + A - 1) / A * A;
                EXPECT_EQ(l.input_slot_stride, color + depth + mv) << at;
                if (flags & FGSR_SESSION_NO_DEPTH) {
                    EXPECT_EQ(l.depth.size, 0u) << at;
                    EXPECT_EQ(l.depth.row_pitch, 0u) << at;
                    EXPECT_EQ(l.depth.offset, 0u) << at;
                } else {
                    EXPECT_EQ(l.depth.size, uint64_t(w) * h * 4) << at;
                    EXPECT_EQ(l.depth.offset, color) << at;
                }
                if (flags & FGSR_SESSION_NO_MVS) {
                    EXPECT_EQ(l.mv.size, 0u) << at;
                    EXPECT_EQ(l.mv.row_pitch, 0u) << at;
                    EXPECT_EQ(l.mv.format, uint32_t(FGSR_MV_RG32F)) << at;
                } else {
                    EXPECT_EQ(l.mv.size, uint64_t(w) * h * 8) << at;
                    EXPECT_EQ(l.mv.offset, color + depth) << at;
                }
            }
    // Bits beyond the known ones are still refused.
    fgsr_session_desc in = base_desc(), d{};
    in.flags = FGSR_SESSION_COLOUR_AGREE << 1;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, nullptr, 0), FGSR_STATUS_INVALID_ARGUMENT);
    // Correction of given vectors needs given vectors, and no super resolution.
    char reason[160];
    in.flags = FGSR_SESSION_CORRECT_MVS;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(reason).find("scale 1"), std::string::npos) << reason;
    in.scale = 1.f;
    in.modes = FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.flags = FGSR_SESSION_CORRECT_MVS | FGSR_SESSION_NO_MVS;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(reason).find("CORRECT_MVS"), std::string::npos) << reason;
    // Interpolation by agreement (minor 7) adds a field from colour to given vectors: not with
    // NO_MVS; with super resolution only for sessions that generate frames (minor 8: ISR, ESR);
    // with the correction of the given vectors it may.
    in.flags = FGSR_SESSION_COLOUR_AGREE;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.flags = FGSR_SESSION_COLOUR_AGREE | FGSR_SESSION_CORRECT_MVS;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.flags = FGSR_SESSION_COLOUR_AGREE | FGSR_SESSION_NO_MVS | FGSR_SESSION_NO_DEPTH;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(reason).find("COLOUR_AGREE"), std::string::npos) << reason;
    EXPECT_NE(std::string(reason).find("NO_MVS"), std::string::npos) << reason;
    in.flags = FGSR_SESSION_COLOUR_AGREE;
    in.scale = 2.f;
    in.modes = FGSR_MODE_SR;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(reason).find("COLOUR_AGREE"), std::string::npos) << reason;
    EXPECT_NE(std::string(reason).find("FGSR_MODE_INTERPOLATE"), std::string::npos) << reason;
    in.modes = FGSR_MODE_SR | FGSR_MODE_INTERPOLATE;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.modes = FGSR_MODE_SR | FGSR_MODE_EXTRAPOLATE;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.modes = FGSR_MODE_EXTRAPOLATE;
    in.scale = 1.5f;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    in.scale = 1.f;
    in.modes = FGSR_MODE_INTERPOLATE | FGSR_MODE_EXTRAPOLATE;
    // Fast motion estimation is for sessions that estimate motion: only with NO_MVS.
    in.flags = FGSR_SESSION_FAST_MOTION;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(reason).find("FAST_MOTION"), std::string::npos) << reason;
    EXPECT_NE(std::string(reason).find("NO_MVS"), std::string::npos) << reason;
    in.flags = FGSR_SESSION_FAST_MOTION | FGSR_SESSION_NO_MVS;
    EXPECT_EQ(fgsr_session_desc_normalize(&in, &d, reason, sizeof reason), FGSR_STATUS_OK) << reason;
    EXPECT_EQ(d.flags, FGSR_SESSION_FAST_MOTION | FGSR_SESSION_NO_MVS);
}

TEST(Rings, HelpersAndLoopsAgreeAcrossWrapAround) {
    constexpr uint32_t cap = 4;
    alignas(64) std::byte memory[16384]{};
    ASSERT_GE(sizeof(memory), fgsr_rings_layout_for(cap).total_size);
    fgsr::ipc::Rings rings = fgsr::ipc::Rings::at(memory, cap);
    auto& ring = rings.release;
    uint64_t head = 0, tail = 0, seen_head = 0;
    EXPECT_EQ(ring.free_space(head), int64_t(cap));
    EXPECT_EQ(fgsr_ring_available(ring.header, tail), 0u);
    // The slot of a position wraps at the capacity.
    EXPECT_EQ(fgsr_ring_slot(ring.entries, sizeof(fgsr_release_entry), 5, cap),
              static_cast<void*>(&ring.entries[1]));
    std::vector<uint32_t> got;
    uint32_t next = 0;
    for (int round = 0; round < 5; ++round) {
        while (ring.free_space(head) > 0) ring.push(head, fgsr_release_entry{next++, 0});
        EXPECT_EQ(ring.free_space(head), 0);
        EXPECT_EQ(fgsr_ring_available(ring.header, tail), uint64_t(cap));
        EXPECT_EQ(fgsr::ipc::drain(ring, tail, seen_head,
                                   [&](const fgsr_release_entry& e) {
                                       got.push_back(e.output_slot);
                                       return true;
                                   }),
                  fgsr::ipc::Drain::done);
        EXPECT_EQ(seen_head, head);
        EXPECT_EQ(tail, head);
        EXPECT_EQ(fgsr_ring_load_tail(ring.header), tail);
    }
    ASSERT_EQ(got.size(), size_t(5 * cap));
    for (uint32_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], i);

    // A consumer stop leaves the rest; entries up to the stopping one are consumed.
    ring.push(head, fgsr_release_entry{100, 0});
    ring.push(head, fgsr_release_entry{101, 0});
    EXPECT_EQ(fgsr::ipc::drain(ring, tail, seen_head, [](const fgsr_release_entry&) { return false; }),
              fgsr::ipc::Drain::stopped);
    EXPECT_EQ(fgsr_ring_available(ring.header, tail), 1u);

    // A producer more than the capacity ahead is an overrun; nothing is consumed.
    fgsr_ring_publish(ring.header, tail + cap + 1);
    const uint64_t before = tail;
    EXPECT_EQ(fgsr::ipc::drain(ring, tail, seen_head, [](const fgsr_release_entry&) { return true; }),
              fgsr::ipc::Drain::overrun);
    EXPECT_EQ(tail, before);
    EXPECT_EQ(seen_head, before + cap + 1);

    // A consumer tail beyond the producer's head, or more than the capacity behind: negative room.
    fgsr_ring_header& h = *rings.submit.header;
    fgsr_ring_consume(&h, 10);
    EXPECT_LT(fgsr_ring_free_space(&h, 9, cap), 0);
    EXPECT_EQ(fgsr_ring_free_space(&h, 10, cap), int64_t(cap));
    EXPECT_EQ(fgsr_ring_free_space(&h, 14, cap), 0);
    EXPECT_LT(fgsr_ring_free_space(&h, 15, cap), 0);
}
