// Default algorithm parameters. `fgsr calibrate --write-defaults` rewrites this file with the
// values it fits on captures (and records how in the comment below); otherwise they are the
// paper's (Mob-FGSR section 4) or were chosen by hand as noted.
//
// Depth threshold: relative (|d0 - d1| / min(d0, d1)), so it holds for any linear depth unit; the
// paper's T_D = 0.0028 is absolute in its Unreal depth units (about [0.02, 0.43] on bunker).
#pragma once

namespace fgsr::defaults {

inline constexpr float t_depth = 0.05f;  // hand-set (relative depth)
inline constexpr float t_bright = 0.13f; // paper
inline constexpr float sr_a = 0.34f;     // paper
inline constexpr float sr_b = 0.81f;     // paper

} // namespace fgsr::defaults
