// The checks shared by the stress feeders (fgsr/capture/stress_checks.hpp).
#include <fgsr/capture/metrics.hpp>
#include <fgsr/capture/stress_checks.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace fgsr::stress {

bool contains_nocase(const std::string& hay, const std::string& needle) {
    auto lower = [](std::string s) {
        for (char& ch : s)
            if (ch >= 'A' && ch <= 'Z') ch = char(ch - 'A' + 'a');
        return s;
    };
    return lower(hay).find(lower(needle)) != std::string::npos;
}

size_t count_non_finite(std::span<const float> v) {
    size_t bad = 0;
    for (float x : v) bad += std::isfinite(x) ? 0 : 1;
    return bad;
}

std::string step_where(size_t i, Op op) {
    return "step " + std::to_string(i) + " (" +
           (op == Op::submit        ? "submit"
            : op == Op::interpolate ? "interpolate"
            : op == Op::extrapolate ? "extrapolate"
                                    : "super_resolve") +
           ")";
}

bool CaseChecks::fail(std::string why) {
    r_.pass = false;
    if (r_.failure.empty()) r_.failure = std::move(why);
    return false;
}

bool CaseChecks::check_values(std::span<const float> v, const std::string& what) {
    ++r_.outputs_checked;
    r_.values_checked += v.size();
    const size_t bad = count_non_finite(v);
    if (bad) return fail(what + ": " + std::to_string(bad) + " non-finite values");
    return true;
}

bool CaseChecks::check_repeat_and_drift(const Step& st, const std::vector<ImageRGBA>& images,
                                        const std::string& where) {
    if (st.same_as_previous) {
        bool same = previous_.size() == images.size();
        for (size_t k = 0; same && k < images.size(); ++k)
            same =
                previous_[k].rgba.size() == images[k].rgba.size() &&
                std::memcmp(previous_[k].rgba.data(), images[k].rgba.data(), images[k].rgba.size() * 4) == 0;
        if (!same) return fail(where + ": outputs differ from the identical previous request");
    }
    if (st.op == Op::interpolate || st.op == Op::extrapolate) previous_ = images;
    if (st.drift_reference >= 0 && !images.empty()) {
        if (drift_refs_.size() <= size_t(st.drift_reference))
            drift_refs_.resize(size_t(st.drift_reference) + 1);
        drift_refs_[size_t(st.drift_reference)] = images[0];
    }
    if (st.drift_compare >= 0 && !images.empty()) {
        if (size_t(st.drift_compare) >= drift_refs_.size() || !drift_refs_[size_t(st.drift_compare)])
            return fail(where + ": no drift reference " + std::to_string(st.drift_compare));
        auto p = capture::psnr(images[0], *drift_refs_[size_t(st.drift_compare)]);
        if (!p) return fail(where + ": " + p.error().message);
        r_.drift_db = r_.drift_db ? std::min(*r_.drift_db, *p) : *p;
    }
    return true;
}

bool CaseChecks::check_min_drift(double min_drift_db) {
    if (r_.drift_db && *r_.drift_db < min_drift_db) {
        char b[128];
        std::snprintf(b, sizeof b, "drift %.2f dB is below %.1f dB", *r_.drift_db, min_drift_db);
        return fail(b);
    }
    return true;
}

} // namespace fgsr::stress
