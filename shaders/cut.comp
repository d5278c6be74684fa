#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.h"
#include "bindings.h"
// Stage cut of pass ingest (shaders/cut.h), after ingest and its dilate stage, with their bindings
// and push constants: the frame's ingested colour and vectors against the previous frame's colour.
// One invocation per 8x8 block, in small workgroups (as the dilate stage's edge rule: a 480x270
// frame's 2040 blocks still spread over every CPU thread of lavapipe).
layout(local_size_x = FGSR_DILATE_EDGES_GROUP_X, local_size_y = FGSR_DILATE_EDGES_GROUP_Y) in;
layout(push_constant) uniform Push { IngestParams p; } pc;
layout(std430, binding = INGEST_COLOR) readonly buffer Color { uvec2 color[]; }; // pack_color
layout(std430, binding = INGEST_MV) readonly buffer Mv { vec2 mv[]; };
layout(std430, binding = INGEST_PREV_COLOR) readonly buffer PrevColor { uvec2 prev_color[]; }; // pack_color
layout(std430, binding = INGEST_CUT) writeonly buffer Cut { vec4 cut[]; }; // two per block

float load_cut_luma(uint i) { return motion_luma(unpack_color(color[i])); }
float load_cut_prev_luma(uint i) { return motion_luma(unpack_color(prev_color[i])); }
vec2 load_cut_mv(uint i) { return mv[i]; }
void store_cut_block(uint b, vec4 sad, vec4 level) {
    cut[2u * b] = sad;
    cut[2u * b + 1u] = level;
}

#include "cut.h"

void main() { cut_block(gl_GlobalInvocationID.xy, pc.p.width, pc.p.height); }
