// Descriptor binding numbers of every pass (set 0, all storage buffers), shared by the GLSL entry
// files and the host code that binds them. Each pass's bindings are numbered 0..COUNT-1.
#ifndef FGSR_SHADERS_BINDINGS_H
#define FGSR_SHADERS_BINDINGS_H

#define INGEST_COLOR_RAW 0
#define INGEST_DEPTH_RAW 1
#define INGEST_MV_RAW 2
#define INGEST_COLOR 3
#define INGEST_DEPTH 4
#define INGEST_MV 5
#define INGEST_BRIGHT 6 // per 16x16 tile: over-white content within 1 pixel (stage dilate)
#define INGEST_PREV_COLOR 7 // the previous frame's ingested colour (stage dilate, edge rule)
#define INGEST_CUT 8 // per 8x8 block: vec2(SAD, contrast) of the frame against the previous one (stage cut)
#define INGEST_COUNT 9

// splat, refine, disocc and generate share the bindings of the frames and keys they read.
#define GEN_MV1 0
#define GEN_MV0 1
#define GEN_DEPTH1 2
#define GEN_DEPTH0 3
#define GEN_KEYS 4
#define GEN_MOTION 5 // per frame-1 pixel: field vectors (v0, v1) from its position at the generated time

#define SPLAT_COUNT 6

#define REFINE_FIELD 6
#define REFINE_FIELD_DEPTH 7
#define REFINE_FIELD_STATE 8
#define REFINE_COUNT 9

#define DISOCC_FIELD 6
#define DISOCC_FIELD_DEPTH 7
#define DISOCC_FIELD_STATE 8
#define DISOCC_COLOR1 9 // pack_color (uvec2): frame 1, for the edge cover's over-white test
#define DISOCC_COUNT 10

#define GENERATE_COLOR0 6
#define GENERATE_COLOR1 7
#define GENERATE_OUTPUT 8
#define GENERATE_COUNT 9

#define WARP_FIELD 0
#define WARP_COLOR0 1
#define WARP_COLOR1 2
#define WARP_DEPTH0 3
#define WARP_DEPTH1 4
#define WARP_OUT_COLOR0 5
#define WARP_OUT_DEPTH0 6
#define WARP_OUT_COLOR1 7 // extrapolation: the output frame
#define WARP_OUT_DEPTH1 8
#define WARP_FIELD_STATE 9 // extrapolation: the holes' state (warp.h, extrapolated_color)
#define WARP_COUNT 10

#define BLEND_COLOR0 0
#define BLEND_DEPTH0 1
#define BLEND_COLOR1 2
#define BLEND_DEPTH1 3
#define BLEND_FIELD_STATE 4
#define BLEND_OUTPUT 5
#define BLEND_FIELD 6 // the field's vectors (v0, v1): where warped frame 1 sampled
#define BLEND_MV1 7   // frame 1's vectors and depth (BLEND_DEPTH_MOTION, blend_depth.h)
#define BLEND_FRAME_DEPTH1 8
#define BLEND_COUNT 9

#define SR_COLOR 0
#define SR_DEPTH 1
#define SR_MV 2
#define SR_PREV_DEPTH 3
#define SR_HISTORY 4
#define SR_LUT 5
#define SR_OUTPUT 6
#define SR_NOISE 7 // vec2 per LR pixel: (r, q) of sr.h steps 3 and 7 (written by variant sr_noise)
#define SR_COUNT 8

#define GENSR_COLOR0 6
#define GENSR_COLOR1 7
#define GENSR_SRC 8
#define GENSR_LUT 9
#define GENSR_OUTPUT 10
#define GENSR_COUNT 11

#define DENOISE_COLOR_IN 0 // stages 0-2: the ingested frame colour; stage 3: the scratch (pack_color)
#define DENOISE_COLOR 1    // stage 2: the scratch; stage 3: the frame colour (pack_color)
#define DENOISE_NOISE 2    // DENOISE_WORDS uints: histogram, level, dispatch (zeroed by the host)
#define DENOISE_COUNT 3

// Motion estimation from colour (luma.h, match.h, flow.h).
#define LUMA_COLOR 0   // the frame's colour (pack_color), level 0
#define LUMA_PYRAMID 1 // the frame's pyramid (floats, every level), written ...
#define LUMA_PYRAMID_TEXELS 2 // ... and read as R32F texels (the finer level; never the one written)
#define LUMA_COUNT 3
#define LUMA_TEXELS (1u << LUMA_PYRAMID_TEXELS)

#define MATCH_SRC 0   // pyramid of the frame whose blocks are matched
#define MATCH_DST 1   // pyramid of the frame searched
#define MATCH_FIELD 2 // block vectors of every level and both directions (vec4: v.xy, cost, 0)
#define MATCH_COUNT 3
#define MATCH_TEXELS ((1u << MATCH_SRC) | (1u << MATCH_DST)) // read with texelFetch (variants.hpp)

