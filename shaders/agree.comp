#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
layout(local_size_x = FGSR_GROUP, local_size_y = FGSR_GROUP) in;
layout(push_constant) uniform Push { AgreeParams p; } pc;
#if AGREE_STAGE == 4
// Extrapolation's stage 1 (agree.h, stage 4): the inputs and each field's frame-1 vectors.
layout(std430, binding = AGREE_FRAME_COLOR0) readonly buffer Color0 { uint64_t color0[]; }; // pack_color
layout(std430, binding = AGREE_FRAME_DEPTH0) readonly buffer Depth0 { float depth0[]; };
layout(std430, binding = AGREE_FRAME_COLOR1) readonly buffer Color1 { uint64_t color1[]; };
layout(std430, binding = AGREE_FRAME_DEPTH1) readonly buffer Depth1 { float depth1[]; };
layout(std430, binding = AGREE_GIVEN_MV) readonly buffer GivenMv { vec2 given_mv[]; };
layout(std430, binding = AGREE_COLOUR_MV) readonly buffer ColourMv { vec2 colour_mv[]; };
#include "load64.h"
vec4 load_frame_colour(uint frame, uint i) { return unpack_color(as_uvec2(frame == 0u ? color0[i] : color1[i])); }
float load_frame_depth(uint frame, uint i) { return frame == 0u ? depth0[i] : depth1[i]; }
vec2 load_field_mv(uint field, uint i) { return field == 0u ? given_mv[i] : colour_mv[i]; }
vec2 load_mv1(ivec2 q) { return given_mv[uint(q.y) * pc.p.g.width + uint(q.x)]; }
float load_depth1(ivec2 q) { return depth1[uint(q.y) * pc.p.g.width + uint(q.x)]; }
vec4 load_warped(uint field, uint frame, uint i) { return vec4(0.0f); }
vec4 load_given_field(uint i) { return vec4(0.0f); }
float load_warped_depth(uint field, uint frame, uint i) { return 0.0f; }
uint load_field_state(uint field, uint i) { return 0u; }
#else
layout(std430, binding = AGREE_GIVEN_W0) readonly buffer GivenW0 { vec4 given_w0[]; };
layout(std430, binding = AGREE_GIVEN_D0) readonly buffer GivenD0 { float given_d0[]; };
layout(std430, binding = AGREE_GIVEN_W1) readonly buffer GivenW1 { vec4 given_w1[]; };
layout(std430, binding = AGREE_GIVEN_D1) readonly buffer GivenD1 { float given_d1[]; };
layout(std430, binding = AGREE_GIVEN_STATE) readonly buffer GivenState { uint given_state[]; };
layout(std430, binding = AGREE_COLOUR_W0) readonly buffer ColourW0 { vec4 colour_w0[]; };
layout(std430, binding = AGREE_COLOUR_D0) readonly buffer ColourD0 { float colour_d0[]; };
layout(std430, binding = AGREE_COLOUR_W1) readonly buffer ColourW1 { vec4 colour_w1[]; };
layout(std430, binding = AGREE_COLOUR_D1) readonly buffer ColourD1 { float colour_d1[]; };
layout(std430, binding = AGREE_COLOUR_STATE) readonly buffer ColourState { uint colour_state[]; };
layout(std430, binding = AGREE_GIVEN_FIELD) readonly buffer GivenField { vec4 given_field[]; };
vec4 load_given_field(uint i) { return given_field[i]; }

vec4 load_warped(uint field, uint frame, uint i) {
    if (field == 0u) return frame == 0u ? given_w0[i] : given_w1[i];
    return frame == 0u ? colour_w0[i] : colour_w1[i];
}
float load_warped_depth(uint field, uint frame, uint i) {
    if (field == 0u) return frame == 0u ? given_d0[i] : given_d1[i];
    return frame == 0u ? colour_d0[i] : colour_d1[i];
}
uint load_field_state(uint field, uint i) { return field == 0u ? given_state[i] : colour_state[i]; }
vec4 load_frame_colour(uint frame, uint i) { return vec4(0.0f); }
float load_frame_depth(uint frame, uint i) { return 0.0f; }
vec2 load_field_mv(uint field, uint i) { return vec2(0.0f); }
vec2 load_mv1(ivec2 q) { return vec2(0.0f); }
float load_depth1(ivec2 q) { return 0.0f; }
#endif
layout(std430, binding = AGREE_GIVEN) buffer Given { vec4 given[]; };
layout(std430, binding = AGREE_COLOUR) readonly buffer Colour { vec4 colour[]; };
layout(std430, binding = AGREE_E) buffer E { vec2 e_buf[]; };
layout(std430, binding = AGREE_ROWS) buffer Rows { vec2 rows_buf[]; };
layout(std430, binding = AGREE_LIGHT) buffer Light { vec4 light_buf[]; };
layout(std430, binding = AGREE_LIGHT_ROWS) buffer LightRows { vec4 light_rows_buf[]; };
vec4 load_light(uint i) { return light_buf[i]; }
vec4 load_light_rows(uint i) { return light_rows_buf[i]; }
void store_light(uint i, vec4 v) { light_buf[i] = v; }
void store_light_rows(uint i, vec4 v) { light_rows_buf[i] = v; }

vec2 load_e(uint i) { return e_buf[i]; }
vec2 load_rows(uint i) { return rows_buf[i]; }
vec4 load_given(uint i) { return given[i]; }
vec4 load_colour(uint i) { return colour[i]; }
void store_rows(uint i, vec2 v) { rows_buf[i] = v; }
void store_agreed(uint i, vec4 c) { given[i] = c; }
void store_means(uint i, vec2 m) { e_buf[i] = m; }

#include "field.h"
#include "blend.h"
#include "agree.h"

// Stages 1, 4 and 5: one invocation per pixel; stages 2 and 6: per segment of a row (x: the
// segment, y: the row); stages 3, 7 and 8: per segment of a column (x: the column, y: the segment);
// stage 9: one invocation per output pixel.
void main() {
#if AGREE_STAGE == 2
    agree_rows_segment(gl_GlobalInvocationID.xy, pc.p);
#elif AGREE_STAGE == 6
    agree_light_segment(gl_GlobalInvocationID.xy, false, pc.p);
#elif AGREE_STAGE == 7
    agree_light_segment(gl_GlobalInvocationID.xy, true, pc.p);
#elif AGREE_STAGE == 3
    agree_column_segment(gl_GlobalInvocationID.xy, false, pc.p);
#elif AGREE_STAGE == 8
    agree_column_segment(gl_GlobalInvocationID.xy, true, pc.p);
#elif AGREE_STAGE == 9
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= int(pc.p.out_width) || t.y >= int(pc.p.out_height)) return;
    agree_mix_upscaled(t, pc.p);
#else
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(t, pc.p.g)) return;
    uint i = uint(t.y) * pc.p.g.width + uint(t.x);
#if AGREE_STAGE == 4
    e_buf[i] = agree_residual(t, pc.p);
#elif AGREE_STAGE == 5
    light_buf[i] = agree_light(t, pc.p);
#else
    e_buf[i] = agree_error(t, pc.p);
#endif
#endif
}
