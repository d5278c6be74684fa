/* The one table of GPU passes (plain C, no dependencies). Everything that numbers or names a pass
 * follows from it: the protocol's fgsr_pass_id and fgsr_pass_name (protocol.h, status.c), the
 * engine's fgsr::PassId and pass_name (fgsr/engine/passes.hpp), and through the shader variant
 * table (shaders/variants.def, which names passes by their ID) the engine's pipelines and the
 * SPIR-V builds of shaders/CMakeLists.txt.
 *
 * FGSR_PASSES(X) calls X(ID, name, value) once per pass, in value order. value is the public ABI
 * (fgsr_pass_record.pass, skipped_passes bits): never renumber, only append. */
#ifndef FGSR_PASSES_H
#define FGSR_PASSES_H

#define FGSR_PASSES(X)                                                                                       \
    X(INGEST, ingest, 0)                                                                                     \
    X(SPLAT, splat, 1)                                                                                       \
    X(REFINE, refine, 2)                                                                                     \
    X(DISOCC, disocc, 3)                                                                                     \
    X(WARP, warp, 4)                                                                                         \
    X(BLEND, blend, 5)                                                                                       \
    X(GENERATE, generate, 6)       /* fused refine, disocc, warp, blend */                                   \
    X(SR, sr, 7)                   /* temporal super resolution */                                           \
    X(GENERATE_SR, generate_sr, 8) /* generation at output resolution (ISR/ESR) */                           \
    X(CLASSIFY, classify, 9)       /* per-tile work classification */                                        \
    X(DENOISE, denoise, 10)        /* SR: noise estimate and pre-filter of the rendered frame */             \
    X(LUMA, luma, 11)              /* colour-only: luma pyramid of a submitted frame */                      \
    X(MATCH, match, 12)            /* colour-only: block matching, coarse to fine, both directions */        \
    X(FLOW, flow, 13)              /* colour-only: per-pixel vectors, consistency, depth proxy */            \
    X(POLISH, polish, 14)          /* colour-only: variational refinement of the vectors */                  \
    X(AGREE, agree, 15)            /* with vectors: per pixel the field whose warped frames agree */

#endif
