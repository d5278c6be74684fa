// Pass `ingest`: one client frame in its declared formats and conventions -> the internal
// convention (fgsr/core/types.hpp). One invocation per pixel.
//
// Entry provides:
//   uint  load_color_word(uint word)      raw colour plane as 32-bit words
//   uvec2 load_color_pair(uint pair)      its words 2 pair and 2 pair + 1 (one 64-bit access where
//                                         the entry can: CPU devices, shaders/load64.h)
//   uint  load_depth_word(uint pixel)     raw depth plane (one float per pixel)
//   uint  load_mv_word(uint word)         raw vector plane as 32-bit words
//   uvec2 load_mv_pair(uint pair)         its words 2 pair and 2 pair + 1
//   void  store_frame(uint pixel, uvec2 color, float depth, vec2 mv)   colour packed by pack_color
//   void  note_bright(uvec2 pixel, vec4 color, IngestParams p)  the dilate stage's tile flags
//                                         (shaders/dilate.h); a no-op where the stage does not run

FGSR_INLINE bool is_finite(float v) { return !(isnan(v) || isinf(v)); }

FGSR_INLINE float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}

// Linear view depth from the client's depth; FGSR_FAR_DEPTH for invalid or far-plane values.
FGSR_INLINE float linear_depth(float d, IngestParams p) {
    if (!is_finite(d)) return FGSR_FAR_DEPTH;
    float n = p.near_plane;
    float f = p.far_plane;
    bool infinite_far = !(f > 0.0f) || isinf(f);
    float z = d;
    if (p.depth_kind == 1u) { // device depth, 0 at near, 1 at far
        if (d >= 1.0f) return FGSR_FAR_DEPTH;
        z = infinite_far ? n / (1.0f - d) : (n * f) / (f - d * (f - n));
    } else if (p.depth_kind == 2u) { // reversed-Z, 1 at near, 0 at far
        if (d <= 0.0f) return FGSR_FAR_DEPTH;
        z = infinite_far ? n / d : (n * f) / (n + d * (f - n));
    }
    return (is_finite(z) && z > 0.0f) ? min(z, float(FGSR_FAR_DEPTH)) : float(FGSR_FAR_DEPTH);
}

FGSR_INLINE vec4 decode_color(uint pixel, IngestParams p) {
    vec4 c;
    if (p.color_format == 0u) {
        c = unpackUnorm4x8(load_color_word(pixel));
        c = vec4(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w);
    } else if (p.color_format == 1u) {
        uvec2 w = load_color_pair(pixel);
        c = vec4(unpackHalf2x16(w.x), unpackHalf2x16(w.y));
    } else {
        uvec2 w0 = load_color_pair(2u * pixel);
        uvec2 w1 = load_color_pair(2u * pixel + 1u);
        c = vec4(uintBitsToFloat(w0.x), uintBitsToFloat(w0.y), uintBitsToFloat(w1.x), uintBitsToFloat(w1.y));
    }
    // Non-finite channels become 0; negative light is clamped; HDR values are kept up to half max.
    for (int k = 0; k < 4; ++k) c[k] = is_finite(c[k]) ? clamp(c[k], 0.0f, 65504.0f) : 0.0f;
    return c;
}

FGSR_INLINE vec2 decode_mv(uint pixel, IngestParams p) {
    if (p.has_mv == 0u) return vec2(0.0f);
    vec2 m = p.mv_format == 0u ? unpackHalf2x16(load_mv_word(pixel)) : uintBitsToFloat(load_mv_pair(pixel));
    m = vec2(m.x * p.mv_scale_x + p.mv_offset_x, m.y * p.mv_scale_y + p.mv_offset_y);
    // Non-finite vectors carry no motion; huge ones are clamped so positions stay exact in float.
    float limit = 4.0f * float(p.width + p.height);
    return vec2(is_finite(m.x) ? clamp(m.x, -limit, limit) : 0.0f, is_finite(m.y) ? clamp(m.y, -limit, limit) : 0.0f);
}

FGSR_INLINE void ingest_pixel(uvec2 pix, IngestParams p) {
    if (pix.x >= p.width || pix.y >= p.height) return;
    uint i = pix.y * p.width + pix.x;
    float z = p.has_depth != 0u ? linear_depth(uintBitsToFloat(load_depth_word(i)), p) : 1.0f;
    vec4 c = decode_color(i, p);
    note_bright(pix, c, p);
    store_frame(i, pack_color(c), z, decode_mv(i, p));
}
