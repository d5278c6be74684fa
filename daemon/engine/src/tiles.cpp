// Tile skipping (shaders/classify.h, tiles.h): the tile geometry, the tile sets (flags and lists)
// and their headers, the classify pass, the tiled recordings of sr and of a generated frame, and
// the skip bookkeeping (when to classify, the tile counts of the passes).
#include <fgsr/engine/params.hpp>

#include "session.hpp"

#include <algorithm>
#include <cmath>

namespace fgsr {

namespace {

// Tile side when Params::tile_size is 0 (measured on lavapipe, docs/TILES.md).
constexpr uint32_t kDefaultTile = 16;
constexpr uint32_t kMinTile = 8;
static_assert(FGSR_CLASSIFY_SPAN_CPU % kMinTile == 0,
              "classify segments are whole sub-segments (classify.comp)");

// Invocations along one side of the square each listed LR tile of `tile` pixels gets in a pass at
// `scale` x resolution (shaders/tiles.h, listed_output_pixel).
uint32_t output_span(uint32_t tile, float scale) {
    return scale == 1.f ? tile : uint32_t(std::ceil(double(tile) * double(scale))) + 3;
}

// The TILED_EXTRA bindings of a tiled pass: the list it iterates, the flags, and the list splat
// appends the static tiles it dirties to (the other passes do not write it: unused).
template <PassId P, uint32_t Base = pass_bindings(P)>
At<Base + TILED_LIST, Base + TILED_FLAGS, Base + TILED_APPEND>
tile_list(const vk::Buffer& list, const Session::Impl::TileSet& ts, bool appends) {
    return {{list, ts.flags, appends ? BufRef(ts.generate) : unused(ts.generate)}};
}

// classify's outputs: the flags and the three lists.
At<CLASSIFY_FLAGS, CLASSIFY_LIST_WORK, CLASSIFY_LIST_GENERATE, CLASSIFY_LIST_STATIC>
tile_lists(const Session::Impl::TileSet& ts) {
    return {{ts.flags, ts.work, ts.generate, ts.statics}};
}

} // namespace

uint32_t Session::Impl::tile_side() const {
    return params.tile_size ? params.tile_size : kDefaultTile;
}
uint32_t Session::Impl::tiles_x() const {
    return (format.width + tile_side() - 1) / tile_side();
}
uint32_t Session::Impl::tiles_total() const {
    return tiles_x() * ((format.height + tile_side() - 1) / tile_side());
}

Result<void> Session::Impl::ensure_tile_sets(size_t count) {
    // Sized for the smallest tile side, so that Params::tile_size may change between calls.
    const VkDeviceSize max_tiles =
        VkDeviceSize((format.width + kMinTile - 1) / kMinTile) * ((format.height + kMinTile - 1) / kMinTile);
    const VkDeviceSize list_bytes = (TILE_LIST_HEADER + max_tiles) * 4;
    while (tiles.sets.size() < count) {
        TileSet t;
        for (auto [b, bytes] : {std::pair{&t.flags, max_tiles * 4}, std::pair{&t.work, list_bytes},
                                std::pair{&t.generate, list_bytes}, std::pair{&t.statics, list_bytes}}) {
            auto r = vk::Buffer::create(*ctx, bytes, true);
            if (!r) return r.error();
            *b = std::move(*r);
        }
        tiles.sets.push_back(std::move(t));
    }
    return {};
}

// Records the header of each list of a tile set: empty, dispatch (0, 1, 1), tile side, and the
// invocation span per listed tile of the passes over the work list and over the others.
void Session::Impl::reset_lists(const TileSet& t, uint32_t work_span, uint32_t output_span) {
    const uint32_t side = tile_side();
    const auto work = empty_list_header(side, work_span), out = empty_list_header(side, output_span);
    vkCmdUpdateBuffer(rec.cmd(), t.work.handle(), 0, sizeof(work), work.data());
    vkCmdUpdateBuffer(rec.cmd(), t.generate.handle(), 0, sizeof(out), out.data());
    vkCmdUpdateBuffer(rec.cmd(), t.statics.handle(), 0, sizeof(out), out.data());
}

uint32_t Session::Impl::list_count(const vk::Buffer& list) {
    return static_cast<const uint32_t*>(list.mapped())[3];
}

// The classify dispatches (both stages, shaders/classify.comp) after the lists' reset: per row
// segment (1 pixel on GPUs, FGSR_CLASSIFY_SPAN_CPU on CPU devices), then per tile. Generate mode
// also empties the keys for the tiled splat.
Result<void> Session::Impl::classify(gpu::ClassifyParams c, const Slots<PassId::classify>& s,
                                     bool empty_keys) {
    vkCmdFillBuffer(rec.cmd(), s[CLASSIFY_FLAGS].buffer, 0, VK_WHOLE_SIZE, 0u);
    if (c.mode == CLASSIFY_GENERATE && empty_keys)
        vkCmdFillBuffer(rec.cmd(), s[GEN_KEYS].buffer, s[GEN_KEYS].offset, s[GEN_KEYS].range, 0xffffffffu);
    rec.barrier();
    c.stage = 0;
    const bool cpu = rec.group() == 32;
    const Variant pixels = c.mode == CLASSIFY_SR       ? Variant::classify_sr
                           : cpu && c.g.width % 4 == 0 ? Variant::classify_gen_quad
                                                       : Variant::classify_gen;
    FGSR_TRY(
        rec.dispatch_pixels(pixels, s, &c, groups(c.g.width, cpu ? FGSR_CLASSIFY_SPAN_CPU : 1u), c.g.height));
    rec.barrier();
    c.stage = 1;
    FGSR_TRY(
        rec.dispatch_pixels(Variant::classify, s, &c, groups(c.g.width, c.tile), groups(c.g.height, c.tile)));
    return {};
}

// Records the sr pass of a frame with history with tile skipping: classify in sr mode, then sr
// over the moving tiles and its static form over the others. Writes timestamp `query` (after
// classify); the caller writes the one after sr.
Result<void> Session::Impl::record_sr_tiled(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                            const vk::Buffer& history, const vk::Buffer& out,
                                            uint32_t query) {
    FGSR_TRY(ensure_tile_sets(1));
    const TileSet& ts = tiles.sets[0];
    const uint32_t side = tile_side();
    const uint32_t span = output_span(side, sp.scale);
    reset_lists(ts, span, span);
    rec.barrier();
    gpu::ClassifyParams c{};
    c.g.width = format.width;
    c.g.height = format.height;
    c.g.t_depth = sp.t_depth;
    c.tile = side;
    c.mode = CLASSIFY_SR;
    c.dilate = sp.dilate;
    c.work_invocations = span * span;
    c.output_invocations = span * span;
    // sr mode reads the current vectors and depth (GEN_MV1, GEN_DEPTH1) and the previous depth
    // (GEN_DEPTH0); the generate-mode bindings it does not touch are unused.
    FGSR_TRY(classify(c, make_slots<PassId::classify>(
                             at<GEN_MV1>(f.mv), at<GEN_MV0>(unused(prev.mv)), at<GEN_DEPTH1>(f.depth),
                             at<GEN_DEPTH0>(prev.depth), at<GEN_KEYS>(unused(keys)),
                             at<GEN_MOTION>(unused(motion)), at<CLASSIFY_COLOR0>(unused(f.color)),
                             at<CLASSIFY_COLOR1>(unused(f.color)), at<CLASSIFY_OUTPUT>(unused(out)),
                             tile_lists(ts))));
    rec.barrier();
    rec.timestamp(query);
    FGSR_TRY(record_sr_noise(sp, f, prev, history, out));
    const auto in = sr_inputs(f, prev, history, out);
    FGSR_TRY(rec.dispatch_indirect(
        Variant::sr_tiled,
        make_slots<PassId::sr, Layout::TILED>(in, tile_list<PassId::sr>(ts.work, ts, false)), &sp, ts.work));
    gpu::SrParams st = sp;
    st.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
    st.dilate = 0;                              // every vector around a static pixel is zero
    FGSR_TRY(rec.dispatch_indirect(
        Variant::sr_static,
        make_slots<PassId::sr, Layout::TILED>(in, tile_list<PassId::sr>(ts.statics, ts, false)), &st,
        ts.statics));
    return {};
}

// Records generated frame k with tile skipping: classify (copy-through output of static pixels at
// input resolution, tile lists), splat over the moving tiles, then generate (or generate_sr) over
// the moving and dirtied tiles; with super resolution the static tiles that stayed clean take
// generate_sr's static form. Writes timestamps q..q+2.
Result<void> Session::Impl::record_tiled(size_t k, const gpu::GenParams& g, bool extrapolate, uint32_t& q) {
    const TileSet& ts = tiles.sets[k];
    const vk::Buffer& out = outputs[k];
    const GpuFrame& f1 = frames[size_t(newest)];
    const GpuFrame& f0 = frames[size_t(1 - newest)];
    FGSR_TRY(classify_frame(ts, g, &out));
    rec.barrier();
    rec.timestamp(q++);
    const gpu::SplatParams sp = splat_params(g, std::span<const float>(&g.alpha, 1)); // single-alpha
    FGSR_TRY(rec.dispatch_indirect(splat_variant(g, 1, true),
                                   make_slots<PassId::splat, Layout::TILED>(
                                       generated_frames(), tile_list<PassId::splat>(ts.work, ts, true)),
                                   &sp, ts.work));
    rec.barrier();
    rec.timestamp(q++);
    if (!sr() && rec.group() == 32) {
        // CPU devices: the split form (shaders/generate.comp), the splatted pixels of the listed
        // tiles, then the list of the empty ones.
        FGSR_TRY(reset_gap_list(tile_side()));
        const auto colors = At<GENERATE_COLOR0, GENERATE_COLOR1, GENERATE_OUTPUT>{{f0.color, f1.color, out}};
        constexpr uint32_t base = GENERATE_COUNT;
        using ListSlots = At<base + TILED_LIST, base + TILED_FLAGS, base + TILED_APPEND>;
        FGSR_TRY(rec.dispatch_indirect(
            extrapolate ? Variant::generate_split_tiled_extrap : Variant::generate_split_tiled,
            make_slots<PassId::generate, Layout::TILED>(generated_frames(), colors,
                                                        ListSlots{{ts.generate, ts.flags, gap_list}}),
            &g, ts.generate));
        rec.barrier();
        FGSR_TRY(rec.dispatch_indirect(
            extrapolate ? Variant::generate_rest_tiled_extrap : Variant::generate_rest_tiled,
            make_slots<PassId::generate, Layout::TILED>(generated_frames(), colors,
                                                        ListSlots{{gap_list, ts.flags, unused(gap_list)}}),
            &g, gap_list));
    } else if (!sr()) {
        const auto b = make_slots<PassId::generate, Layout::TILED>(
            generated_frames(), at<GENERATE_COLOR0>(f0.color), at<GENERATE_COLOR1>(f1.color),
            at<GENERATE_OUTPUT>(out), tile_list<PassId::generate>(ts.generate, ts, false));
        FGSR_TRY(rec.dispatch_indirect(Variant::generate_tiled, b, &g, ts.generate));
    } else {
        GenSrPush push = gen_sr_push(g);
        const auto gen = At<GENSR_COLOR0, GENSR_COLOR1, GENSR_SRC, GENSR_LUT, GENSR_OUTPUT>{
            {f0.color, f1.color, gen_sr_source(extrapolate), sr_history.lut, out}};
        FGSR_TRY(rec.dispatch_indirect(
            Variant::generate_sr_tiled,
            make_slots<PassId::generate_sr, Layout::TILED>(
                generated_frames(), gen, tile_list<PassId::generate_sr>(ts.generate, ts, false)),
            &push, ts.generate));
        push.s.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
        FGSR_TRY(rec.dispatch_indirect(
            Variant::generate_sr_static,
            make_slots<PassId::generate_sr, Layout::TILED>(
                generated_frames(), gen, tile_list<PassId::generate_sr>(ts.statics, ts, false)),
            &push, ts.statics));
    }
    rec.barrier();
    rec.timestamp(q++);
    return {};
}

Result<void> Session::Impl::reset_gap_list(uint32_t side) {
    if (!gap_list.handle()) {
        auto r = vk::Buffer::create(*ctx, (VkDeviceSize(TILE_LIST_HEADER) + n) * 4, false);
        if (!r) return r.error();
        gap_list = std::move(*r);
    }
    const auto empty = empty_list_header(side, 1); // entries are pixels, x | y << 16
    vkCmdUpdateBuffer(rec.cmd(), gap_list.handle(), 0, sizeof(empty), empty.data());
    rec.barrier();
    return {};
}

Session::Impl::GenTiles Session::Impl::classify_generate() {
    const bool due = tiles.gen_backoff.due();
    if (!params.skip_tiles || (separate() && !sr()) || !due) return GenTiles::none;
    return tiles.gen_backoff.missed() ? GenTiles::probe : GenTiles::tiled;
}

// The generate-mode classify of a generated frame into tile set `ts`, after the lists' reset. With
// `out`, the tiled recording's: the copy-through of the static pixels into it (without super
// resolution) and the keys emptied for the tiled splat. Without, a probe's: the lists only.
Result<void> Session::Impl::classify_frame(const TileSet& ts, const gpu::GenParams& g,
                                           const vk::Buffer* out) {
    const GpuFrame& f1 = frames[size_t(newest)];
    const GpuFrame& f0 = frames[size_t(1 - newest)];
    const uint32_t side = tile_side();
    const float scale = sr() ? float(out_w) / float(format.width) : 1.f;
    const uint32_t span = output_span(side, scale);
    reset_lists(ts, side, span);
    rec.barrier();
    gpu::ClassifyParams c{};
    c.g = g;
    c.tile = side;
    c.mode = CLASSIFY_GENERATE;
    c.write_output = out && !sr() ? 1u : 0u;
    c.work_invocations = side * side;
    c.output_invocations = span * span;
    const BufRef output = out ? BufRef(*out) : unused(outputs[0]);
    return classify(c,
                    make_slots<PassId::classify>(generated_frames(), at<CLASSIFY_COLOR0>(f0.color),
                                                 at<CLASSIFY_COLOR1>(f1.color), at<CLASSIFY_OUTPUT>(output),
                                                 tile_lists(ts)),
                    out != nullptr);
}

// A probe (classify_generate): classify_frame of the call's first frame into tile set 0 (which the
// caller made), before the plain passes. Writes timestamp q.
Result<void> Session::Impl::record_probe(const gpu::GenParams& g, uint32_t& q) {
    FGSR_TRY(classify_frame(tiles.sets[0], g, nullptr));
    rec.barrier();
    rec.timestamp(q++);
    return {};
}

// After a probe's fence: the tiles its classify would have let generate skip (those outside its
// generate list; the tiles a splat would dirty are not known without one).
uint32_t Session::Impl::probe_skippable() const {
    const uint32_t total = tiles_total();
    return total - std::min(total, list_count(tiles.sets[0].generate));
}

bool Session::Impl::classify_sr(bool has_history) {
    const bool due = tiles.sr_backoff.due();
    return params.skip_tiles && has_history && due;
}

// classify, splat, generate(_sr): tiles outside the lists were skipped.
void Session::Impl::count_generate_tiles(size_t k, GeneratedFrame& gf) const {
    const TileSet& ts = tiles.sets[k];
    const uint32_t total = tiles_total();
    gf.passes[0].tiles_total = gf.passes[1].tiles_total = gf.passes[2].tiles_total = total;
    gf.passes[1].tiles_skipped = total - std::min(total, list_count(ts.work));
    gf.passes[2].tiles_skipped = total - std::min(total, list_count(ts.generate));
}

bool Session::Impl::generate_worth_skipping(uint32_t skippable) const {
    return double(skippable) >= min_generate_skip_share() * double(tiles_total());
}

double Session::Impl::min_generate_skip_share() const {
    return rec.group() == 32 ? kMinSkipShareCpu : kMinSkipShare; // group 32: CPU builds
}

void Session::Impl::count_sr_tiles() {
    tiles.last_side = tile_side();
    tiles.sr_total = tiles_total();
    tiles.sr_skipped = std::min(tiles.sr_total, list_count(tiles.sets[0].statics));
    tiles.sr_backoff.classified(double(tiles.sr_skipped) >= kMinSkipShare * double(tiles.sr_total));
}

std::vector<uint32_t> Session::last_sr_tile_flags() const {
    const Impl& s = *impl_;
    if (!s.tiles.last_sr_tiled || s.tiles.sets.empty()) return {};
    const uint32_t* flags = static_cast<const uint32_t*>(s.tiles.sets[0].flags.mapped());
    return std::vector<uint32_t>(flags, flags + s.tiles.sr_total);
}

} // namespace fgsr
