// The bake: trace every (surface sample, grid direction) path, project each sample's mapping
// onto SH with one GEMM per batch, low-pass, and hand back what the file stores.
//
// Samples are compressed in fixed batches of kBakeBatch, always with the same neighbours, so a
// bake cut into slices at batch boundaries (shards, checkpoints: bake/shard.h) computes the same
// weights bit for bit as one that runs whole.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "shrefract/enum_names.h"
#include "bake/chart_layout.h"
#include "bake/fit.h"
#include "bake/residual.h"
#include "bake/tracer.h"
#include "common/bakefile.h"
#include "common/direction_grid.h"
#include "common/error.h"
#include "common/scene.h"

namespace shrefract {

// Samples per batch: R is J x 4B. 32 keeps R (2048 x 128 floats = 1 MiB) in L2-ish reach and
// leaves enough batches for load balance. Part of a bake's identity: shards record it.
constexpr size_t kBakeBatch = 32;

struct BakeProgress {
    size_t samplesDone = 0, samplesTotal = 0;
    size_t samplesResumed = 0;  // of samplesDone, those an earlier run did (--resume)
    size_t rays = 0;            // traced by this run, in `seconds`
    double seconds = 0.0;
};

struct BakeOptions {
    // Sh: fit each sample's grid with SH (the paper). Grid: store the traced grid itself, one
    // coefficient per direction (docs/bake.md "The grid basis"): no fit, order 0; its error model
    // is traced apart, at the cells' corners (bake/residual.h).
    Basis basis = Basis::Sh;
    int order = 12;          // SH order L; 12 by the charts (docs/bake.md), the paper's is 8
    LayoutKind layout = LayoutKind::Joining;
    int rate = 0;            // joining: grid steps per triangle edge; 0: from `samples`
    size_t samples = 35000;  // target unique sample count when rate == 0 (the paper's bunny);
                             // chart layouts: target covered texels
    ChartOptions charts;     // isolated and uv (its kind and samples are set from the above)
    DirectionGrid grid;      // 32 x 64 = 2048 directions, the paper's count
    TraceOptions trace;
    bool coherent = true;    // trace a sample's paths as Embree streams (Tracer::traceCoherent)
    double filterWidth = 0.0;  // semi-Gaussian width in bands; <= 0: none
    Fit fit = Fit::Weighted;  // the default by the charts (docs/bake.md "Fits"); the paper: Projection
    FitWeighting weighting;    // for Fit::Weighted
    int errorOrder = kDefaultErrorOrder;  // the error model's SH order (bake/residual.h); < 0: none
    Precision precision = Precision::U8;  // by the charts: f32's accuracy at a quarter of the bytes
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
    double rhoOverhead = 0;  // rho texels per unique sample (chart layouts: atlas texels)
    ChartStats charts;       // isolated and uv layouts

    // Sums counts and seconds: the stats of a bake assembled from slices.
    BakeStats& operator+=(const BakeStats& o);
    // The manifest's "stats" object, and back.
    nlohmann::json ToJson() const;
    static BakeStats fromJson(const nlohmann::json& j);
};

// The weights of one slice of a bake's samples.
struct SliceResult {
    size_t first = 0, count = 0;  // samples [first, first + count)
    std::vector<float> weights;   // [(k * count + i) * 4 + c], as BakeData::weights
    std::vector<float> errors;    // [k * count + i], as BakeData::errors (empty: no error model)
    BakeStats stats;              // samples, paths, rays, flags, seconds of this slice
};

// Where a slice starts among the slices before it in this run, for progress reports.
struct SliceProgress {
    size_t samplesDone = 0, samplesResumed = 0, rays = 0;
    double seconds = 0;
};

// What every slice of one bake shares: the layout, the compression matrix with the band filter
// folded in, the directions and the tracer. Built once per process; the matrix and the tracer
// only when the first slice is baked (a merge needs neither).
class BakePlan {
public:
    BakePlan(const Scene& scene, const BakeOptions& options, const std::string& inputPath);
    ~BakePlan();
    BakePlan(const BakePlan&) = delete;
    BakePlan& operator=(const BakePlan&) = delete;

    const SurfaceLayout& layout() const { return layout_; }
    const BakeOptions& options() const { return opt_; }
    const Scene& scene() const { return scene_; }
    size_t sampleCount() const { return layout_.position.size(); }
    size_t batchCount() const { return (sampleCount() + kBakeBatch - 1) / kBakeBatch; }
    double setupSeconds() const { return setupSeconds_; }  // the layout's
    const ChartStats& chartStats() const { return charts_; }

    // Traces and compresses batches [beginBatch, endBatch): one GEMM per batch. Throws
    // Cancelled when options().cancel is set.
    SliceResult bakeSlice(size_t beginBatch, size_t endBatch, const SliceProgress& base = {}) const;
    // The descriptive manifest of the whole bake (docs/format.md), "stats" from `stats`.
    nlohmann::json manifest(const BakeStats& stats) const;
    // BakeData of the whole bake around `weights` (sampleCount x coefficients x 4) and the error
    // model's `errors` (sampleCount x error coefficients; empty when options().errorOrder < 0).
    BakeData data(std::vector<float> weights, std::vector<float> errors, const BakeStats& stats) const;
    // XXH3-64 of the samples' positions, normals and parts: what the tracing saw.
    std::string layoutChecksum() const;

private:
    const Scene& scene_;
    BakeOptions opt_;
    std::string input_;
    SurfaceLayout layout_;
    struct Compression;
    void prepareTracing() const;
    mutable std::once_flag prepared_;
    mutable std::unique_ptr<Compression> compression_;
    mutable std::unique_ptr<Tracer> tracer_;
    double setupSeconds_ = 0;
    ChartStats charts_;  // chart layouts: how the atlas came out
};

struct BakeResult {
    BakeData data;
    BakeStats stats;
};

// The whole bake in one slice. `inputPath` is recorded in the manifest so evaluation can
// re-trace the same scene.
BakeResult bake(const Scene& scene, const BakeOptions& options, const std::string& inputPath);

}  // namespace shrefract
