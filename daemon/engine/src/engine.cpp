#include <fgsr/core/clock.hpp>
#include <fgsr/engine/engine.hpp>
#include <fgsr/engine/lut.hpp>
#include <fgsr/engine/reference.hpp>

#include "bindings.h"
#include "vk.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <ctime>
#include <initializer_list>

namespace fgsr {

namespace {

constexpr uint32_t kMaxAlphas = 64;
constexpr uint32_t kQueriesPerFrame = 8; // start + up to 5 passes, rounded up

enum PassId : uint32_t {
    kIngest,
    kSplat,
    kRefine,
    kDisocc,
    kWarp,
    kBlend,
    kGenerate,
    kSr,
    kGenerateSr,
    kDenoise,
    kPassCount
};
constexpr std::array<const char*, kPassCount> kPassNames = {
    "ingest", "splat", "refine", "disocc", "warp", "blend", "generate", "sr", "generate_sr", "denoise"};
constexpr std::array<uint32_t, kPassCount> kPassBindings = {
    INGEST_COUNT, SPLAT_COUNT,    REFINE_COUNT, DISOCC_COUNT, WARP_COUNT,
    BLEND_COUNT,  GENERATE_COUNT, SR_COUNT,     GENSR_COUNT,  DENOISE_COUNT};
// generate_sr's push block is GenParams followed by SrParams.
struct GenSrPush {
    gpu::GenParams g;
    gpu::SrParams s;
};
static_assert(offsetof(GenSrPush, s) == sizeof(gpu::GenParams) && sizeof(GenSrPush) <= 128);
constexpr std::array<uint32_t, kPassCount> kPassPush = {
    sizeof(gpu::IngestParams), sizeof(gpu::GenParams),    sizeof(gpu::GenParams), sizeof(gpu::GenParams),
    sizeof(gpu::GenParams),    sizeof(gpu::GenParams),    sizeof(gpu::GenParams), sizeof(gpu::SrParams),
    sizeof(GenSrPush),         sizeof(gpu::DenoiseParams)};

// Passes of tile skipping (shaders/classify.h, tiles.h) and ingest's per-format builds, numbered
// after the others; the variants are timed under their base pass's name (classify's as "classify").
enum TilePassId : uint32_t {
    kClassify = uint32_t(kPassCount),
    kSplatTiled,
    kGenerateTiled,
    kSrTiled,
    kSrStatic,
    kGenerateSrTiled,
    kGenerateSrStatic,
    kClassifyGen,     // classify's stage 0 (per pixel) in generate mode; kClassify is stage 1
    kClassifySr,      // ... in sr mode
    kClassifyGenQuad, // ... in generate mode, 4 pixels per access (CPU devices, width % 4 == 0)
    kIngestFormats,   // ingest with fixed formats: + 2 * ColorFormat + MvFormat (6 builds)
    kAllPassCount = kIngestFormats + 6
};
struct TilePassInfo {
    const char* shader; // embedded "<shader>_g<group>"
    PassId base;        // timing name and bindings before the TILED_EXTRA ones
};
constexpr std::array<TilePassInfo, uint32_t(kAllPassCount) - uint32_t(kPassCount)> kTilePasses = {
    {{"classify", kIngest},
     {"splat_tiled", kSplat},
     {"generate_tiled", kGenerate},
     {"sr_tiled", kSr},
     {"sr_static", kSr},
     {"generate_sr_tiled", kGenerateSr},
     {"generate_sr_static", kGenerateSr},
     {"classify_gen", kIngest},
     {"classify_sr", kIngest},
     {"classify_gen_quad", kIngest},
     {"ingest_c0_m0", kIngest},
     {"ingest_c0_m1", kIngest},
     {"ingest_c1_m0", kIngest},
     {"ingest_c1_m1", kIngest},
     {"ingest_c2_m0", kIngest},
     {"ingest_c2_m1", kIngest}}};
bool is_classify(uint32_t p) {
    return p == kClassify || p == kClassifyGen || p == kClassifySr || p == kClassifyGenQuad;
}
const char* shader_name(uint32_t p) {
    return p < kPassCount ? kPassNames[p] : kTilePasses[p - kPassCount].shader;
}
const char* timing_name(uint32_t p) {
    return p < kPassCount   ? kPassNames[p]
           : is_classify(p) ? "classify"
                            : kPassNames[kTilePasses[p - kPassCount].base];
}
uint32_t pass_bindings(uint32_t p) {
    return p < kPassCount   ? kPassBindings[p]
           : is_classify(p) ? CLASSIFY_COUNT
                            : kPassBindings[kTilePasses[p - kPassCount].base] + TILED_EXTRA;
}
uint32_t pass_push(uint32_t p) {
    return p < kPassCount   ? kPassPush[p]
           : is_classify(p) ? uint32_t(sizeof(gpu::ClassifyParams))
                            : kPassPush[kTilePasses[p - kPassCount].base];
}

constexpr double kMinSkipShare = 0.25;
constexpr uint32_t kUnclassifiedRun = 7;

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

uint32_t groups(uint32_t n, uint32_t size) {
    return (n + size - 1) / size;
}

// A storage-buffer binding: a whole engine buffer, or a range of one (imported host memory).
struct BufRef {
    BufRef(const vk::Buffer* b) : buffer(b->handle()) {}
    BufRef(VkBuffer b, VkDeviceSize o, VkDeviceSize r) : buffer(b), offset(o), range(r) {}
    VkBuffer buffer;
    VkDeviceSize offset = 0;
    VkDeviceSize range = VK_WHOLE_SIZE;
};

} // namespace

struct HostMemory::Impl {
    vk::Buffer buffer;
    const std::byte* data = nullptr;
    size_t size = 0;
};
HostMemory::HostMemory(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HostMemory::~HostMemory() = default;
const std::byte* HostMemory::data() const {
    return impl_->data;
}
size_t HostMemory::size() const {
    return impl_->size;
}

struct Engine::Impl {
    std::unique_ptr<vk::Context> ctx;
    uint32_t group = 8; // workgroup side of every pass
    std::array<vk::Pipeline, kAllPassCount> pipelines;
};

Engine::Engine(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Engine::~Engine() = default;

Result<std::unique_ptr<Engine>> Engine::create(const DeviceOptions& options) {
    auto impl = std::make_unique<Impl>();
    auto ctx = vk::create_context(options);
    if (!ctx) return ctx.error();
    impl->ctx = std::move(*ctx);
    // Measured on lavapipe (2 cores, 1080p interpolation): 8x8 groups 364 ms, 16x16 157 ms,
    // 32x32 28 ms; its cost per workgroup dominates, so CPU devices get the 32x32 build.
    if (impl->ctx->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU &&
        impl->ctx->props.limits.maxComputeWorkGroupInvocations >= 1024 &&
        impl->ctx->props.limits.maxComputeWorkGroupSize[0] >= 32 &&
        impl->ctx->props.limits.maxComputeWorkGroupSize[1] >= 32)
        impl->group = 32;
    for (uint32_t p = 0; p < kAllPassCount; ++p) {
        const uint32_t push = pass_push(p);
        const std::string shader = std::string(shader_name(p)) + "_g" + std::to_string(impl->group);
        auto pipe = vk::Pipeline::create(*impl->ctx, shader, pass_bindings(p), push);
        if (!pipe) return pipe.error();
        impl->pipelines[p] = std::move(*pipe);
    }
    return std::unique_ptr<Engine>(new Engine(std::move(impl)));
}

std::string Engine::device_name() const {
    return impl_->ctx->props.deviceName;
}
bool Engine::is_cpu_device() const {
    return impl_->ctx->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}
uint64_t Engine::validation_errors() const {
    return impl_->ctx->validation_errors.load();
}
bool Engine::calibrated_time() const {
    return impl_->ctx->get_calibrated_timestamps != nullptr;
}
size_t Engine::host_import_alignment() const {
    return impl_->ctx->host_import ? size_t(impl_->ctx->host_import_alignment) : 0;
}
Result<std::unique_ptr<HostMemory>> Engine::import_host_memory(void* data, size_t size) {
    auto b = vk::Buffer::import_host(*impl_->ctx, data, size);
    if (!b) return b.error();
    auto impl = std::make_unique<HostMemory::Impl>();
    impl->buffer = std::move(*b);
    impl->data = static_cast<const std::byte*>(data);
    impl->size = size;
    return std::unique_ptr<HostMemory>(new HostMemory(std::move(impl)));
}
Result<std::vector<std::string>> Engine::list_devices() {
    return vk::enumerate_devices();
}

struct Session::Impl {
    Engine::Impl* engine = nullptr;
    vk::Context* ctx = nullptr;
    FrameFormat format;
    Params params;
    size_t n = 0;

    // Client planes are copied here, then ingested.
    vk::Buffer color_raw, depth_raw, mv_raw;
    struct GpuFrame {
        vk::Buffer color, depth, mv;
        bool has_mv = false;
    };
    std::array<GpuFrame, 2> frames;
    int newest = 1; // index into frames of frame 1
    uint64_t submitted = 0;
    PassTiming ingest_timing{"ingest"};
    PassTiming sr_timing{"sr"};
    // Clock pairing of the last timed submission: GPU tick calib_tick is CLOCK_MONOTONIC calib_ns.
    uint64_t calib_tick = 0, calib_ns = 0;
    float jitter_x = 0, jitter_y = 0; // of the newest frame

    // Super resolution: output size, ping-pong history (the newest output is hr[hr_newest]), LUT.
    uint32_t out_w = 0, out_h = 0;
    std::array<vk::Buffer, 2> hr;
    int hr_newest = 0;
    bool hr_valid = false;
    vk::Buffer lut;
    // Params::denoise (shaders/denoise.h): the filter's scratch (copied back into the frame's
    // colour) and the noise buffer (host-visible: histogram, estimate, indirect dispatch).
    vk::Buffer color_scratch, noise;
    PassTiming denoise_timing{"denoise"};
    NoiseEstimate noise_estimate;

    // Intermediates of one generated frame, reused by each alpha in turn.
    vk::Buffer keys, motion, field, field_depth, field_state, warped_color0, warped_depth0, warped_color1,
        warped_depth1;
    std::vector<vk::Buffer> outputs; // host-visible, one per alpha of a call

    // Tile skipping (shaders/classify.h): per generated frame of a call (and index 0 for the sr
    // pass of a submit), the TILE_* flags and the tile lists, host-visible (the host writes their
    // headers in the command buffer and reads the counts after the fence).
    struct TileSet {
        vk::Buffer flags, work, generate, statics;
    };
    std::vector<TileSet> tile_sets;
    bool last_tiled = false;     // the last generated frame was classified
    bool last_sr_tiled = false;  // the last submit's sr pass was classified
    uint32_t last_tile_side = 0; // of the last classification
    uint32_t sr_tiles_total = 0, sr_tiles_skipped = 0;
    PassTiming classify_sr_timing{"classify"};
    // Classification pays only where tiles can be skipped (on lavapipe a frame with every tile
    // moving costs about 2x with it, docs/TILES.md): after a classification that found less than
    // kMinSkipShare of the tiles skippable, the next kUnclassifiedRun calls (generate) or submits
    // (sr) run every tile without classifying, then classify again. Same frames either way.
    uint32_t gen_unclassified_left = 0, sr_unclassified_left = 0;
    bool last_extrapolate = false;
    bool last_separate = false;
    size_t last_output = 0;

    VkCommandPool cmd_pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkDescriptorPool desc_pool = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;

    ~Impl() {
        if (!ctx) return;
        vkDeviceWaitIdle(ctx->device);
        if (queries) vkDestroyQueryPool(ctx->device, queries, nullptr);
        if (desc_pool) vkDestroyDescriptorPool(ctx->device, desc_pool, nullptr);
        if (fence) vkDestroyFence(ctx->device, fence, nullptr);
        if (cmd_pool) vkDestroyCommandPool(ctx->device, cmd_pool, nullptr);
    }

    Result<void> init() {
        VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pi.queueFamilyIndex = ctx->queue_family;
        FGSR_VK(vkCreateCommandPool(ctx->device, &pi, nullptr, &cmd_pool), "vkCreateCommandPool");
        VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        ai.commandPool = cmd_pool;
        ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        ai.commandBufferCount = 1;
        FGSR_VK(vkAllocateCommandBuffers(ctx->device, &ai, &cmd), "vkAllocateCommandBuffers");
        VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        FGSR_VK(vkCreateFence(ctx->device, &fi, nullptr, &fence), "vkCreateFence");
        const uint32_t max_sets = kMaxAlphas * kPassCount + 4;
        VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, max_sets * 16};
        VkDescriptorPoolCreateInfo di{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        di.maxSets = max_sets;
        di.poolSizeCount = 1;
        di.pPoolSizes = &ps;
        FGSR_VK(vkCreateDescriptorPool(ctx->device, &di, nullptr, &desc_pool), "vkCreateDescriptorPool");
        VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qi.queryCount = kMaxAlphas * kQueriesPerFrame;
        FGSR_VK(vkCreateQueryPool(ctx->device, &qi, nullptr, &queries), "vkCreateQueryPool");

        const VkDeviceSize px = n;
        auto make = [&](vk::Buffer& b, VkDeviceSize bytes, bool host) -> Result<void> {
            auto r = vk::Buffer::create(*ctx, bytes, host);
            if (!r) return r.error();
            b = std::move(*r);
            return {};
        };
        FGSR_TRY(make(color_raw, px * bytes_per_pixel(format.color_format), true));
        FGSR_TRY(make(depth_raw, px * 4, true));
        FGSR_TRY(make(mv_raw, px * bytes_per_pixel(format.mv_format), true));
        for (GpuFrame& f : frames) {
            FGSR_TRY(make(f.color, px * 8, false)); // pack_color: 4 halves
            FGSR_TRY(make(f.depth, px * 4, false));
            FGSR_TRY(make(f.mv, px * 8, false));
        }
        FGSR_TRY(make(keys, px * 8, false));
        FGSR_TRY(make(motion, px * 16, false));
        FGSR_TRY(make(field, px * 16, false));
        FGSR_TRY(make(field_depth, px * 4, false));
        FGSR_TRY(make(field_state, px * 4, false));
        FGSR_TRY(make(warped_color0, px * 16, false));
        FGSR_TRY(make(warped_depth0, px * 4, false));
        FGSR_TRY(make(warped_color1, px * 16, false));
        FGSR_TRY(make(warped_depth1, px * 4, false));
        if (sr()) {
            const VkDeviceSize hpx = VkDeviceSize(out_w) * out_h;
            for (vk::Buffer& b : hr) FGSR_TRY(make(b, hpx * 16, false));
            FGSR_TRY(make(lut, kLutSize * 4, true));
            FGSR_TRY(upload_lut());
            // Whatever Params::denoise says now: set_params may turn it on later.
            FGSR_TRY(make(color_scratch, px * 8, false));
            FGSR_TRY(make(noise, DENOISE_WORDS * 4, true));
        }
        return {};
    }

    bool sr() const { return out_w != format.width || out_h != format.height; }
    bool denoise() const { return sr() && params.denoise; }

    // Records the denoise dispatches (shaders/denoise.comp) on a frame's ingested colour, which
    // they filter in place (through the scratch) when the frame's estimate asks for it.
    Result<void> record_denoise(const vk::Buffer& color) {
        vkCmdFillBuffer(cmd, noise.handle(), 0, VK_WHOLE_SIZE, 0u);
        barrier();
        gpu::DenoiseParams d = ref::denoise_params(format, params);
        d.stage = DENOISE_HISTOGRAM;
        FGSR_TRY(dispatch(kDenoise, {&color, &color_scratch, &noise}, &d, (format.width + 1) / 2,
                          (format.height + 1) / 2));
        barrier();
        d.stage = DENOISE_LEVEL;
        FGSR_TRY(dispatch(kDenoise, {&color, &color_scratch, &noise}, &d, 1, 1));
        barrier();
        d.stage = DENOISE_FILTER;
        FGSR_TRY(bind(kDenoise, {&color, &color_scratch, &noise}, &d));
        vkCmdDispatchIndirect(cmd, noise.handle(), VkDeviceSize(DENOISE_DISPATCH) * 4);
        barrier();
        d.stage = DENOISE_COPY;
        FGSR_TRY(bind(kDenoise, {&color_scratch, &color, &noise}, &d));
        vkCmdDispatchIndirect(cmd, noise.handle(), VkDeviceSize(DENOISE_DISPATCH) * 4);
        return {};
    }

    uint32_t tile_side() const { return params.tile_size ? params.tile_size : kDefaultTile; }
    uint32_t tiles_x() const { return (format.width + tile_side() - 1) / tile_side(); }
    uint32_t tiles_total() const { return tiles_x() * ((format.height + tile_side() - 1) / tile_side()); }

    Result<void> ensure_tile_sets(size_t count) {
        // Sized for the smallest tile side, so that Params::tile_size may change between calls.
        const VkDeviceSize max_tiles = VkDeviceSize((format.width + kMinTile - 1) / kMinTile) *
                                       ((format.height + kMinTile - 1) / kMinTile);
        const VkDeviceSize list_bytes = (TILE_LIST_HEADER + max_tiles) * 4;
        while (tile_sets.size() < count) {
            TileSet t;
            for (auto [b, bytes] : {std::pair{&t.flags, max_tiles * 4}, std::pair{&t.work, list_bytes},
                                    std::pair{&t.generate, list_bytes}, std::pair{&t.statics, list_bytes}}) {
                auto r = vk::Buffer::create(*ctx, bytes, true);
                if (!r) return r.error();
                *b = std::move(*r);
            }
            tile_sets.push_back(std::move(t));
        }
        return {};
    }

    // Records the header of each list of a tile set: empty, dispatch (0, 1, 1), tile side, and the
    // invocation span per listed tile of the passes over the work list and over the others.
    void reset_lists(const TileSet& t, uint32_t work_span, uint32_t output_span) {
        const uint32_t side = tile_side();
        const std::array<uint32_t, TILE_LIST_HEADER> work{0, 1, 1, 0, side, work_span, 0, 0};
        const std::array<uint32_t, TILE_LIST_HEADER> out{0, 1, 1, 0, side, output_span, 0, 0};
        vkCmdUpdateBuffer(cmd, t.work.handle(), 0, sizeof(work), work.data());
        vkCmdUpdateBuffer(cmd, t.generate.handle(), 0, sizeof(out), out.data());
        vkCmdUpdateBuffer(cmd, t.statics.handle(), 0, sizeof(out), out.data());
    }

    static uint32_t list_count(const vk::Buffer& list) {
        return static_cast<const uint32_t*>(list.mapped())[3];
    }

    // The classify dispatches (both stages, shaders/classify.comp) after the lists' reset: per
    // row segment (1 pixel on GPUs, FGSR_CLASSIFY_SPAN_CPU on CPU devices), then per tile. The flags are
    // buffers[CLASSIFY_FLAGS]; generate mode also empties the keys (buffers[GEN_KEYS]) for the tiled splat.
    Result<void> classify(gpu::ClassifyParams c, std::initializer_list<BufRef> buffers) {
        vkCmdFillBuffer(cmd, buffers.begin()[CLASSIFY_FLAGS].buffer, 0, VK_WHOLE_SIZE, 0u);
        if (c.mode == CLASSIFY_GENERATE)
            vkCmdFillBuffer(cmd, buffers.begin()[GEN_KEYS].buffer, 0, VK_WHOLE_SIZE, 0xffffffffu);
        barrier();
        c.stage = 0;
        const bool cpu = engine->group == 32;
        const uint32_t pixels = c.mode == CLASSIFY_SR       ? kClassifySr
                                : cpu && c.g.width % 4 == 0 ? kClassifyGenQuad
                                                            : kClassifyGen;
        FGSR_TRY(
            dispatch(pixels, buffers, &c, groups(c.g.width, cpu ? FGSR_CLASSIFY_SPAN_CPU : 1u), c.g.height));
        barrier();
        c.stage = 1;
        FGSR_TRY(dispatch(kClassify, buffers, &c, groups(c.g.width, c.tile), groups(c.g.height, c.tile)));
        return {};
    }

    Result<void> upload_lut() {
        Lut l = params.lut.size() == kLutSize ? Lut{params.scale, params.lut} : default_lut(params.scale);
        force_identity_phase(l);
        const std::vector<float>& weights = l.weights;
        std::memcpy(lut.mapped(), weights.data(), kLutSize * 4);
        return {};
    }

    Result<void> ensure_outputs(size_t count) {
        while (outputs.size() < count) {
            auto r = vk::Buffer::create(*ctx, VkDeviceSize(out_w) * out_h * 16, true);
            if (!r) return r.error();
            outputs.push_back(std::move(*r));
        }
        return {};
    }

    Result<void> begin() {
        FGSR_VK(vkResetDescriptorPool(ctx->device, desc_pool, 0), "vkResetDescriptorPool");
        FGSR_VK(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        FGSR_VK(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
        vkCmdResetQueryPool(cmd, queries, 0, kMaxAlphas * kQueriesPerFrame);
        return {};
    }

    // timed: the command buffer wrote timestamp query 0 first; pairs the GPU clock with
    // CLOCK_MONOTONIC for tick_ns() (calibrated timestamps when the device has them, else query 0
    // is taken to be the CPU time just before vkQueueSubmit).
    Result<void> finish(bool timed = false) {
        FGSR_VK(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmd;
        FGSR_VK(vkResetFences(ctx->device, 1, &fence), "vkResetFences");
        const uint64_t submit_ns = monotonic_ns();
        FGSR_VK(vkQueueSubmit(ctx->queue, 1, &si, fence), "vkQueueSubmit");
        FGSR_VK(vkWaitForFences(ctx->device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        if (!timed) return {};
        if (ctx->get_calibrated_timestamps) {
            std::array<VkCalibratedTimestampInfoEXT, 2> info{};
            info[0] = {VK_STRUCTURE_TYPE_CALIBRATED_TIMESTAMP_INFO_EXT, nullptr, VK_TIME_DOMAIN_DEVICE_EXT};
            info[1] = {VK_STRUCTURE_TYPE_CALIBRATED_TIMESTAMP_INFO_EXT, nullptr,
                       VK_TIME_DOMAIN_CLOCK_MONOTONIC_EXT};
            std::array<uint64_t, 2> ts{};
            uint64_t deviation = 0;
            FGSR_VK(ctx->get_calibrated_timestamps(ctx->device, 2, info.data(), ts.data(), &deviation),
                    "vkGetCalibratedTimestampsEXT");
            calib_tick = ts[0];
            calib_ns = ts[1];
            return {};
        }
        uint64_t first = 0;
        FGSR_VK(vkGetQueryPoolResults(ctx->device, queries, 0, 1, 8, &first, 8,
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                "vkGetQueryPoolResults");
        calib_tick = first;
        calib_ns = submit_ns;
        return {};
    }

    // CLOCK_MONOTONIC ns of a GPU timestamp of the last timed submission.
    uint64_t tick_ns(uint64_t tick) const {
        const uint64_t mask =
            ctx->timestamp_valid_bits >= 64 ? ~0ull : ((1ull << ctx->timestamp_valid_bits) - 1);
        uint64_t diff = (tick - calib_tick) & mask;
        int64_t signed_diff = int64_t(diff);
        if (mask != ~0ull && diff > mask / 2) signed_diff = int64_t(diff) - int64_t(mask) - 1;
        const double ns = double(signed_diff) * double(ctx->props.limits.timestampPeriod);
        return uint64_t(int64_t(calib_ns) + int64_t(std::llround(ns)));
    }

    void barrier() {
        VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                           VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                           VK_ACCESS_HOST_READ_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                                 VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                             0, 1, &mb, 0, nullptr, 0, nullptr);
    }

    void timestamp(uint32_t query) {
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, queries, query);
    }

    // Dispatches one invocation per pixel of a width x height image (0: the session's frame size).
    Result<void> dispatch(uint32_t pass, std::initializer_list<BufRef> buffers, const void* push,
                          uint32_t width = 0, uint32_t height = 0) {
        FGSR_TRY(bind(pass, buffers, push));
        vkCmdDispatch(cmd, groups(width ? width : format.width, engine->group),
                      groups(height ? height : format.height, engine->group), 1);
        return {};
    }

    // Dispatches a tiled pass over a tile list (shaders/tiles.h); the list is also bound at
    // <PASS>_COUNT + TILED_LIST, followed by the flags and the list splat appends to.
    Result<void> dispatch_tiles(uint32_t pass, std::initializer_list<BufRef> buffers, const void* push,
                                const vk::Buffer& list) {
        FGSR_TRY(bind(pass, buffers, push));
        vkCmdDispatchIndirect(cmd, list.handle(), 0);
        return {};
    }

    // Binds a pass's pipeline, a fresh descriptor set of `buffers` (binding i = i-th buffer) and
    // its push constants.
    Result<void> bind(uint32_t pass, std::initializer_list<BufRef> buffers, const void* push) {
        const vk::Pipeline& p = engine->pipelines[pass];
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = desc_pool;
        ai.descriptorSetCount = 1;
        VkDescriptorSetLayout layout = p.set_layout();
        ai.pSetLayouts = &layout;
        VkDescriptorSet set = VK_NULL_HANDLE;
        FGSR_VK(vkAllocateDescriptorSets(ctx->device, &ai, &set), "vkAllocateDescriptorSets");
        std::array<VkDescriptorBufferInfo, 16> infos{};
        std::array<VkWriteDescriptorSet, 16> writes{};
        uint32_t i = 0;
        for (const BufRef& b : buffers) {
            infos[i] = VkDescriptorBufferInfo{b.buffer, b.offset, b.range};
            writes[i] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            writes[i].dstSet = set;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
            ++i;
        }
        vkUpdateDescriptorSets(ctx->device, i, writes.data(), 0, nullptr);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.handle());
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout(), 0, 1, &set, 0, nullptr);
        vkCmdPushConstants(cmd, p.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, p.push_size(), push);
        return {};
    }

    // Timings between consecutive timestamps [first, first + count] (names left empty).
    Result<std::vector<PassTiming>> read_times(uint32_t first, uint32_t count) {
        std::vector<uint64_t> ticks(count + 1);
        FGSR_VK(vkGetQueryPoolResults(ctx->device, queries, first, count + 1, ticks.size() * 8, ticks.data(),
                                      8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                "vkGetQueryPoolResults");
        const uint64_t mask =
            ctx->timestamp_valid_bits >= 64 ? ~0ull : ((1ull << ctx->timestamp_valid_bits) - 1);
        std::vector<PassTiming> t(count);
        for (uint32_t i = 0; i < count; ++i) {
            t[i].ms =
                double((ticks[i + 1] - ticks[i]) & mask) * double(ctx->props.limits.timestampPeriod) * 1e-6;
            t[i].begin_ns = tick_ns(ticks[i]);
            t[i].end_ns = tick_ns(ticks[i + 1]);
        }
        return t;
    }

    // Copies a buffer to the host (through a staging buffer when it is not mapped).
    template <class T> Result<std::vector<T>> download(const vk::Buffer& b, size_t count) {
        auto staging = vk::Buffer::create(*ctx, count * sizeof(T), true);
        if (!staging) return staging.error();
        FGSR_TRY(begin());
        VkBufferCopy region{0, 0, count * sizeof(T)};
        vkCmdCopyBuffer(cmd, b.handle(), staging->handle(), 1, &region);
        barrier();
        FGSR_TRY(finish());
        std::vector<T> out(count);
        std::memcpy(out.data(), staging->mapped(), count * sizeof(T));
        return out;
    }

    Result<std::vector<GeneratedFrame>> generate(std::span<const float> alphas, bool extrapolate);
    Result<void> submit(const FrameView& frame, const HostMemory* memory);

    // Records the sr pass of a frame with history with tile skipping: classify in sr mode, then
    // sr over the moving tiles and its static form over the others. Writes timestamp `query`
    // (after classify); the caller writes the one after sr.
    Result<void> record_sr_tiled(const gpu::SrParams& sp, const GpuFrame& f, const GpuFrame& prev,
                                 const vk::Buffer& history, const vk::Buffer& out, uint32_t query) {
        FGSR_TRY(ensure_tile_sets(1));
        const TileSet& ts = tile_sets[0];
        const uint32_t side = tile_side();
        const uint32_t span = output_span(side, sp.scale);
        reset_lists(ts, span, span);
        barrier();
        gpu::ClassifyParams c{};
        c.g.width = format.width;
        c.g.height = format.height;
        c.g.t_depth = sp.t_depth;
        c.tile = side;
        c.mode = CLASSIFY_SR;
        c.dilate = sp.dilate;
        c.work_invocations = span * span;
        c.output_invocations = span * span;
        // Generate-mode bindings the sr mode does not touch get any buffer of the right kind.
        FGSR_TRY(classify(c, {&f.mv, &prev.mv, &f.depth, &prev.depth, &keys, &motion, &f.color, &f.color,
                              &out, &ts.flags, &ts.work, &ts.generate, &ts.statics}));
        barrier();
        timestamp(query);
        FGSR_TRY(dispatch_tiles(
            kSrTiled,
            {&f.color, &f.depth, &f.mv, &prev.depth, &history, &lut, &out, &ts.work, &ts.flags, &ts.generate},
            &sp, ts.work));
        gpu::SrParams st = sp;
        st.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
        st.dilate = 0;                              // every vector around a static pixel is zero
        FGSR_TRY(dispatch_tiles(kSrStatic,
                                {&f.color, &f.depth, &f.mv, &prev.depth, &history, &lut, &out, &ts.statics,
                                 &ts.flags, &ts.generate},
                                &st, ts.statics));
        return {};
    }

    // Records generated frame k with tile skipping: classify (copy-through output of static
    // pixels at input resolution, tile lists), splat over the moving tiles, then generate (or
    // generate_sr) over the moving and dirtied tiles; with super resolution the static tiles that
    // stayed clean take generate_sr's static form. Writes timestamps q..q+2.
    Result<void> record_tiled(size_t k, const gpu::GenParams& g, bool extrapolate, uint32_t& q) {
        const TileSet& ts = tile_sets[k];
        const vk::Buffer& out = outputs[k];
        const GpuFrame& f1 = frames[size_t(newest)];
        const GpuFrame& f0 = frames[size_t(1 - newest)];
        const uint32_t side = tile_side();
        const float scale = sr() ? float(out_w) / float(format.width) : 1.f;
        const uint32_t span = output_span(side, scale);
        reset_lists(ts, side, span);
        barrier();
        gpu::ClassifyParams c{};
        c.g = g;
        c.tile = side;
        c.mode = CLASSIFY_GENERATE;
        c.write_output = sr() ? 0u : 1u;
        c.work_invocations = side * side;
        c.output_invocations = span * span;
        FGSR_TRY(classify(c, {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color, &f1.color,
                              &out, &ts.flags, &ts.work, &ts.generate, &ts.statics}));
        barrier();
        timestamp(q++);
        FGSR_TRY(dispatch_tiles(
            kSplatTiled,
            {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &ts.work, &ts.flags, &ts.generate}, &g,
            ts.work));
        barrier();
        timestamp(q++);
        if (!sr()) {
            FGSR_TRY(dispatch_tiles(kGenerateTiled,
                                    {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color,
                                     &f1.color, &out, &ts.generate, &ts.flags, &ts.generate},
                                    &g, ts.generate));
        } else {
            GenSrPush push{g, ref::sr_params(format, params, out_w, out_h, jitter_x, jitter_y, true)};
            const vk::Buffer& src = hr[size_t(extrapolate ? hr_newest : 1 - hr_newest)];
            FGSR_TRY(dispatch_tiles(kGenerateSrTiled,
                                    {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color,
                                     &f1.color, &src, &lut, &out, &ts.generate, &ts.flags, &ts.generate},
                                    &push, ts.generate));
            push.s.resample = uint32_t(Resample::bilinear); // exact at the static pixels' phase 0
            FGSR_TRY(dispatch_tiles(kGenerateSrStatic,
                                    {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color,
                                     &f1.color, &src, &lut, &out, &ts.statics, &ts.flags, &ts.generate},
                                    &push, ts.statics));
        }
        barrier();
        timestamp(q++);
        return {};
    }
};

Result<void> validate(const Params& p) {
    auto bad = [](const char* field, float v, const char* range) {
        return make_error(Errc::invalid_argument, std::string("parameter ") + field + " = " +
                                                      std::to_string(v) + " is outside " + range);
    };
    if (!(std::isfinite(p.t_depth) && p.t_depth >= 0.f)) return bad("t_depth", p.t_depth, "[0, inf)");
    if (!(std::isfinite(p.t_bright) && p.t_bright >= 0.f)) return bad("t_bright", p.t_bright, "[0, inf)");
    if (!(p.sr_a >= 0.f && p.sr_a <= 1.f)) return bad("sr_a", p.sr_a, "[0, 1]");
    if (!(std::isfinite(p.sr_b) && p.sr_b >= 0.f)) return bad("sr_b", p.sr_b, "[0, inf)");
    if (!(p.denoise_strength >= 0.f && p.denoise_strength <= 64.f))
        return bad("denoise_strength", p.denoise_strength, "[0, 64]");
    if (!(std::isfinite(p.noise_floor) && p.noise_floor >= 0.f))
        return bad("noise_floor", p.noise_floor, "[0, inf)");
    if (!(std::isfinite(p.scale) && p.scale >= 1.f && p.scale <= 4.f))
        return make_error(Errc::invalid_argument,
                          "scale factor " + std::to_string(p.scale) + " is outside [1, 4]");
    if (uint32_t(p.motion) > uint32_t(MotionModel::linear) || uint32_t(p.blend) > uint32_t(BlendMode::mix) ||
        uint32_t(p.resample) > uint32_t(Resample::lut))
        return make_error(Errc::invalid_argument, "unknown motion model, blend mode or resampling kind");
    if (!p.lut.empty() && p.lut.size() != kLutSize)
        return make_error(Errc::invalid_argument, "LUT has " + std::to_string(p.lut.size()) +
                                                      " weights, expected " + std::to_string(kLutSize));
    for (size_t i = 0; i < p.lut.size(); ++i)
        if (!std::isfinite(p.lut[i]))
            return make_error(Errc::invalid_argument,
                              "LUT weight " + std::to_string(i) + " is " + std::to_string(p.lut[i]));
    return {};
}

Result<std::unique_ptr<Session>> Engine::create_session(const FrameFormat& format, const Params& params) {
    // Validate the format with an empty frame view of the right sizes.
    const size_t n = size_t(format.width) * format.height;
    if (n == 0)
        return make_error(Errc::empty_input, "session frame size is " + std::to_string(format.width) + "x" +
                                                 std::to_string(format.height));
    if (bytes_per_pixel(format.color_format) == 0)
        return make_error(Errc::unsupported,
                          "unknown colour format " + std::to_string(uint32_t(format.color_format)));
    if (bytes_per_pixel(format.mv_format) == 0)
        return make_error(Errc::unsupported,
                          "unknown motion-vector format " + std::to_string(uint32_t(format.mv_format)));
    auto impl = std::make_unique<Session::Impl>();
    impl->engine = impl_.get();
    impl->ctx = impl_->ctx.get();
    impl->format = format;
    impl->params = params;
    impl->n = n;
    FGSR_TRY(validate(params));
    impl->out_w = uint32_t(std::lround(double(format.width) * params.scale));
    impl->out_h = uint32_t(std::lround(double(format.height) * params.scale));
    if (impl->out_w > kMaxFrameSide || impl->out_h > kMaxFrameSide)
        return make_error(Errc::invalid_argument, "output size " + std::to_string(impl->out_w) + "x" +
                                                      std::to_string(impl->out_h) + " exceeds " + std::to_string(kMaxFrameSide) + "x" + std::to_string(kMaxFrameSide));
    if (params.tile_size != 0 && params.tile_size != 8 && params.tile_size != 16 && params.tile_size != 32)
        return make_error(Errc::invalid_argument,
                          "tile size " + std::to_string(params.tile_size) + " is not 0, 8, 16 or 32");
    // A view with planes of exactly the right size validates conventions and limits.
    std::vector<std::byte> c(n * bytes_per_pixel(format.color_format)), d(n * 4);
    FGSR_TRY(ref::validate(format, FrameView{c, d, {}}));
    FGSR_TRY(impl->init());
    return std::unique_ptr<Session>(new Session(std::move(impl)));
}

Session::Session(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Session::~Session() = default;
const FrameFormat& Session::format() const {
    return impl_->format;
}
const Params& Session::params() const {
    return impl_->params;
}
void Session::set_params(const Params& p) {
    // The scale (and so every buffer size) is fixed at creation.
    const float scale = impl_->params.scale;
    Params checked = p;
    checked.scale = scale;
    if (!validate(checked)) return;
    const bool lut_changed = p.lut != impl_->params.lut;
    impl_->params = p;
    impl_->params.scale = scale;
    if (p.tile_size != 8 && p.tile_size != 16 && p.tile_size != 32) impl_->params.tile_size = 0;
    if (lut_changed && impl_->sr()) (void)impl_->upload_lut();
}
uint32_t Session::output_width() const {
    return impl_->out_w;
}
uint32_t Session::output_height() const {
    return impl_->out_h;
}
uint64_t Session::frames_submitted() const {
    return impl_->submitted;
}
NoiseEstimate Session::last_noise_estimate() const {
    return impl_->noise_estimate;
}
double Session::last_ingest_ms() const {
    return impl_->ingest_timing.ms;
}
PassTiming Session::last_ingest_timing() const {
    return impl_->ingest_timing;
}
uint32_t Session::tile_side() const {
    return impl_->tile_side();
}
std::vector<uint32_t> Session::last_sr_tile_flags() const {
    const Impl& s = *impl_;
    if (!s.last_sr_tiled || s.tile_sets.empty()) return {};
    const uint32_t* flags = static_cast<const uint32_t*>(s.tile_sets[0].flags.mapped());
    return std::vector<uint32_t>(flags, flags + s.sr_tiles_total);
}

void Session::reset() {
    impl_->submitted = 0;
    impl_->hr_valid = false;
    for (auto& f : impl_->frames) f.has_mv = false;
}

Result<void> Session::submit(const FrameView& frame) {
    return impl_->submit(frame, nullptr);
}

Result<void> Session::submit(const FrameView& frame, const HostMemory& memory) {
    return impl_->submit(frame, &memory);
}

Result<void> Session::Impl::submit(const FrameView& frame, const HostMemory* memory) {
    Impl& s = *this;
    FGSR_TRY(ref::validate(s.format, frame));
    const bool has_mv = !frame.mv.empty();
    // Zero copy: the planes must lie inside the imported memory, at offsets the device can bind.
    std::array<BufRef, 3> raw{&s.color_raw, &s.depth_raw, &s.mv_raw};
    if (memory) {
        const std::byte* base = memory->data();
        const VkDeviceSize align =
            std::max<VkDeviceSize>(ctx->props.limits.minStorageBufferOffsetAlignment, 4);
        auto range = [&](std::span<const std::byte> plane, const char* what, BufRef& out) -> Result<void> {
            if (plane.data() < base || plane.data() + plane.size() > base + memory->size())
                return make_error(Errc::invalid_argument,
                                  std::string(what) + " plane lies outside the imported host memory");
            const VkDeviceSize offset = VkDeviceSize(plane.data() - base);
            if (offset % align != 0)
                return make_error(Errc::invalid_argument,
                                  std::string(what) + " plane offset " + std::to_string(offset) +
                                      " is not a multiple of " + std::to_string(align));
            out = BufRef(memory->impl()->buffer.handle(), offset, plane.size());
            return {};
        };
        FGSR_TRY(range(frame.color, "colour", raw[0]));
        FGSR_TRY(range(frame.depth, "depth", raw[1]));
        if (has_mv)
            FGSR_TRY(range(frame.mv, "motion-vector", raw[2]));
        else
            raw[2] = raw[0]; // bound, not read
    } else {
        std::memcpy(s.color_raw.mapped(), frame.color.data(), frame.color.size());
        std::memcpy(s.depth_raw.mapped(), frame.depth.data(), frame.depth.size());
        if (has_mv) std::memcpy(s.mv_raw.mapped(), frame.mv.data(), frame.mv.size());
    }
    if (!std::isfinite(frame.jitter_x) || !std::isfinite(frame.jitter_y) || std::abs(frame.jitter_x) > 1.f ||
        std::abs(frame.jitter_y) > 1.f)
        return make_error(Errc::invalid_argument, "jitter (" + std::to_string(frame.jitter_x) + ", " +
                                                      std::to_string(frame.jitter_y) +
                                                      ") is outside [-1, 1] pixels");
    const bool restart = frame.reset || s.submitted == 0;
    const int slot = 1 - s.newest;
    Impl::GpuFrame& f = s.frames[size_t(slot)];
    const Impl::GpuFrame& prev = s.frames[size_t(s.newest)];
    gpu::IngestParams p = ref::ingest_params(s.format, has_mv);
    if (s.params.mvs_contain_jitter && !restart) {
        p.mv_offset_x = s.jitter_x - frame.jitter_x;
        p.mv_offset_y = s.jitter_y - frame.jitter_y;
    }
    FGSR_TRY(s.begin());
    // Timestamps: 0, after ingest, [after denoise], [after classify], after sr.
    uint32_t q = 0;
    s.timestamp(q++);
    const bool denoise = s.denoise();
    // The build for the session's formats (shaders/ingest.comp); the generic kIngest serves the same.
    const uint32_t ingest =
        p.color_format <= 2 && p.mv_format <= 1 ? kIngestFormats + 2 * p.color_format + p.mv_format : kIngest;
    const uint32_t span = ingest != kIngest && s.engine->group == 32 ? FGSR_INGEST_SPAN_CPU : 1u;
    FGSR_TRY(s.dispatch(ingest, {raw[0], raw[1], raw[2], &f.color, &f.depth, &f.mv}, &p,
                        groups(s.format.width, span), s.format.height));
    s.barrier();
    s.timestamp(q++);
    if (denoise) {
        FGSR_TRY(s.record_denoise(f.color));
        s.barrier();
        s.timestamp(q++);
    }
    bool sr_tiled = false;
    if (s.sr()) {
        gpu::SrParams sp = ref::sr_params(s.format, s.params, s.out_w, s.out_h, frame.jitter_x,
                                          frame.jitter_y, !restart && s.hr_valid && has_mv);
        const vk::Buffer& history = s.hr[size_t(s.hr_newest)];
        const vk::Buffer& out = s.hr[size_t(1 - s.hr_newest)];
        // Without history every pixel is a spatial upsample: nothing to classify.
        sr_tiled = s.params.skip_tiles && sp.has_history != 0u && s.sr_unclassified_left == 0;
        if (s.sr_unclassified_left > 0) --s.sr_unclassified_left;
        if (sr_tiled) {
            FGSR_TRY(s.record_sr_tiled(sp, f, prev, history, out, q++));
        } else {
            FGSR_TRY(s.dispatch(kSr, {&f.color, &f.depth, &f.mv, &prev.depth, &history, &s.lut, &out}, &sp,
                                s.out_w, s.out_h));
        }
        s.barrier();
        s.timestamp(q++);
    }
    FGSR_TRY(s.finish(true));
    auto t = s.read_times(0, q - 1);
    if (!t) return t.error();
    size_t ti = 0;
    s.ingest_timing = (*t)[ti++];
    s.ingest_timing.name = "ingest";
    s.noise_estimate = NoiseEstimate{};
    if (denoise) {
        s.denoise_timing = (*t)[ti++];
        s.denoise_timing.name = "denoise";
        const uint32_t* words = static_cast<const uint32_t*>(s.noise.mapped());
        std::memcpy(&s.noise_estimate.sigma, &words[DENOISE_SIGMA], 4);
        std::memcpy(&s.noise_estimate.range, &words[DENOISE_RANGE], 4);
    }
    s.last_sr_tiled = sr_tiled;
    s.classify_sr_timing = sr_tiled ? (*t)[ti++] : PassTiming{};
    s.classify_sr_timing.name = "classify";
    if (sr_tiled) {
        s.last_tile_side = s.tile_side();
        s.sr_tiles_total = s.tiles_total();
        s.sr_tiles_skipped = std::min(s.sr_tiles_total, Impl::list_count(s.tile_sets[0].statics));
        if (double(s.sr_tiles_skipped) < kMinSkipShare * double(s.sr_tiles_total))
            s.sr_unclassified_left = kUnclassifiedRun;
    }
    f.has_mv = has_mv;
    s.newest = slot;
    s.jitter_x = frame.jitter_x;
    s.jitter_y = frame.jitter_y;
    if (restart) s.submitted = 0;
    ++s.submitted;
    if (s.sr()) {
        s.sr_timing = (*t)[ti];
        s.sr_timing.name = "sr";
        s.hr_newest = 1 - s.hr_newest;
        s.hr_valid = true;
    }
    return {};
}

Result<std::vector<GeneratedFrame>> Session::Impl::generate(std::span<const float> alphas, bool extrapolate) {
    if (submitted < 2)
        return make_error(Errc::empty_input, std::string(extrapolate ? "extrapolation" : "interpolation") +
                                                 " needs two submitted frames, the session has " +
                                                 std::to_string(submitted));
    if (alphas.empty()) return make_error(Errc::invalid_argument, "no alpha requested");
    if (alphas.size() > kMaxAlphas)
        return make_error(Errc::invalid_argument, std::to_string(alphas.size()) +
                                                      " alphas requested, at most " +
                                                      std::to_string(kMaxAlphas) + " per call");
    for (float a : alphas) {
        bool ok = extrapolate ? (a > 0.f && a <= 1.f) : (a > 0.f && a < 1.f);
        if (!std::isfinite(a) || !ok)
            return make_error(Errc::invalid_argument,
                              "alpha " + std::to_string(a) + " is outside " +
                                  (extrapolate ? "(0, 1] for extrapolation" : "(0, 1) for interpolation"));
    }
    FGSR_TRY(ensure_outputs(alphas.size()));
    const bool tiled = params.skip_tiles && !(params.separate_passes && !sr()) && gen_unclassified_left == 0;
    if (gen_unclassified_left > 0) --gen_unclassified_left;
    if (tiled) FGSR_TRY(ensure_tile_sets(alphas.size()));
    const GpuFrame& f1 = frames[size_t(newest)];
    const GpuFrame& f0 = frames[size_t(1 - newest)];

    std::vector<std::vector<uint32_t>> timings(alphas.size()); // passes timed per generated frame, in order
    FGSR_TRY(begin());
    for (size_t k = 0; k < alphas.size(); ++k) {
        const gpu::GenParams g =
            ref::gen_params(format, params, alphas[k], extrapolate, f0.has_mv, f1.has_mv);
        const uint32_t q0 = uint32_t(k) * kQueriesPerFrame;
        uint32_t q = q0;
        const vk::Buffer& out = outputs[k];
        timestamp(q++);
        if (tiled) {
            FGSR_TRY(record_tiled(k, g, extrapolate, q));
            timings[k] = {kClassify, kSplatTiled, sr() ? kGenerateSrTiled : kGenerateTiled};
            continue;
        }
        vkCmdFillBuffer(cmd, keys.handle(), 0, VK_WHOLE_SIZE, 0xffffffffu);
        barrier();
        FGSR_TRY(dispatch(kSplat, {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion}, &g));
        barrier();
        timestamp(q++);
        if (sr()) { // joint ISR / ESR at output resolution (always fused)
            GenSrPush push{g, ref::sr_params(format, params, out_w, out_h, jitter_x, jitter_y, true)};
            const vk::Buffer& src = hr[size_t(extrapolate ? hr_newest : 1 - hr_newest)];
            FGSR_TRY(dispatch(kGenerateSr,
                              {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color, &f1.color,
                               &src, &lut, &out},
                              &push, out_w, out_h));
            barrier();
            timestamp(q++);
            timings[k] = {kSplat, kGenerateSr};
            continue;
        }
        if (!params.separate_passes) {
            FGSR_TRY(dispatch(
                kGenerate, {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &f0.color, &f1.color, &out},
                &g));
            barrier();
            timestamp(q++);
            timings[k] = {kSplat, kGenerate};
            continue;
        }
        FGSR_TRY(dispatch(
            kRefine,
            {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &field, &field_depth, &field_state}, &g));
        barrier();
        timestamp(q++);
        timings[k] = {kSplat, kRefine};
        if (params.fill_holes) {
            FGSR_TRY(dispatch(
                kDisocc,
                {&f1.mv, &f0.mv, &f1.depth, &f0.depth, &keys, &motion, &field, &field_depth, &field_state},
                &g));
            barrier();
            timestamp(q++);
            timings[k].push_back(kDisocc);
        }
        const vk::Buffer& w1 = extrapolate ? out : warped_color1;
        FGSR_TRY(dispatch(kWarp,
                          {&field, &f0.color, &f1.color, &f0.depth, &f1.depth, &warped_color0, &warped_depth0,
                           &w1, &warped_depth1},
                          &g));
        barrier();
        timestamp(q++);
        timings[k].push_back(kWarp);
        if (!extrapolate) {
            FGSR_TRY(dispatch(
                kBlend, {&warped_color0, &warped_depth0, &warped_color1, &warped_depth1, &field_state, &out},
                &g));
            barrier();
            timestamp(q++);
            timings[k].push_back(kBlend);
        }
    }
    FGSR_TRY(finish(true));

    std::vector<GeneratedFrame> result(alphas.size());
    for (size_t k = 0; k < alphas.size(); ++k) {
        GeneratedFrame& gf = result[k];
        gf.time = extrapolate ? 1.f + alphas[k] : alphas[k];
        auto t = read_times(uint32_t(k) * kQueriesPerFrame, uint32_t(timings[k].size()));
        if (!t) return t.error();
        for (size_t p = 0; p < timings[k].size(); ++p) {
            PassTiming pt = (*t)[p];
            pt.name = timing_name(timings[k][p]);
            gf.gpu_ms += pt.ms;
            gf.passes.push_back(std::move(pt));
        }
        if (tiled) { // classify, splat, generate(_sr): tiles outside the lists were skipped
            const TileSet& ts = tile_sets[k];
            const uint32_t total = tiles_total();
            gf.passes[0].tiles_total = gf.passes[1].tiles_total = gf.passes[2].tiles_total = total;
            gf.passes[1].tiles_skipped = total - std::min(total, list_count(ts.work));
            gf.passes[2].tiles_skipped = total - std::min(total, list_count(ts.generate));
            if (double(gf.passes[2].tiles_skipped) < kMinSkipShare * double(total))
                gen_unclassified_left = kUnclassifiedRun;
        }
        const size_t out_n = size_t(out_w) * out_h;
        gf.color.width = out_w;
        gf.color.height = out_h;
        gf.color.rgba.resize(out_n * 4);
        std::memcpy(gf.color.rgba.data(), outputs[k].mapped(), out_n * 16);
    }
    last_extrapolate = extrapolate;
    last_separate = params.separate_passes && !sr();
    last_tiled = tiled;
    last_tile_side = tile_side();
    last_output = alphas.size() - 1;
    return result;
}

Result<GeneratedFrame> Session::super_resolved() {
    Impl& s = *impl_;
    if (!s.sr())
        return make_error(Errc::invalid_argument, "the session does not upscale (Params::scale is 1)");
    if (!s.hr_valid) return make_error(Errc::empty_input, "no frame submitted yet");
    const size_t hpx = size_t(s.out_w) * s.out_h;
    auto px = s.download<float>(s.hr[size_t(s.hr_newest)], hpx * 4);
    if (!px) return px.error();
    GeneratedFrame gf;
    gf.time = 1.f;
    gf.color = ImageRGBA{s.out_w, s.out_h, std::move(*px)};
    PassTiming sr = s.sr_timing;
    if (s.denoise()) {
        gf.passes.push_back(s.denoise_timing);
        gf.gpu_ms += s.denoise_timing.ms;
    }
    if (s.last_sr_tiled) {
        PassTiming cl = s.classify_sr_timing;
        cl.tiles_total = s.sr_tiles_total;
        gf.passes.push_back(cl);
        gf.gpu_ms += cl.ms;
        sr.tiles_total = s.sr_tiles_total;
        sr.tiles_skipped = s.sr_tiles_skipped;
    }
    gf.passes.push_back(sr);
    gf.gpu_ms += sr.ms;
    return gf;
}

Result<std::vector<GeneratedFrame>> Session::interpolate(std::span<const float> alphas) {
    return impl_->generate(alphas, false);
}

Result<std::vector<GeneratedFrame>> Session::extrapolate(std::span<const float> alphas) {
    return impl_->generate(alphas, true);
}

Result<Session::Intermediates> Session::read_intermediates() const {
    Impl& s = *impl_;
    Intermediates out;
    auto keys = s.download<uint64_t>(s.keys, s.n);
    if (!keys) return keys.error();
    out.keys = std::move(*keys);
    auto motion = s.download<float>(s.motion, s.n * 4);
    if (!motion) return motion.error();
    out.motion = std::move(*motion);
    if (s.last_tiled && s.last_output < s.tile_sets.size()) {
        const uint32_t* flags = static_cast<const uint32_t*>(s.tile_sets[s.last_output].flags.mapped());
        out.tile_flags.assign(flags, flags + s.tiles_total());
        out.tile_side = s.last_tile_side;
    }
    if (!s.last_separate) return out; // the fused pass keeps no other intermediates
    auto get_f = [&](const vk::Buffer& b, size_t count, std::vector<float>& dst) -> Result<void> {
        auto r = s.download<float>(b, count);
        if (!r) return r.error();
        dst = std::move(*r);
        return {};
    };
    FGSR_TRY(get_f(s.field, s.n * 4, out.field));
    FGSR_TRY(get_f(s.field_depth, s.n, out.field_depth));
    auto st = s.download<uint32_t>(s.field_state, s.n);
    if (!st) return st.error();
    out.field_state = std::move(*st);
    FGSR_TRY(get_f(s.warped_color0, s.n * 4, out.warped_color0));
    FGSR_TRY(get_f(s.warped_depth0, s.n, out.warped_depth0));
    FGSR_TRY(
        get_f(s.last_extrapolate ? s.outputs[s.last_output] : s.warped_color1, s.n * 4, out.warped_color1));
    FGSR_TRY(get_f(s.warped_depth1, s.n, out.warped_depth1));
    return out;
}

Result<Session::InternalFrameData> Session::read_frame(int which) const {
    Impl& s = *impl_;
    if (which != 0 && which != 1) return make_error(Errc::invalid_argument, "frame index must be 0 or 1");
    const Impl::GpuFrame& f = s.frames[size_t(which == 1 ? s.newest : 1 - s.newest)];
    InternalFrameData out;
    auto c = s.download<uint32_t>(f.color, s.n * 2); // pack_color
    if (!c) return c.error();
    auto d = s.download<float>(f.depth, s.n);
    if (!d) return d.error();
    auto m = s.download<float>(f.mv, s.n * 2);
    if (!m) return m.error();
    out.color.resize(s.n * 4);
    for (size_t i = 0; i < s.n; ++i) {
        const glm::vec4 v = gpu::unpack_color(glm::uvec2((*c)[2 * i], (*c)[2 * i + 1]));
        for (int k = 0; k < 4; ++k) out.color[4 * i + size_t(k)] = v[k];
    }
    out.depth = std::move(*d);
    out.mv = std::move(*m);
    out.has_mv = f.has_mv;
    return out;
}

} // namespace fgsr
