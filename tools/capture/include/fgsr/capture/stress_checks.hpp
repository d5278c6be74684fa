// The checks both stress feeders apply to a case (fgsr/capture/stress.hpp): the in-process one
// (run_on_engine) and the daemon one (fgsr/stress/daemon.hpp). One place decides what a failure,
// a non-finite output, a determinism break and a drift below the case's floor are, and how they are
// recorded in the CaseResult.
#pragma once

#include <fgsr/capture/stress.hpp>

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace fgsr::stress {

// Case-insensitive substring test (ASCII): rejection messages must mention the case's reason.
bool contains_nocase(const std::string& hay, const std::string& needle);

// Number of non-finite values.
size_t count_non_finite(std::span<const float> v);

// "step <i> (<op>)": how reports name a step.
std::string step_where(size_t i, Op op);

// The running verdict of one case. Not thread-safe; one per case run.
class CaseChecks {
  public:
    explicit CaseChecks(CaseResult& r) : r_(r) {}

    // Records the first failure (later ones are dropped); returns false.
    bool fail(std::string why);
    bool failed() const { return !r_.failure.empty(); }

    // One output's values: counted (outputs_checked, values_checked); fails with
    // "<what>: <n> non-finite values" when any is not finite.
    bool check_values(std::span<const float> v, const std::string& what);
    bool check_image(const ImageRGBA& img, const std::string& what) { return check_values(img.rgba, what); }

    // Determinism and drift of the outputs of a request `st` that succeeded (`where` names it):
    // same_as_previous requires bit-identical outputs to the previous interpolate/extrapolate
    // request's; drift_reference keeps the first output, drift_compare scores the first output
    // against that reference (PSNR) and keeps the minimum in drift_db.
    bool check_repeat_and_drift(const Step& st, const std::vector<ImageRGBA>& images,
                                const std::string& where);

    // After the last step: the drift, when measured, must be at least min_drift_db.
    bool check_min_drift(double min_drift_db);

  private:
    CaseResult& r_;
    std::vector<ImageRGBA> previous_;
    std::vector<std::optional<ImageRGBA>> drift_refs_;
};

} // namespace fgsr::stress
