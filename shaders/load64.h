// Storage-buffer elements read and written as 64-bit words (GLSL entry files only: generate,
// generate_sr, ingest, splat and sr).
// On CPU devices (lavapipe) a storage-buffer access at a per-invocation index is a loop over the
// lanes with one bounds-checked scalar access per 32-bit component; as 64-bit words a packed
// colour (uvec2) is one access instead of two and a vec4 two instead of four. The bits are the
// same, so the values are exactly those of the 32-bit declarations (little-endian: component 0 in
// the low word).
#ifndef FGSR_SHADERS_LOAD64_H
#define FGSR_SHADERS_LOAD64_H
uvec2 as_uvec2(uint64_t w) { return uvec2(uint(w), uint(w >> 32)); }
vec2 as_vec2(uint64_t w) { return uintBitsToFloat(as_uvec2(w)); }
vec4 as_vec4(u64vec2 w) { return vec4(as_vec2(w.x), as_vec2(w.y)); }
uint64_t as_u64(uvec2 v) { return uint64_t(v.x) | (uint64_t(v.y) << 32); }
u64vec2 as_u64vec2(vec4 v) {
    return u64vec2(as_u64(floatBitsToUint(vec2(v.x, v.y))), as_u64(floatBitsToUint(vec2(v.z, v.w))));
}
#endif
