// The least model a scene needs, or the best one a budget buys: a search over (basis, order,
// rate, grid, precision) by the median angular error on held-out (point, direction) pairs
// (`shrefract-bake --target-error DEG` and `--budget MB`; docs/bake.md "Choosing the model").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"

namespace shrefract {

struct TargetCandidate {
    Basis basis = Basis::Sh;  // Grid: the traced grid itself, order 0 (docs/bake.md "The grid basis")
    int order = 8, rate = 1;
    DirectionGrid grid;
    Precision precision = Precision::F32;
    double medianDeg = 0, p95Deg = 0, meanDeg = 0;
    size_t samples = 0;        // unique samples of the whole scene at this rate
    size_t weightBytes = 0;    // samples x weightsTexelBytes(coefficients, precision)
    double bakeCost = 0;       // samples x directions: paths to trace
};

// Error: the fewest weight bytes (then the fewest paths) whose median meets `targetDeg`.
// Budget: the lowest median whose weights fit in `budgetBytes` (then the fewest bytes, paths).
enum class TargetGoal { Error, Budget };

struct TargetSearchOptions {
    TargetGoal goal = TargetGoal::Error;
    double targetDeg = 10.0;  // Error: on the median angular error over held-out pairs
    size_t budgetBytes = 0;   // Budget: the weights' bytes (file and GPU alike)
    int points = 400;         // held-out surface points, area-weighted over all triangles
    int directionsPerPoint = 4;
    uint64_t seed = 12345;
    std::vector<int> orders{1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 14, 16};
    std::vector<int> rates;   // empty: 1, 2, 3 and the base options' rate
    std::vector<DirectionGrid> grids{{8, 16}, {16, 32}, {32, 64}, {64, 128}};
    std::vector<Precision> precisions{Precision::F32, Precision::F16, Precision::U8};
    // Sh: every order at every grid; Grid: the grid itself, for the grids the runtime can hold
    // as a basis (limits::kMaxGridBasis directions).
    std::vector<Basis> bases{Basis::Sh, Basis::Grid};
    std::function<void(const std::string&)> log;  // a line per (rate, grid) traced; may be empty
};

struct TargetSearchResult {
    TargetCandidate chosen;     // by the goal; for Error, the most accurate when none meets it
    // The paper's fixed model: order 8, the base rate, 32 x 64, f32; measured whatever the options
    // restrict the search to.
    TargetCandidate reference;
    bool reached = false;       // Error: a candidate met the target (Budget: always)
    std::vector<TargetCandidate> all;  // every candidate searched (Budget: those within it)
    nlohmann::json ToJson() const;
};

// A held-out pair: a point inside a triangle (not a sample) and a direction (not a grid one),
// its truth from a fresh trace.
struct HeldOutPair {
    int triangle;       // in layout order: the parts in order, their triangles in order
    float u, v;         // barycentrics of corners 1, 2
    glm::vec3 omega;    // object space, toward the viewer
    glm::vec3 truth;    // exit direction of the fresh trace
};
std::vector<HeldOutPair> heldOutPairs(const Scene& scene, const TraceOptions& trace,
                                      const TargetSearchOptions& options);
// The angles (degrees, sorted) between each pair's truth and what `bake` predicts there, its
// samples interpolated across the triangle as the runtime's rho lookup does. A joining bake of
// the same scene.
std::vector<double> heldOutErrorsDeg(const BakeData& bake, const std::vector<HeldOutPair>& pairs);

// Each SH candidate is fitted as the bake would fit it (the base options' fit, band filter and
// weighting), each grid-basis one is the traced grid, and each is rounded to its precision (u8's scale and offset from the traced samples, not
// the whole bake's); only the samples the held-out triangles touch are traced, once per (rate,
// grid). A Budget search fits no candidate over the budget, and traces no (rate, grid) that has
// none within it. Throws InputError when no candidate fits the budget, naming the cheapest.
TargetSearchResult searchTarget(const Scene& scene, const BakeOptions& base,
                                const TargetSearchOptions& options);

}  // namespace shrefract
