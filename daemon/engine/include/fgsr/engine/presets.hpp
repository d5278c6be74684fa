// Quality presets and named single switches of fgsr::Params, defined once for every front end
// (`fgsr eval --preset`, `fgsr bench`, the daemon).
//
// Presets span the run-time / error trade-off (figures: docs/PERFORMANCE.md):
//   performance  uniform-velocity motion (Eqs. 14-15, no frame-0 vector lookups), no gap refinement,
//                the paper's select blend, bilinear warps and SR history resampling, fused passes;
//                without vectors, fast motion estimation (no refinement of the estimated vectors).
//   balanced     uniform-acceleration motion, gap and hole filling, mix blend, the warps' kernel
//                chosen by the input (warp=auto: the cubic in interpolation of antialiased input),
//                bilinear SR history resampling (on orbit-sr as good as the LUT and cheaper), fused
//                passes; no edge rule of ingest's dilate stage (on CPU devices a third to all of
//                ingest's time again).
//   quality      everything on: uniform acceleration, gap and hole filling, mix blend, the learned
//                LUT for SR history, depth-informed vector dilation, the dilate stage's edge rule,
//                frame generation from both fields by agreement with vectors (switch colour_agree:
//                per pixel the frame from motion estimated from colour where it explains the colour
//                and the given vectors do not; train interp +8.67 dB summed, sundial-fg +3.53,
//                street-fg +2.67, mobfgsr-bunker HR +0.91; validation interp fan-fg -0.18, the
//                rest up or within 0.003; several times a frame's cost on CPU devices:
//                docs/ACCURACY.md, changes 33-37, 41; as the default Params), fused passes (the
//                separate passes give the same frames, only slower). Not the correction of given
//                vectors by colour (switch correct_vectors): it gains where shading moves on its
//                own (street-fg interp +1.77 dB, shadow-fg +0.27 / +0.41) and loses up to 0.08 dB
//                elsewhere (pan, spin, cut; docs/ACCURACY.md, changes 4 and 27), at several times
//                the cost of a frame on CPU devices, and is refused with super resolution.
// balanced and quality estimate colour-only motion with DIS's patch inverse search on the coarse
// levels (switch motion_search; docs/ACCURACY.md, change 40: mobfgsr-bunker HR +0.84 dB, validation
// up on every row, about 1.2x a 480x270 colour-only frame's time on lavapipe and 1.4x a 1080p one's).
// Thresholds (t_depth, t_bright, sr_a, sr_b) are the calibrated defaults in every preset; the SR
// pre-filter of noisy input (denoise) is on in every preset (on clean input it filters nothing),
// and so is the scene-cut test of sessions with vectors (vector_cuts). The frame-0 depth test's
// expected depth change (accel_depth) is in quality only, with the two other refinements of the
// acceleration (accel_search, accel_median).
//
// Switches are "key=value" settings of one field each, e.g. "motion=linear", "resample=lut",
// "fill_gaps=off", "passes=separate"; kSwitches lists every key and its values, and
// switch_toggles() names the settings that differ from a base (what `fgsr bench` toggles one at a
// time from `balanced`).
//
// Thread-safety: every function here is pure (no shared state).
#pragma once

