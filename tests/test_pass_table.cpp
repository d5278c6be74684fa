// The pass table (fgsr/passes.h): the protocol's pass ids and names (fgsr_pass_id,
// fgsr_pass_name) and the engine's (fgsr::PassId, pass_name) agree, the public numbering is the
// one of protocol minor 1, and every timing the engine reports carries the id of its name.
#include "engine_fixture.hpp"

#include <fgsr/engine/passes.hpp>
#include <fgsr/protocol.h>

#include <string>

using namespace fgsr;

TEST(PassTable, ProtocolAndEngineAgree) {
    ASSERT_EQ(uint32_t(FGSR_PASS_COUNT_), kPassCount);
    for (uint32_t i = 0; i < FGSR_PASS_COUNT_; ++i) {
        EXPECT_EQ(std::string(fgsr_pass_name(i)), std::string(pass_name(PassId(i)))) << "pass " << i;
        EXPECT_NE(std::string(fgsr_pass_name(i)), "unknown") << "pass " << i;
    }
    for (uint32_t i : {uint32_t(FGSR_PASS_COUNT_), 64u, 0xffffffffu}) {
        EXPECT_STREQ(fgsr_pass_name(i), "unknown");
        EXPECT_EQ(pass_name(PassId(i)), "unknown");
    }
}

TEST(PassTable, PublicNumberingIsFixed) {
    struct Known {
        uint32_t protocol;
        PassId engine;
        uint32_t value;
        const char* name;
    };
    const Known known[] = {
        {FGSR_PASS_INGEST, PassId::ingest, 0, "ingest"},
        {FGSR_PASS_SPLAT, PassId::splat, 1, "splat"},
        {FGSR_PASS_REFINE, PassId::refine, 2, "refine"},
        {FGSR_PASS_DISOCC, PassId::disocc, 3, "disocc"},
        {FGSR_PASS_WARP, PassId::warp, 4, "warp"},
        {FGSR_PASS_BLEND, PassId::blend, 5, "blend"},
        {FGSR_PASS_GENERATE, PassId::generate, 6, "generate"},
        {FGSR_PASS_SR, PassId::sr, 7, "sr"},
        {FGSR_PASS_GENERATE_SR, PassId::generate_sr, 8, "generate_sr"},
        {FGSR_PASS_CLASSIFY, PassId::classify, 9, "classify"},
        {FGSR_PASS_DENOISE, PassId::denoise, 10, "denoise"},
        {FGSR_PASS_LUMA, PassId::luma, 11, "luma"},
        {FGSR_PASS_MATCH, PassId::match, 12, "match"},
        {FGSR_PASS_FLOW, PassId::flow, 13, "flow"},
        {FGSR_PASS_POLISH, PassId::polish, 14, "polish"},
        {FGSR_PASS_AGREE, PassId::agree, 15, "agree"},
    };
    ASSERT_EQ(std::size(known), size_t(FGSR_PASS_COUNT_));
    EXPECT_EQ(uint32_t(FGSR_PASS_COUNT_), 16u);
    for (const Known& k : known) {
        EXPECT_EQ(k.protocol, k.value) << k.name;
        EXPECT_EQ(uint32_t(k.engine), k.value) << k.name;
        EXPECT_STREQ(fgsr_pass_name(k.protocol), k.name);
        EXPECT_EQ(pass_name(k.engine), k.name);
    }
}

namespace {

void expect_ids_match_names(const std::vector<PassTiming>& passes, const char* what) {
    EXPECT_FALSE(passes.empty()) << what;
    for (const PassTiming& p : passes) {
        EXPECT_LT(uint32_t(p.pass), kPassCount) << what << ": " << p.name;
        EXPECT_EQ(p.name, pass_name(p.pass)) << what;
        EXPECT_EQ(p.name, fgsr_pass_name(uint32_t(p.pass))) << what;
    }
}

} // namespace

// Every path that reports timings: ingest, fused, separate, tiled, super resolution with denoise.
TEST(PassTable, TimingsCarryTheirPassId) {
    using test::engine;
    const uint32_t w = 64, h = 48;
    const FrameFormat fmt = test::internal_format(w, h);
    const test::RawFrame a = test::random_frame(w, h, 1, 1.f), b = test::random_frame(w, h, 2, 1.f);
    for (int mode = 0; mode < 4; ++mode) {
        Params p;
        p.skip_tiles = mode == 2;
        p.separate_passes = mode == 1;
        if (mode == 3) p.scale = 2.f;
        auto s = engine().create_session(fmt, p);
        ASSERT_TRUE(s) << s.error().message;
        ASSERT_TRUE((*s)->submit(a.view()));
        ASSERT_TRUE((*s)->submit(b.view()));
        const PassTiming ingest = (*s)->last_ingest_timing();
        EXPECT_EQ(ingest.pass, PassId::ingest);
        EXPECT_EQ(ingest.name, "ingest");
        const float alpha = 0.5f;
        auto out = (*s)->interpolate(std::span<const float>(&alpha, 1));
        ASSERT_TRUE(out) << out.error().message;
        expect_ids_match_names(out->front().passes, "interpolate");
        auto ex = (*s)->extrapolate(std::span<const float>(&alpha, 1));
        ASSERT_TRUE(ex) << ex.error().message;
        expect_ids_match_names(ex->front().passes, "extrapolate");
        if (mode == 3) {
            auto sr = (*s)->super_resolved();
            ASSERT_TRUE(sr) << sr.error().message;
            expect_ids_match_names(sr->passes, "super_resolved");
            EXPECT_EQ(sr->passes.back().pass, PassId::sr);
        }
    }
    test::expect_no_validation_errors();
}
