// The reconstructed motion field of a generated frame, as refine, disocc, warp and blend see it.
//
// Per target pixel: v = (v0.xy, v1.xy), the displacement from the pixel centre to the position of
// its surface point in frame 0 and in frame 1 (backward warp: sample frame k at centre + vk), the
// frame-1 depth of that point (FGSR_FAR_DEPTH when unknown) and a state:
#define FIELD_SPLATTED 0u    // written by splatting
#define FIELD_GAP_FILLED 1u  // grid-like gap filled by the mean of its neighbours (refine)
#define FIELD_HOLE 2u        // nothing reached it: disocclusion (extrapolation) or occlusion (interpolation)
#define FIELD_HOLE_FILLED 3u // hole given a vector by disocc; in interpolation only frame 0 sees it

struct FieldSample {
    vec4 v;
    float depth;
    uint state;
};

FGSR_INLINE FieldSample field_sample(vec4 v, float depth, uint state) {
    FieldSample f;
    f.v = v;
    f.depth = depth;
    f.state = state;
    return f;
}
