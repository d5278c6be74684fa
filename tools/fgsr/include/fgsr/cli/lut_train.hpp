// `fgsr lut-train`: learns the resampling LUT (paper 3.5, 4; supplement 5) for one scale factor by
// optimising the result of six-fold repeated resampling with sub-pixel shifts, and scores it
// against bilinear and bicubic (Catmull-Rom) on held-back images. The model it trains is
// fgsr/cli/lut_model.hpp (the engine's shaders/resample.h arithmetic).
#pragma once

#include <fgsr/core/result.hpp>
#include <fgsr/engine/defaults.hpp>
#include <fgsr/engine/lut.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace fgsr::cli {

struct LutTrainOptions {
    float scale = 2.f;               // 1.5, 2, 3 or 4 (any value in [1, 8] is accepted)
    std::vector<std::string> images; // capture directories and/or "builtin" / "synthetic";
                                     // empty: {"builtin"}
    std::filesystem::path out;       // FILE.lut (fgsr::save_lut); FILE.json (provenance) beside it;
                                     // empty: nothing written
    int iterations = 600;            // Adam steps, >= 0 (0: evaluate the Catmull-Rom start)
    int batch = 16;                  // repeated-resampling sequences per step, >= 1
    // SR loops per step (>= 0; 0: the six-fold objective alone) and the weight of their loss: the
    // history resampling as the `sr` pass runs it (lutmodel::SrLoop), with Eq. 2's a and b.
    int sr_batch = 0;
    double sr_weight = 1.0;
    float sr_a = defaults::sr_a, sr_b = defaults::sr_b;
    float sr_noise = 0.5f;    // largest relative input noise of a loop (lutmodel::make_sr_loop), >= 0
    uint32_t seed = 1;        // training crops and shifts; the result depends on nothing else
                              // (not on the thread count)
    int threads = 2;          // >= 1
    bool progress = true;     // progress on stderr
    std::string command_line; // recorded in the JSON
};

struct MethodFigures {
    double ssim = 0, psnr = 0; // means over held-back images and shift sequences
};

struct LutTrainReport {
    Lut lut;
    std::vector<std::string> training_images, held_back_images;
    // Loss on a fixed validation batch (training images, other crops and shifts) before and after
    // training: six-fold (1 - SSIM) + sr_weight * SR loops (1 - SSIM), and the two parts.
    double initial_loss = 0, final_loss = 0;
    double initial_sixfold = 0, final_sixfold = 0, initial_sr = 0, final_sr = 0;
    double seconds = 0;
    // protocol ("half": six +1/2 px shifts as in the paper; "random": random sub-pixel shifts
    // summing to whole pixels) -> method ("lut", "bilinear", "bicubic", "catmull_rom_lut") -> figures
    std::map<std::string, std::map<std::string, MethodFigures>> figures;
};

// Trains and evaluates. Errors: invalid_argument for options out of range, io for unreadable
// captures or an unwritable output, empty_input when no training image remains.
Result<LutTrainReport> run_lut_train(const LutTrainOptions& options);

// Provenance JSON text (what FILE.json holds).
std::string lut_train_json(const LutTrainOptions& options, const LutTrainReport& report);

// CLI glue: registers the `lut-train` subcommand's options into `o` (returns the subcommand), and
// runs it (progress on stderr, figures table on stdout); returns the process exit code.
CLI::App* add_lut_train_command(CLI::App& app, LutTrainOptions& o);
int lut_train_main(LutTrainOptions& o, int argc, char** argv);

} // namespace fgsr::cli
