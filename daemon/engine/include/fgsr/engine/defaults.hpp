// Default algorithm parameters. `fgsr calibrate --write-defaults` rewrites this file with the
// values it fits on captures (and records how in the comment below); otherwise they are the
// paper's (Mob-FGSR section 4) or were chosen by hand as noted.
//
// Depth threshold: relative (|d0 - d1| / min(d0, d1)), so it holds for any linear depth unit; the
// paper's T_D = 0.0028 is absolute in its Unreal depth units (about [0.02, 0.43] on bunker).
// Calibration (2026-11-22): build/bin/fgsr calibrate --capture ../shared/captures/blender/toss-fg
//   --capture ../shared/captures/mobfgsr-bunker --capture ../shared/captures/blender/orbit-sr --frames 6
//   (85 evaluations, 16 min on 2 cores, lavapipe). Fitted: sr_a 0.34 -> 0.6598 (sr PSNR 22.39 ->
//   22.98 dB: bunker LR->HR 27.75 -> 28.43, orbit-sr 17.04 -> 17.53); sr_b stays 0.81; t_depth
//   0.05 -> 0.0557 moved the frame-generation score by 0.01 dB only (bunker wants more, toss-fg
//   less), so the hand-set 0.05 is kept; t_bright has no effect with the default mix blend.
// Recalibration of a and b (2026-11-22, after the jitter fix and with the denoise pre-filter):
//   build/bin/fgsr calibrate --capture ../shared/captures/blender/orbit-sr
//   --capture ../shared/captures/mobfgsr-bunker --fit sr_a,sr_b --modes sr --frames 6
//   (51 evaluations, 24 min on 2 busy cores, lavapipe; values copied from its table). Fitted:
//   sr_a 0.6598 -> 0.7466, sr_b 0.81 -> 1.09 (sr PSNR 24.012 -> 24.093: bunker LR->HR 28.428 ->
//   28.571, orbit-sr 19.595 -> 19.615, first 6 frames of each).
#pragma once

#include <cstdint>

