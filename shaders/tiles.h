// Entry-side helpers of the tiled pass variants (built with FGSR_TILED): an indirect dispatch over
// a tile list (layout: common.h, TILE_LIST_HEADER) gives each listed tile span x span invocations,
// span = tile_list[5], packed into FGSR_GROUP x FGSR_GROUP workgroups along x. GLSL only.
//
// Entry declares, in the FGSR_TILED variants: uint tile_list[] (the list it iterates, binding
// <PASS>_COUNT + TILED_LIST). classify uses only tile_index and TILE_APPEND.

// log2 of a tile side (8, 16 or 32): tile coordinates are shifts, not divisions.
uint tile_shift(uint side) { return side == 8u ? 3u : (side == 16u ? 4u : 5u); }

#ifdef FGSR_TILED

// The listed tile (tile units) and the invocation's position in its span x span square; false
// for the invocations past the end of the list.
bool listed_invocation(out ivec2 tile, out ivec2 local) {
    uint span = tile_list[5];
    uint per_tile = span * span;
    uint lin = gl_WorkGroupID.x * uint(FGSR_GROUP * FGSR_GROUP) + gl_LocalInvocationIndex;
    uint slot = udiv(lin, per_tile);
    tile = ivec2(0);
    local = ivec2(0);
    if (slot >= tile_list[3]) return false;
    uint packed = tile_list[TILE_LIST_HEADER + slot];
    uint l = lin - slot * per_tile;
    tile = ivec2(int(packed & 0xffffu), int(packed >> 16));
    uint row = udiv(l, span);
    local = ivec2(int(l - row * span), int(row));
    return true;
}

// Pixel of a pass at the tiles' own resolution (span = tile side).
bool listed_pixel(out ivec2 p) {
    ivec2 tile, local;
    bool ok = listed_invocation(tile, local);
    p = tile * int(tile_list[4]) + local;
    return ok;
}

// Output pixel q of a pass at scale x the tiles' resolution (sr, generate_sr): the listed LR tile
// covers the output pixels whose LR pixel clamp(floor((q + 0.5) / scale)) lies in it. The span
// (ceil(tile * scale) + 3) covers them from floor(origin * scale) - 1 on; false for the others,
// so each output pixel is processed by exactly one listed tile.
bool listed_output_pixel(float scale, ivec2 lr_size, ivec2 out_size, out ivec2 q) {
    ivec2 tile, local;
    bool ok = listed_invocation(tile, local);
    int side = int(tile_list[4]);
    ivec2 origin = tile * side;
    q = max(ivec2(floor(vec2(origin) * scale)) - ivec2(1), ivec2(0)) + local;
    if (!ok || q.x >= out_size.x || q.y >= out_size.y) return false;
    ivec2 t = clamp(ivec2(floor((vec2(q) + vec2(0.5f)) / scale)), ivec2(0), lr_size - ivec2(1));
    uint sh = tile_shift(uint(side));
    return (uint(t.x) >> sh) == uint(tile.x) && (uint(t.y) >> sh) == uint(tile.y);
}

#endif

// Index (row-major) of the tile holding pixel p, tiles of `side` pixels over an image `width` wide.
uint tile_index(ivec2 p, uint width, uint side) {
    uint sh = tile_shift(side);
    return (uint(p.y) >> sh) * ((width + side - 1u) >> sh) + (uint(p.x) >> sh);
}

// Appends a tile (packed x | y << 16) to a list and grows its dispatch to cover it, each listed
// tile taking `invocations` invocations. A macro: GLSL cannot pass a buffer to a function.
#define TILE_APPEND(list, packed, invocations)                                                            \
    {                                                                                                     \
        uint slot_ = atomicAdd(list[3], 1u);                                                              \
        list[TILE_LIST_HEADER + slot_] = (packed);                                                        \
        atomicMax(list[0], ((slot_ + 1u) * (invocations) + uint(FGSR_GROUP * FGSR_GROUP) - 1u) /          \
                               uint(FGSR_GROUP * FGSR_GROUP));                                            \
    }

#ifdef FGSR_TILED_KEYS
// Keys and field vectors as a full splat leaves them, where classify wrote neither for static
// tiles: a static source splats onto itself (own key, zero vectors), so a pixel of a static tile
// holds the nearer of its own key and what the moving tiles splatted there (keys[], filled empty
// by the host). Entry declares keys[], tile_flags[] and tile_list[], and includes motion.h.
uint64_t load_key(ivec2 q) {
    uint64_t k = keys[q.y * int(pc.g.width) + q.x];
    if ((tile_flags[tile_index(q, pc.g.width, tile_list[4])] & TILE_STATIC) == 0u) return k;
    uint64_t own = (uint64_t(floatBitsToUint(depth1[q.y * int(pc.g.width) + q.x])) << 32) |
                   uint64_t(uint(q.y) * pc.g.width + uint(q.x));
    return min(k, own);
}
vec4 load_motion(uint i) {
    if (i >= frame_pixels(pc.g)) return source_field_vectors(i, pc.g); // frame 0's leaving content
    uint y = udiv(i, pc.g.width);
    ivec2 q = ivec2(int(i - y * pc.g.width), int(y));
    return (tile_flags[tile_index(q, pc.g.width, tile_list[4])] & TILE_STATIC) != 0u ? vec4(0.0f)
                                                                                  : field_vectors_at(q, i, pc.g);
}
#endif
