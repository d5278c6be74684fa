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
template <PassId P>
void bind_list(Slots<P, Layout::TILED>& s, const vk::Buffer& list, const Session::Impl::TileSet& ts,
               bool appends) {
    constexpr uint32_t base = pass_bindings(P);
    s[base + TILED_LIST] = list;
    s[base + TILED_FLAGS] = ts.flags;
    s[base + TILED_APPEND] = appends ? BufRef(ts.generate) : unused(ts.generate);
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
    const std::array<uint32_t, TILE_LIST_HEADER> work{0, 1, 1, 0, side, work_span, 0, 0};
    const std::array<uint32_t, TILE_LIST_HEADER> out{0, 1, 1, 0, side, output_span, 0, 0};
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
Result<void> Session::Impl::classify(gpu::ClassifyParams c, const Slots<PassId::classify>& s) {
    vkCmdFillBuffer(rec.cmd(), s[CLASSIFY_FLAGS].buffer, 0, VK_WHOLE_SIZE, 0u);
    if (c.mode == CLASSIFY_GENERATE)
        vkCmdFillBuffer(rec.cmd(), s[GEN_KEYS].buffer, 0, VK_WHOLE_SIZE, 0xffffffffu);
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
    Slots<PassId::classify> cb;
    cb[GEN_MV1] = f.mv;
    cb[GEN_MV0] = unused(prev.mv);
    cb[GEN_DEPTH1] = f.depth;
    cb[GEN_DEPTH0] = prev.depth;
    cb[GEN_KEYS] = unused(keys);
    cb[GEN_MOTION] = unused(motion);
    cb[CLASSIFY_COLOR0] = unused(f.color);
    cb[CLASSIFY_COLOR1] = unused(f.color);
    cb[CLASSIFY_OUTPUT] = unused(out);
    cb[CLASSIFY_FLAGS] = ts.flags;
    cb[CLASSIFY_LIST_WORK] = ts.work;
    cb[CLASSIFY_LIST_GENERATE] = ts.generate;
    cb[CLASSIFY_LIST_STATIC] = ts.statics;
    FGSR_TRY(classify(c, cb));
    rec.barrier();
    rec.timestamp(query);
    Slots<PassId::sr, Layout::TILED> b;
    b[SR_COLOR] = f.color;
    b[SR_DEPTH] = f.depth;
    b[SR_MV] = f.mv;
    b[SR_PREV_DEPTH] = prev.depth;
    b[SR_HISTORY] = history;
    b[SR_LUT] = sr_history.lut;
    b[SR_OUTPUT] = out;
    bind_list(b, ts.work, ts, false);
    FGSR_TRY(rec.dispatch_indirect(Variant::sr_tiled, b, &sp, ts.work));
    gpu::SrParams st = sp;
    st.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
    st.dilate = 0;                              // every vector around a static pixel is zero
    bind_list(b, ts.statics, ts, false);
    FGSR_TRY(rec.dispatch_indirect(Variant::sr_static, b, &st, ts.statics));
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
    const uint32_t side = tile_side();
    const float scale = sr() ? float(out_w) / float(format.width) : 1.f;
    const uint32_t span = output_span(side, scale);
    reset_lists(ts, side, span);
    rec.barrier();
    gpu::ClassifyParams c{};
    c.g = g;
    c.tile = side;
    c.mode = CLASSIFY_GENERATE;
    c.write_output = sr() ? 0u : 1u;
    c.work_invocations = side * side;
    c.output_invocations = span * span;
    Slots<PassId::classify> cb;
    bind_generated_frames(cb);
    cb[CLASSIFY_COLOR0] = f0.color;
    cb[CLASSIFY_COLOR1] = f1.color;
    cb[CLASSIFY_OUTPUT] = out; // written only without super resolution (write_output)
    cb[CLASSIFY_FLAGS] = ts.flags;
    cb[CLASSIFY_LIST_WORK] = ts.work;
    cb[CLASSIFY_LIST_GENERATE] = ts.generate;
    cb[CLASSIFY_LIST_STATIC] = ts.statics;
    FGSR_TRY(classify(c, cb));
    rec.barrier();
    rec.timestamp(q++);
    Slots<PassId::splat, Layout::TILED> sb;
    bind_generated_frames(sb);
    bind_list(sb, ts.work, ts, true);
    FGSR_TRY(rec.dispatch_indirect(Variant::splat_tiled, sb, &g, ts.work));
    rec.barrier();
    rec.timestamp(q++);
    if (!sr()) {
        Slots<PassId::generate, Layout::TILED> b;
        bind_generated_frames(b);
        b[GENERATE_COLOR0] = f0.color;
        b[GENERATE_COLOR1] = f1.color;
        b[GENERATE_OUTPUT] = out;
        bind_list(b, ts.generate, ts, false);
        FGSR_TRY(rec.dispatch_indirect(Variant::generate_tiled, b, &g, ts.generate));
    } else {
        GenSrPush push = gen_sr_push(g);
        Slots<PassId::generate_sr, Layout::TILED> b;
        bind_generated_frames(b);
        b[GENSR_COLOR0] = f0.color;
        b[GENSR_COLOR1] = f1.color;
        b[GENSR_SRC] = gen_sr_source(extrapolate);
        b[GENSR_LUT] = sr_history.lut;
        b[GENSR_OUTPUT] = out;
        bind_list(b, ts.generate, ts, false);
        FGSR_TRY(rec.dispatch_indirect(Variant::generate_sr_tiled, b, &push, ts.generate));
        push.s.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
        bind_list(b, ts.statics, ts, false);
        FGSR_TRY(rec.dispatch_indirect(Variant::generate_sr_static, b, &push, ts.statics));
    }
    rec.barrier();
    rec.timestamp(q++);
    return {};
}

bool Session::Impl::classify_generate() {
    const bool tiled =
        params.skip_tiles && !(params.separate_passes && !sr()) && tiles.gen_unclassified_left == 0;
    if (tiles.gen_unclassified_left > 0) --tiles.gen_unclassified_left;
    return tiled;
}

bool Session::Impl::classify_sr(bool has_history) {
    const bool tiled = params.skip_tiles && has_history && tiles.sr_unclassified_left == 0;
    if (tiles.sr_unclassified_left > 0) --tiles.sr_unclassified_left;
    return tiled;
}

// classify, splat, generate(_sr): tiles outside the lists were skipped.
void Session::Impl::count_generate_tiles(size_t k, GeneratedFrame& gf) {
    const TileSet& ts = tiles.sets[k];
    const uint32_t total = tiles_total();
    gf.passes[0].tiles_total = gf.passes[1].tiles_total = gf.passes[2].tiles_total = total;
    gf.passes[1].tiles_skipped = total - std::min(total, list_count(ts.work));
    gf.passes[2].tiles_skipped = total - std::min(total, list_count(ts.generate));
    if (double(gf.passes[2].tiles_skipped) < kMinSkipShare * double(total))
        tiles.gen_unclassified_left = kUnclassifiedRun;
}

void Session::Impl::count_sr_tiles() {
    tiles.last_side = tile_side();
    tiles.sr_total = tiles_total();
    tiles.sr_skipped = std::min(tiles.sr_total, list_count(tiles.sets[0].statics));
    if (double(tiles.sr_skipped) < kMinSkipShare * double(tiles.sr_total))
        tiles.sr_unclassified_left = kUnclassifiedRun;
}

std::vector<uint32_t> Session::last_sr_tile_flags() const {
    const Impl& s = *impl_;
    if (!s.tiles.last_sr_tiled || s.tiles.sets.empty()) return {};
    const uint32_t* flags = static_cast<const uint32_t*>(s.tiles.sets[0].flags.mapped());
    return std::vector<uint32_t>(flags, flags + s.tiles.sr_total);
}

} // namespace fgsr
