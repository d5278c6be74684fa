// Pass `refine` (paper 3.3): resolves splat keys into motion vectors and fills the grid-like gaps
// that nearest-pixel splatting leaves. A pixel nobody splatted to is a gap when no 2x2 block of
// empty pixels contains it in its 3x3 neighbourhood (a thin hole, an artefact of splatting); it is
// then filled with the mean of the neighbouring vectors that belong to the nearest surface among
// them (relative depth within T_D of the nearest). A pixel inside a 2x2 empty block is a real hole
// and is left to disocc.
//
// Entry provides (besides motion.h's loads):
//   uint64_t load_key(ivec2 pixel)     splat result of the generated frame

FGSR_INLINE bool key_empty(uint64_t k) { return uint(k & uint64_t(0xffffffffu)) == FGSR_EMPTY_KEY_LO; }
FGSR_INLINE uint key_source(uint64_t k) { return uint(k & uint64_t(0xffffffffu)); }
FGSR_INLINE float key_depth(uint64_t k) { return uintBitsToFloat(uint(k >> 32)); }

// vec4(v0, v1) of the target pixel that frame-1 source pixel `src` splatted to.
FGSR_INLINE vec4 field_from_source(uint src, GenParams g) {
    ivec2 p1 = ivec2(int(src % g.width), int(src / g.width));
    vec4 m = source_motion(p1, g);
    vec2 pt = vec2(m.x, m.y);
    vec2 c1 = vec2(p1) + vec2(0.5f);
    return vec4(vec2(m.z, m.w) - pt, c1 - pt);
}

FGSR_INLINE bool empty_at(ivec2 q, GenParams g) {
    // Off-screen neighbours never make a block empty: a gap on the border is still a gap.
    return inside(q, g) && key_empty(load_key(q));
}

FGSR_INLINE FieldSample refine_field(ivec2 t, GenParams g) {
    uint64_t k = load_key(t);
    if (!key_empty(k)) return field_sample(field_from_source(key_source(k), g), key_depth(k), FIELD_SPLATTED);
    // Empty: look for a 2x2 block of empty pixels containing t.
    bool hole = false;
    for (int by = -1; by <= 0; ++by)
        for (int bx = -1; bx <= 0; ++bx) {
            bool all_empty = true;
            for (int y = 0; y <= 1; ++y)
                for (int x = 0; x <= 1; ++x)
                    if (!(x == -bx && y == -by)) all_empty = all_empty && empty_at(t + ivec2(bx + x, by + y), g);
            hole = hole || all_empty;
        }
    if (!hole && g.fill_gaps != 0u) {
        float nearest = FGSR_FAR_DEPTH;
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = t + ivec2(x, y);
                if (inside(q, g)) {
                    uint64_t kq = load_key(q);
                    if (!key_empty(kq)) nearest = min(nearest, key_depth(kq));
                }
            }
        vec4 sum = vec4(0.0f);
        float n = 0.0f;
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = t + ivec2(x, y);
                if (inside(q, g)) {
                    uint64_t kq = load_key(q);
                    if (!key_empty(kq) && key_depth(kq) <= nearest * (1.0f + g.t_depth)) {
                        sum += field_from_source(key_source(kq), g);
                        n += 1.0f;
                    }
                }
            }
        if (n > 0.0f) return field_sample(sum / n, nearest, FIELD_GAP_FILLED);
    }
    return field_sample(vec4(0.0f), FGSR_FAR_DEPTH, FIELD_HOLE);
}
