// Stage `dilate` of pass ingest (after the ingest stage, sessions with the client's vectors and
// depth in a linear colour format): the pixels around over-white content take its depth and vector.
//
// Why: the client's depth and vectors are point-sampled (one surface per pixel), its colour is
// antialiased, so the pixels just outside a bright object's silhouette hold part of its light. In
// display-referred output (clamped to white) a pixel that holds a twentieth of a lamp of strength
// 20 is white: its colour is the lamp's, and where it moves with the surface behind (its own
// vector) the generated frame leaves a white halo behind the lamp and a dark rim in front of it.
// So a pixel takes the depth and vector of the nearest over-white pixel of its 3x3 neighbourhood
// that lies in front of it (nearer by more than the relative tolerance). The ring around a lamp is
// often over-white itself (a tenth of strength 30 is 3): it counts as a source only with its own,
// undilated depth. Only behind over-white content: dilating every edge (the frontmost of 3x3, in
// the manner of QRISP's depth-informed dilation; the Mob-FGSR authors' code also dilates every
// input) gained 0.6 dB on alpha-tested foliage but lost 1.9-2.9 dB on the point-sampled
// synthetic scene and 0.1-0.3 dB on toss-fg's thin wires over a checker floor, whose rings carry mostly the
// floor's colour (docs/ACCURACY.md, change 11; QRISP's Table 3 also has PSNR fall with its
// dilation).
//
// Without races: depths and vectors are read as ingest stored them (the GPU build decodes them
// again from the client's planes, the CPU reference reads a copy), the results written over
// ingest's. The ingest stage flags every 16x16 tile with an over-white pixel in its 3x3
// (ingest.comp, note_bright): only pixels of flagged tiles can change, and the GPU build runs one
// invocation per tile, which returns after reading the flag or goes over its pixels (dilate.comp;
// the first form, one invocation per pixel and a store per pixel in ingest, cost ingest 1-2 ms
// more at 480x270 on lavapipe with no pixel over white; docs/ACCURACY.md, change 11).
//
// Entry provides:
//   vec4  load_frame_color(uint pixel) the ingested colour (linear)
//   float load_source_depth(uint pixel) depth and vector as ingest stored them (before this stage)
//   vec2  load_source_mv(uint pixel)
//   void  store_frame_depth_mv(uint pixel, float depth, vec2 mv)

FGSR_INLINE void dilate_pixel(uvec2 pix, IngestParams p) {
    if (pix.x >= p.width || pix.y >= p.height) return;
    uint i = pix.y * p.width + pix.x;
    float d = load_source_depth(i);
    float nearest = d;
    uint from = i;
    for (int k = 0; k < 9; ++k) {
        ivec2 q = ivec2(pix) + ivec2(k % 3 - 1, k / 3 - 1);
        if (k == 4 || q.x < 0 || q.y < 0 || q.x >= int(p.width) || q.y >= int(p.height)) continue;
        uint j = uint(q.y) * p.width + uint(q.x);
        if (linear_luminance(load_frame_color(j)) <= p.bright) continue;
        float dj = load_source_depth(j);
        if (dj < nearest && d - dj > p.bright_depth * dj) {
            nearest = dj;
            from = j;
        }
    }
    if (from != i) store_frame_depth_mv(i, nearest, load_source_mv(from));
}
