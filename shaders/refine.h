// Pass `refine` (paper 3.3): resolves splat keys into motion vectors and fills the grid-like gaps
// that nearest-pixel splatting leaves. A pixel nobody splatted to is a gap when no 2x2 block of
// empty pixels contains it in its 3x3 neighbourhood (a thin hole, an artefact of splatting); it is
// then filled with the mean of the neighbouring vectors that belong to the nearest surface among
// them (relative depth within T_D of the nearest). A pixel inside a 2x2 empty block is a real hole
// and is left to disocc.
//
// Entry provides:
//   uint64_t load_key(ivec2 pixel)     splat result of the generated frame
//   vec4     load_motion(uint source)  field vectors (v0, v1) splat stored for a frame-1 pixel

FGSR_INLINE bool key_empty(uint64_t k) { return uint(k & uint64_t(0xffffffffu)) == FGSR_EMPTY_KEY_LO; }
FGSR_INLINE uint key_source(uint64_t k) { return uint(k & uint64_t(0xffffffffu)); }
FGSR_INLINE float key_depth(uint64_t k) { return uintBitsToFloat(uint(k >> 32)); }

FGSR_INLINE FieldSample refine_field(ivec2 t, GenParams g) {
    uint64_t k = load_key(t);
    if (!key_empty(k)) return field_sample(load_motion(key_source(k)), key_depth(k), FIELD_SPLATTED);
    // Empty: read the 3x3 neighbourhood once (off-screen neighbours count as not empty, so that a
    // gap on the border is still a gap), then look for a 2x2 block of empty pixels containing t.
    uint64_t nk[9];
    uint empty = 0u; // bit (y+1)*3 + (x+1): on screen and nobody splatted there
    uint known = 0u; // bit (y+1)*3 + (x+1): on screen and splatted
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = t + ivec2(x, y);
            uint bit = 1u << uint((y + 1) * 3 + (x + 1));
            nk[(y + 1) * 3 + (x + 1)] = uint64_t(0u);
            if (inside(q, g)) {
                uint64_t kq = load_key(q);
                nk[(y + 1) * 3 + (x + 1)] = kq;
                if (key_empty(kq)) empty |= bit;
                else known |= bit;
            }
        }
    // The four 2x2 blocks containing the centre (bit 4): corners 0, 2, 6, 8.
    const uint b00 = (1u << 0) | (1u << 1) | (1u << 3) | (1u << 4), b10 = (1u << 1) | (1u << 2) | (1u << 4) | (1u << 5);
    const uint b01 = (1u << 3) | (1u << 4) | (1u << 6) | (1u << 7), b11 = (1u << 4) | (1u << 5) | (1u << 7) | (1u << 8);
    bool hole = (empty & b00) == b00 || (empty & b10) == b10 || (empty & b01) == b01 || (empty & b11) == b11;
    if (!hole && g.fill_gaps != 0u) {
        float nearest = FGSR_FAR_DEPTH;
        for (int j = 0; j < 9; ++j)
            if ((known & (1u << uint(j))) != 0u) nearest = min(nearest, key_depth(nk[j]));
        vec4 sum = vec4(0.0f);
        float n = 0.0f;
        for (int j = 0; j < 9; ++j)
            if ((known & (1u << uint(j))) != 0u && key_depth(nk[j]) <= nearest * (1.0f + g.t_depth)) {
                sum += load_motion(key_source(nk[j]));
                n += 1.0f;
            }
        if (n > 0.0f) return field_sample(sum / n, nearest, FIELD_GAP_FILLED);
    }
    return field_sample(vec4(0.0f), FGSR_FAR_DEPTH, FIELD_HOLE);
}
