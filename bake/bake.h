// The bake: trace every (surface sample, grid direction) path, project each sample's mapping
// onto SH with one GEMM per batch, low-pass, and hand back what the file stores.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "bake/fit.h"
#include "bake/tracer.h"
#include "common/bakefile.h"
#include "common/direction_grid.h"
#include "common/error.h"
#include "common/scene.h"

namespace shrefract {

struct BakeProgress {
    size_t samplesDone = 0, samplesTotal = 0;
    size_t rays = 0;
    double seconds = 0.0;
};

// How each sample's grid of traced paths becomes SH weights (docs/bake.md "Fits").
enum class Fit {
    Projection,    // W = M R through the compression matrix (paper eq. 10)
    LeastSquares,  // solid-angle-weighted least squares on the grid samples
    Weighted,      // least squares weighted by each path's confidence (bake/fit.h)
};
const char* ToString(Fit fit);   // "projection" | "lsq" | "weighted"
Fit parseFit(const std::string& text);  // throws InputError

struct BakeOptions {
    int order = 8;           // SH order L
    int rate = 0;            // grid steps per triangle edge; 0: from `samples`
    size_t samples = 35000;  // target unique sample count when rate == 0 (the paper's bunny)
    DirectionGrid grid;      // 32 x 64 = 2048 directions, the paper's count
    TraceOptions trace;
    double filterWidth = 0.0;  // semi-Gaussian width in bands; <= 0: none
    Fit fit = Fit::Projection;
    FitWeighting weighting;    // for Fit::Weighted
    Precision precision = Precision::F32;
    int threads = 0;         // 0: all cores
    std::string cacheDir;    // compression matrix cache; empty: none
    std::function<void(const BakeProgress&)> progress;  // called from worker threads, throttled
    const std::atomic<bool>* cancel = nullptr;          // set it to stop; bake() then throws
};

struct BakeStats {
    size_t samples = 0, paths = 0, rays = 0;
    size_t tir = 0, capped = 0, softCapped = 0, reentered = 0, geometricNormal = 0, leaked = 0;
    double traceSeconds = 0, compressSeconds = 0;  // summed over threads
    double wallSeconds = 0;
    double rhoOverhead = 0;  // rho texels per unique sample
};

struct BakeResult {
    BakeData data;
    BakeStats stats;
};

// `inputPath` is recorded in the manifest so evaluation can re-trace the same scene.
BakeResult bake(const Scene& scene, const BakeOptions& options, const std::string& inputPath);

// The stored functions' band l, for the filter: even order k -> l.
std::vector<int> evenBands(int L);

}  // namespace shrefract