namespace fgsr::defaults {

inline constexpr float t_depth = 0.05f;  // hand-set (relative depth)
inline constexpr float t_bright = 0.13f; // paper
inline constexpr float sr_a = 0.7466f;   // calibrated (paper: 0.34), see above
inline constexpr float sr_b = 1.09f;     // calibrated (paper: 0.81), see above
// ISR / ESR history clipping width in LR standard deviations (shaders/generate_sr.h), chosen on
// the train captures of docs/ACCURACY.md by a sweep 0.5 / 0.65 / 0.7 / 0.75 / 1 / off (isr and
// esr, fgsr method): street-sr isr 15.90 dB off -> 17.13 at 0.7 (0.5: 17.95 but bunker LR isr
// 27.71, below bicubic's 27.74; 0.75: 16.95); orbit-sr, foliage-sr, hdr-sr and bunker LR move by
// -0.05 to +0.09 dB at 0.7 (docs/ACCURACY.md, change 2).
inline constexpr float sr_clip = 0.7f;
// The same on input that measures antialiased (Params::sr_clip_antialiased): its 3x3 neighbourhood is
// low-passed, so 0.7 of its spread cuts the detail the SR history restores. Chosen on the train
// captures without jitter (street-, rotor-, foliage-, hdr-, shelf-sraa, bunker LR; isr and esr) from
// 0.7 / 1 / 1.25 / 1.5 / 2 / off: the sum of the 12 gains over 0.7 is 1.30 / 1.52 / 1.55 / 1.54 /
// 1.51 dB, the worst row -0.015 / -0.023 / -0.025 / -0.033 / -0.034 (rotor-sraa and bunker LR esr);
// 1.25 takes 98 % of the gain with the smaller loss (docs/ACCURACY.md, change 47).
inline constexpr float sr_clip_antialiased = 1.25f;
// Less SR history where it disagrees with the new samples (shaders/sr.h step 6), for sessions whose
// input carries no jitter and measures antialiased (Session::input_aliasing below
// antialiased_aliasing). k = 4 chosen on the train captures from 2 / 4 / 8 (bunker LR esr 27.08 /
// 27.22 / 27.26 dB, hdr-sr-aa esr 24.668 / 24.675 / 24.651; docs/ACCURACY.md).
inline constexpr float sr_disagree = 4.0f;
// Ingest's dilate stage (shaders/dilate.h): luminance (linear, 1 = display white) above which a
// pixel's light dominates its antialiased neighbours, so that they take its depth and vector.
// Chosen on the train captures (docs/ACCURACY.md, change 11): 1 and 2 gave hdr-fg the same gain,
// at 1 a white surface lit a little above 1 already counts.
inline constexpr float dilate_bright = 2.0f;
// ... its edge rule (shaders/dilate.h): the pixel behind a depth edge takes the front's vector
// where the previous frame's colour differs by less than this ratio times under its own vector.
// Chosen on the train captures from 0.4 / 0.5 / 0.6 / 0.7 (docs/ACCURACY.md, change 12): at 0.5
// no train capture loses more than 0.01 dB; at 0.6 and 0.7 the point-sampled builtin scene's
// extrapolation loses 0.006 / 0.024 dB.
inline constexpr float dilate_edges = 0.5f;
// The aliasing measure (fgsr/engine/color.hpp, aliasing_sums) below which input counts as
// antialiased: point-sampled renders measure 2.5-3.5, antialiased ones (16 samples) 0.6-1.0,
// bunker's frames about 1.0 (docs/ACCURACY.md, "No SR accumulation on antialiased input" and
// change 9). The session measures its first aliasing_frames frames without jitter.
inline constexpr float antialiased_aliasing = 1.6f;
inline constexpr uint32_t aliasing_frames = 8;
// Pre-filter of noisy SR input (shaders/denoise.h, docs/SR.md "Noisy input"): the range in noise
// sigmas, chosen by sweeps (k = 2..8) on three 1-sample point-sampled Blender captures (orbit-sr
// and two more rendered with render_scene.py: orbit seed 7, toss seed 3), where PSNR rises with
// k up to 5-6; on the analytic scene with added Gaussian noise k = 2 is best and 5 still gains at
// noise >= 0.2. The floor (linear units, soft: the noise above it is filtered) lies above what
// clean content estimates: bunker 0.0013-0.0017, the synthetic scene 0.012-0.026 at 120x80 and
// larger; it is crossed by dense detail in very small frames (0.06 at 80x53, docs/SR.md).
// Correction of given vectors by colour (Params::correct_vectors, shaders/flow.h step 4): a pixel
// takes an estimated vector where its cost (mean absolute display-luma difference over a 5-pixel
// cross, previous frame read bilinearly) is below ratio x the given vector's cost minus margin, and
// the given vector's previous position lies within `depth` (relative) of the pixel's depth. Chosen
// on the train captures of docs/ACCURACY.md (change 4): sweeps of ratio 0.3-1, margin 0-0.1, depth
// 0.05 / 0.1 / 0.3 / inf on street-fg, toss-fg and builtin, then 0.85 and 1 at margin 0.02, depth
// 0.3 on every train capture: street-fg interp 22.63 -> 24.24 dB (1: 24.34), bunker HR interp
// 30.54 -> 30.97 and extrap 28.84 -> 29.67; toss-fg, builtin, foliage-fg, hdr-fg -0.03 to +0.05.
// Depth 0.05 / 0.1 kept street-fg at 22.71 / 23.52: a forward-moving camera changes the ground's
// depth by more than 10 % between frames near the camera.
inline constexpr float correct_ratio = 0.85f;
inline constexpr float correct_margin = 0.02f;
inline constexpr float correct_depth = 0.3f;
// ... but the given vector's previous position no nearer than the pixel by more than 10 % (2 T_D):
// there the colour mismatch is background the motion uncovered, whatever the depth ratio
// (docs/ACCURACY.md, change 27; orbit-fg interp lost 0.18 dB without it). Train sums over the 22
// fgsr interp / extrap figures with the correction: no such test +4.28 (orbit-fg -0.18), 0.05
// +4.12 (twirl-fg +0.27 instead of +0.52), 0.1 +4.44, 0.2 +4.36 dB.
inline constexpr float correct_front = 0.1f;
// The agree pass (Params::colour_agree, shaders/agree.h): the box over which the two fields'
// disagreement is averaged (side 2 radius + 1), and the colour-only frame's weight. Until change 43
// the weight was the ramp clamp((ratio x given - colour - margin) / margin, 0, 1), margin 0.02;
// side and ratio were chosen with it. Chosen on the train fg captures of
// docs/ACCURACY.md (change 33) with a prototype on eval's outputs, from sides 5-31, ratios 0.5-1
// and margins 0.005-0.02 (measured with blend's depth band): side 21, ratio 1, margin 0.02 gained
// on every train capture (sundial-fg +3.16 dB, twirl-fg +0.96) and lost on none by 0.001; smaller
// sides and margins
// lost up to 1.1 dB on rotor-fg and 0.5 on orbit-fg (checker floors, turning blades).
inline constexpr uint32_t agree_radius = 10;
inline constexpr float agree_ratio = 1.0f;
// Since change 43 the weight is the logistic 1 / (1 + exp((colour + centre - ratio x given) /
// softness)): an even mix where the given field's mean disagreement exceeds the colour field's by
// centre (the old ramp's midpoint), and where the two agree equally a share of 1 / (1 + exp(centre /
// softness)) = 0.076 of the colour-only frame: two frames made from independent motion estimates
// err differently, and a little of the other lowers the error where neither measure can tell them
// apart. Chosen on the train fg captures (docs/ACCURACY.md, change 43) from centres 0.025-0.04 and
// softnesses 0.01-0.02 (first on eval's outputs mixed outside the engine, then with the engine): at
// 0.03 / 0.012 all 14 interp figures rose (+0.94 dB summed, mobfgsr-bunker HR +0.16, hdr-fg +0.20)
// and extrap +1.13 (orbit-fg -0.010 the one lower); softer (0.015-0.02) or lower (0.025) centres
// summed about as much or more but lost up to 0.19 on orbit-fg, vane-fg or slats-fg.
inline constexpr float agree_centre = 0.03f;
inline constexpr float agree_softness = 0.012f;
// ... measured where the two warped frames are one surface: depths within this times t_depth
// (relative). Blend's own band (1 x t_depth) leaves out most of a street the camera approaches
// (blend takes one frame, for depth or a frame off screen, at 77 % of street-fg's pixels), where
// the nearer frame is taken with its shading. Chosen on the
// same train captures after the rest, from 1 / 1.5 / 2 / 3 / 4 (street-fg +0.19 / +0.84 / +1.46 /
// +2.65 / +3.32 dB over no agree pass, twirl-fg +0.96 / +1.14 / +1.21 / +1.25 / +1.26, toss-fg
// +0.03 / +0.01 / -0.01 / -0.04 / -0.13): the largest sum with no capture lower by more than
// 0.005 (docs/ACCURACY.md, change 33). Since change 37 the band counts beyond the depth change the
// given field's motion implies; swept again then (1 / 1.5 / 2 / 3), 1.5 stayed.
inline constexpr float agree_depth_band = 1.5f;
// ... and in extrapolation (stage 4: frame 0's depth at t + mv against frame 1's at t, a whole frame
// step apart, where interpolation's warped frames are half a step from either input) within this
// times t_depth: a surface the camera approaches changes its depth by more between them (street-fg's
// road and walls at 7.5 %), and a band as tight as interpolation's took it for a disocclusion, whose
// residual counts 0, so the given field looked right there. Chosen on the train captures from 1.5 /
// 3 / 4 / 5 / 6 / 7 / 10 / none (summed extrap gains +1.11 / +1.17 / +1.28 at 3 / 4 / 5; street-fg
// +0.99 / +1.02 / +1.07, twirl-fg +0.08; from 6 on toss-fg -0.02 and lower, from 10 hdr-fg and
// rotor-fg too): the largest sum with no capture lower by more than 0.005 (docs/ACCURACY.md,
// change 36). Since change 37 beyond the depth change the given vectors imply (1.5 then lost 0.03 to
// 0.07 on twirl-fg, hdr-fg and orbit-fg; 5 stayed).
inline constexpr float agree_extrap_depth_band = 5.0f;
// ... and the colour-only frame's weight falls with the colour-only field's own mean disagreement
// (interpolation) or residual (extrapolation), to 0 at this (brightness units): where neither field
// explains the colour (turning blades, a turning ball's silhouette) the given frame is kept more.
// Chosen on the train fg captures with the prototypes of changes 33 and 34, from 0.1 / 0.15 / 0.2 /
// 0.3 and none: interp +4.43 / +4.71 / +4.77 / +4.76 / +4.43 dB summed (rotor-fg +0.02 -> +0.07,
// twirl-fg +0.96 -> +1.10, street-fg -0.004), extrap +5.02 at 0.15, +5.01 at 0.2, +4.40 none
// (docs/ACCURACY.md, change 35).
inline constexpr float agree_colour_limit = 0.2f;
// ... and in interpolation, stage 1 forgives each field a brightness gain between its two warped
// frames of up to this factor (brightness units, the square root of luminance: 1.06 is 12 % of
// light), fitted as the ratio of the frames' brightness sums over the box of side
// 2 agree_gain_radius + 1: a surface that turns towards or away from the light (pitched blades,
// slats) changes its shading uniformly by a few percent a frame, which its vectors cannot explain
// and the colour-only field, fitted to the colour, appears to. Chosen on the 14 train interp
// captures (docs/ACCURACY.md, change 42) from gains 1.06 / 1.1 / 1.2 and radii 5 / 8 / 12: 1.1 and
// 8 summed +0.52 dB but lost 0.028 on pan-s2-fg; 1.06 and 8 sums +0.47 (slats-fg +0.21 of the 0.36
// agreement cost it, sundial-fg +0.06, brickvane-fg +0.06), its largest losses pan-s2-fg -0.010 and
// mobfgsr-bunker HR -0.008 (every gain tried lost 0.008-0.018 there).
inline constexpr float agree_gain = 1.06f;
inline constexpr uint32_t agree_gain_radius = 8;
// Since change 17 of docs/ACCURACY.md the noise is measured relative to the local brightness to
// the power gamma (shaders/denoise.h): sunlit and shaded parts of one frame carry noise in
// proportion to their light, which one absolute level did not fit. Strength and gamma chosen on
// the train SR captures (street, orbit, hdr, foliage; bunker is clean and filtered by none) from
// gamma 0.5 / 0.75 / 1 and strength 3-7: gamma 0.75, strength 4 has the largest sum of their sr
// PSNR and every one of them gains over the absolute estimate (gamma 0, strength 5; street-sr
// +2.45 dB); gamma 1 loses hdr-sr 0.02 dB at every strength. The floor (0.03, now in units of
// brightness^0.75) still lies above bunker's estimate: its frames pass unchanged.
inline constexpr float denoise_strength = 4.0f;
inline constexpr float noise_floor = 0.03f;
inline constexpr float denoise_gamma = 0.75f;

} // namespace fgsr::defaults