#include <fgsr/engine/engine.hpp>

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fgsr {

enum class Preset : uint32_t { performance = 0, balanced = 1, quality = 2 };

inline constexpr std::array<std::string_view, 3> kPresetNames{"performance", "balanced", "quality"};

inline Params preset_params(Preset preset) {
    Params p;
    p.separate_passes = false;
    switch (preset) {
    case Preset::performance:
        p.motion = MotionModel::linear;
        p.fast_motion = true;
        p.fill_gaps = false;
        p.fill_holes = true; // without it holes keep garbage vectors: large error for little time
        p.blend = BlendMode::select;
        p.resample = Resample::bilinear;
        p.dilate_mvs = false;
        p.dilate_edges = 0.f;
        p.accel_search = false;
        p.accel_median = false;
        p.accel_depth_motion = false;
        p.cover_edges = false;
        p.hole_frame0 = false;                // the holes' ring search in extrapolation
        p.warp_kernel = WarpKernel::bilinear; // the cubic's 16 reads a warped sample
        p.warp_resample = Resample::bilinear; // ISR's too
        p.motion_search = false;              // fast_motion refines nothing anyway
        p.colour_agree = false;
        break;
    case Preset::balanced:
        p.motion = MotionModel::quadratic;
        p.fill_gaps = true;
        p.fill_holes = true;
        p.blend = BlendMode::mix;
        p.resample = Resample::bilinear;
        p.dilate_mvs = false;
        p.dilate_edges = 0.f;
        p.accel_search = false;
        p.accel_median = false;
        p.accel_depth_motion = false;
        p.cover_edges = true;
        p.hole_frame0 = true;
        p.motion_search = true;
        p.colour_agree = false; // several times a frame's cost on CPU devices
        break;
    case Preset::quality:
        p.motion = MotionModel::quadratic;
        p.fill_gaps = true;
        p.fill_holes = true;
        p.blend = BlendMode::mix;
        p.resample = Resample::lut;
        p.dilate_mvs = true;
        p.dilate_edges = defaults::dilate_edges;
        p.accel_search = true;
        p.accel_median = true;
        p.accel_depth_motion = true; // docs/ACCURACY.md, changes 21, 23
        p.cover_edges = true;
        p.hole_frame0 = true;
        p.motion_search = true;
        p.colour_agree = true; // docs/ACCURACY.md, change 41
        break;
    }
    return p;
}

// By name (one of kPresetNames); invalid_argument naming the known presets otherwise.
inline Result<Params> preset_params(std::string_view name) {
    for (size_t i = 0; i < kPresetNames.size(); ++i)
        if (name == kPresetNames[i]) return preset_params(Preset(i));
    return make_error(Errc::invalid_argument,
                      "unknown preset '" + std::string(name) + "' (presets: performance, balanced, quality)");
}

// The names of the resampling kernels (Params::resample, Params::warp_resample), indexed by
// Resample's value, as the "resample" switch below and `fgsr eval --resample / --warp-resample`
// spell them.
inline constexpr std::array<std::string_view, 3> kResampleNames{"bilinear", "catmull_rom", "lut"};
inline std::string_view resample_name(Resample r) {
    return uint32_t(r) < kResampleNames.size() ? kResampleNames[uint32_t(r)] : kResampleNames.back();
}
// The kernel a name (resample_name) stands for; nullopt for any other name.
inline std::optional<Resample> resample_from_name(std::string_view name) {
    for (uint32_t i = 0; i < kResampleNames.size(); ++i)
        if (kResampleNames[i] == name) return Resample(i);
    return std::nullopt;
}

// One named switch: a Params field and the values it can take.
struct SwitchInfo {
    std::string_view key;
    std::array<std::string_view, 3> values; // empty entries unused
    std::string_view meaning;
};

// clang-format off
inline constexpr std::array<SwitchInfo, 22> kSwitches{{
    {"motion", {"linear", "quadratic", ""}, "uniform velocity (Eqs. 14-15) or uniform acceleration"},
    {"resample", kResampleNames, "SR history resampling"},
    {"fill_gaps", {"on", "off", ""}, "refine: fill splatting gaps"},
    {"fill_holes", {"on", "off", ""}, "disocc: give disocclusion holes a vector"},
    {"blend", {"select", "mix", ""}, "where both warped frames agree: closer frame or alpha mix"},
    {"dilate_mvs", {"on", "off", ""}, "SR: vector of the frontmost 3x3 neighbour"},
    {"denoise", {"on", "off", ""}, "SR: pre-filter input whose estimated noise exceeds the floor"},
    {"passes", {"fused", "separate", ""}, "one fused generate pass or refine/disocc/warp/blend"},
    {"correct_vectors", {"on", "off", ""}, "given vectors corrected where shading moves (shadows)"},
    {"fast_motion", {"on", "off", ""}, "without vectors: no refinement of the estimated vectors"},
    {"dilate_edges", {"on", "off", ""}, "ingest: edge pixels take the front's vector where colour follows it"},
    {"accel_search", {"on", "off", ""}, "extrapolation: frame-0 vector of the smallest acceleration among same-surface neighbours"},
    {"accel_median", {"on", "off", ""}, "interpolation: median acceleration of the same surface's 3x3 neighbours"},
    {"accel_depth", {"on", "off", ""}, "quadratic motion: frame-0 depth test expects the depth change the motion implies"},
    {"blend_depth", {"on", "off", ""}, "interpolation: frame 0's depth against what frame 1 shows within a pixel, with its vectors' depth change"},
    {"warp", {"auto", "bilinear", "cubic"}, "warps' colour kernel: auto = cubic in interpolation of input that measures antialiased"},
    {"cover_edges", {"on", "off", ""}, "disocc: a hole pixel that a front surface's footprint overlaps takes its vectors"},
    {"hole_frame0", {"on", "off", ""}, "disocc, extrapolation: a hole takes frame 0 where frame 1's sample lies on the surface that left"},
    {"vector_cuts", {"on", "off", ""}, "with vectors: a frame whose vectors do not explain its colour is a scene cut"},
    {"motion_consensus", {"on", "off", ""}, "without vectors: ambiguous blocks of the coarse levels take their neighbours' consensus"},
    {"colour_agree", {"on", "off", ""}, "per pixel the frame from vectors estimated from colour where they explain the colour and the given vectors do not"},
    {"motion_search", {"on", "off", ""}, "without vectors: patch inverse search and densification on the coarse levels (DIS)"},
}};
// clang-format on

// The value of switch `key` in p ("" for an unknown key).
inline std::string_view switch_value(const Params& p, std::string_view key) {
    auto onoff = [](bool b) { return b ? std::string_view("on") : std::string_view("off"); };
    if (key == "motion") return p.motion == MotionModel::linear ? "linear" : "quadratic";
    if (key == "resample") return resample_name(p.resample);
    if (key == "fill_gaps") return onoff(p.fill_gaps);
    if (key == "fill_holes") return onoff(p.fill_holes);
    if (key == "blend") return p.blend == BlendMode::select ? "select" : "mix";
    if (key == "dilate_mvs") return onoff(p.dilate_mvs);
    if (key == "denoise") return onoff(p.denoise);
    if (key == "passes") return p.separate_passes ? "separate" : "fused";
    if (key == "correct_vectors") return onoff(p.correct_vectors);
    if (key == "fast_motion") return onoff(p.fast_motion);
    if (key == "dilate_edges") return onoff(p.dilate_edges > 0.f);
    if (key == "accel_search") return onoff(p.accel_search);
    if (key == "accel_median") return onoff(p.accel_median);
    if (key == "accel_depth") return onoff(p.accel_depth_motion);
    if (key == "blend_depth") return onoff(p.blend_depth_motion);
    if (key == "warp")
        return p.warp_kernel == WarpKernel::bilinear ? "bilinear"
               : p.warp_kernel == WarpKernel::cubic  ? "cubic"
                                                     : "auto";
    if (key == "cover_edges") return onoff(p.cover_edges);
    if (key == "hole_frame0") return onoff(p.hole_frame0);
    if (key == "vector_cuts") return onoff(p.vector_cuts);
    if (key == "motion_consensus") return onoff(p.motion_consensus);
    if (key == "colour_agree") return onoff(p.colour_agree);
    if (key == "motion_search") return onoff(p.motion_search);
    return "";
}

// Applies one "key=value" setting; invalid_argument naming the key or value otherwise (p unchanged).
inline Result<void> apply_switch(Params& p, std::string_view setting) {
    const size_t eq = setting.find('=');
    const std::string_view key = setting.substr(0, eq);
    const std::string_view value = eq == std::string_view::npos ? std::string_view() : setting.substr(eq + 1);
    const SwitchInfo* info = nullptr;
    for (const SwitchInfo& s : kSwitches)
        if (s.key == key) info = &s;
    if (!info)
        return make_error(
            Errc::invalid_argument,
            "unknown switch '" + std::string(key) + "' in '" + std::string(setting) +
                "' (switches: motion, resample, fill_gaps, fill_holes, blend, dilate_mvs, denoise, passes, "
                "correct_vectors, fast_motion, dilate_edges, accel_search, accel_median, accel_depth, "
                "blend_depth, warp, cover_edges, hole_frame0, vector_cuts, motion_consensus, colour_agree, "
                "motion_search)");
    bool known = false;
    for (std::string_view v : info->values) known = known || (!v.empty() && v == value);
    if (!known) {
        std::string values;
        for (std::string_view v : info->values)
            if (!v.empty()) values += (values.empty() ? "" : ", ") + std::string(v);
        return make_error(Errc::invalid_argument, "switch " + std::string(key) + " has no value '" +
                                                      std::string(value) + "' (values: " + values + ")");
    }
    const bool on = value == "on";
    if (key == "motion") p.motion = value == "linear" ? MotionModel::linear : MotionModel::quadratic;
    if (key == "resample") p.resample = *resample_from_name(value); // a known value, checked above
    if (key == "fill_gaps") p.fill_gaps = on;
    if (key == "fill_holes") p.fill_holes = on;
    if (key == "blend") p.blend = value == "select" ? BlendMode::select : BlendMode::mix;
    if (key == "dilate_mvs") p.dilate_mvs = on;
    if (key == "denoise") p.denoise = on;
    if (key == "passes") p.separate_passes = value == "separate";
    if (key == "correct_vectors") p.correct_vectors = on;
    if (key == "fast_motion") p.fast_motion = on;
    if (key == "dilate_edges") p.dilate_edges = on ? defaults::dilate_edges : 0.f;
    if (key == "accel_search") p.accel_search = on;
    if (key == "accel_median") p.accel_median = on;
    if (key == "accel_depth") p.accel_depth_motion = on;
    if (key == "blend_depth") p.blend_depth_motion = on;
    if (key == "warp")
        p.warp_kernel = value == "bilinear" ? WarpKernel::bilinear
                        : value == "cubic"  ? WarpKernel::cubic
                                            : WarpKernel::automatic;
    if (key == "cover_edges") p.cover_edges = on;
    if (key == "hole_frame0") p.hole_frame0 = on;
    if (key == "vector_cuts") p.vector_cuts = on;
    if (key == "motion_consensus") p.motion_consensus = on;
    if (key == "colour_agree") p.colour_agree = on;
    if (key == "motion_search") p.motion_search = on;
    return {};
}

// Every "key=value" setting of kSwitches whose value differs from base's, in kSwitches order.
inline std::vector<std::string> switch_toggles(const Params& base) {
    std::vector<std::string> out;
    for (const SwitchInfo& s : kSwitches) {
        for (std::string_view v : s.values)
            if (!v.empty() && v != switch_value(base, s.key))
                out.push_back(std::string(s.key) + "=" + std::string(v));
    }
    return out;
}

} // namespace fgsr