#define FLOW_CUR 0   // pyramid of the current frame (level 0 read)
#define FLOW_PREV 1  // pyramid of the previous frame
#define FLOW_FIELD 2 // the block field
#define FLOW_MV 3    // the current frame's vectors (vec2, internal convention)
#define FLOW_DEPTH 4 // the current frame's depth (written as a proxy; read when correcting)
#define FLOW_PREV_DEPTH 5 // the previous frame's depth (read when correcting)
#define FLOW_COARSE 6     // the coarse-to-fine refined field (RG32F texels; read where coarse_level > 0)
#define FLOW_COUNT 7
#define FLOW_TEXELS ((1u << FLOW_CUR) | (1u << FLOW_PREV) | (1u << FLOW_FIELD) | (1u << FLOW_COARSE))

// polish (polish.h): variational refinement of the estimated vectors, in place.
#define POLISH_CUR 0  // pyramid of the current frame (level 0 read)
#define POLISH_PREV 1 // pyramid of the previous frame
#define POLISH_MV 2   // the current frame's vectors (vec2, internal convention), written ...
#define POLISH_MV_TEXELS 3 // ... and read as RG32F texels (a dispatch never reads what it writes)
#define POLISH_FIELD 4     // the block field (RGBA32F texels; read by the polish_seed build)
#define POLISH_PATCHES 5   // the patches' vectors (vec4; the polish_search and polish_densify builds)
#define POLISH_COUNT 6
#define POLISH_TEXELS                                                                                        \
    ((1u << POLISH_CUR) | (1u << POLISH_PREV) | (1u << POLISH_MV_TEXELS) | (1u << POLISH_FIELD))

// agree (agree.h): the warped frames, depths and field states of the given field (separate passes)
// and of the colour-only field, each field's blended frame, the disagreement and its row means.
#define AGREE_GIVEN_W0 0
#define AGREE_GIVEN_D0 1
#define AGREE_GIVEN_W1 2
#define AGREE_GIVEN_D1 3
#define AGREE_GIVEN_STATE 4
#define AGREE_COLOUR_W0 5
#define AGREE_COLOUR_D0 6
#define AGREE_COLOUR_W1 7
#define AGREE_COLOUR_D1 8
#define AGREE_COLOUR_STATE 9
#define AGREE_GIVEN 10  // the given field's frame (vec4), which stage 3 overwrites with the result
#define AGREE_COLOUR 11 // the colour-only field's frame (vec4)
#define AGREE_E 12      // stage 1 writes, stage 2 reads: vec2 (given, colour) per pixel
#define AGREE_ROWS 13   // stage 2 writes, stage 3 reads: their means along rows
// The given field's vectors (vec4 v0, v1 per pixel, field.h): the depth change stage 1 expects.
#define AGREE_GIVEN_FIELD 14
#define AGREE_LIGHT 15      // stage 5 writes, stage 6 reads; stage 7 writes its box sums, stage 1 reads them
#define AGREE_LIGHT_ROWS 16 // stage 6 writes, stage 7 reads: the row sums
#define AGREE_COUNT 17
// Extrapolation's stage 1 (agree_residual) reads the inputs and each field's frame-1 vectors in
// the first slots instead (agree.comp, AGREE_STAGE 4); the other slots are unused there.
#define AGREE_FRAME_COLOR0 AGREE_GIVEN_W0 // pack_color
#define AGREE_FRAME_DEPTH0 AGREE_GIVEN_D0
#define AGREE_FRAME_COLOR1 AGREE_GIVEN_W1
#define AGREE_FRAME_DEPTH1 AGREE_GIVEN_D1
#define AGREE_GIVEN_MV AGREE_GIVEN_STATE
#define AGREE_COLOUR_MV AGREE_COLOUR_W0

// classify (classify.h): the frames it reads use the GEN_* numbers (sr mode: GEN_MV1 = current
// vectors, GEN_DEPTH1 = current depth, GEN_DEPTH0 = previous depth), then:
#define CLASSIFY_COLOR0 6
#define CLASSIFY_COLOR1 7
#define CLASSIFY_OUTPUT 8 // copy-through pixels of static tiles (generate mode, write_output)
#define CLASSIFY_FLAGS 9  // TILE_* per tile
#define CLASSIFY_LIST_WORK 10
#define CLASSIFY_LIST_GENERATE 11
#define CLASSIFY_LIST_STATIC 12
#define CLASSIFY_COUNT 13

// Tiled variants (built with FGSR_TILED) of splat, generate, sr and generate_sr bind three more
// buffers after their own, at <PASS>_COUNT + TILED_*: the tile list they iterate (an indirect
// dispatch over it), the TILE_* flags, and the list splat appends the static tiles it dirties to.
#define TILED_LIST 0
#define TILED_FLAGS 1
#define TILED_APPEND 2
#define TILED_EXTRA 3

#endif
