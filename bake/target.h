// The least model a scene needs: the smallest (order, rate, grid) whose error on held-out
// (point, direction) pairs meets a target (`shrefract-bake --target-error DEG`).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"

namespace shrefract {

struct TargetCandidate {
    int order = 8, rate = 1;
    DirectionGrid grid;
    double medianDeg = 0, p95Deg = 0, meanDeg = 0;
    size_t samples = 0;        // unique samples of the whole scene at this rate
    size_t weightBytes = 0;    // samples x coefficients x 4 channels x 4 bytes (f32)
    double bakeCost = 0;       // samples x directions: paths to trace
};

struct TargetSearchOptions {
    double targetDeg = 10.0;  // on the median angular error over held-out pairs
    int points = 400;         // held-out surface points, area-weighted over all triangles
    int directionsPerPoint = 4;
    uint64_t seed = 12345;
    std::vector<int> orders{1, 2, 3, 4, 5, 6, 7, 8, 10, 12};
    std::vector<int> rates;   // empty: 1, 2, 3
    std::vector<DirectionGrid> grids{{8, 16}, {16, 32}, {32, 64}, {64, 128}};
};

struct TargetSearchResult {
    TargetCandidate chosen;     // the cheapest meeting the target, else the most accurate
    TargetCandidate reference;  // the paper's fixed model: order 8, `base` rate, 32 x 64
    bool reached = false;
    std::vector<TargetCandidate> all;
    nlohmann::json ToJson() const;
};

// Held-out pairs are random points inside triangles (not samples) and random directions (not
// grid directions), truth from fresh traces; predictions interpolate decompressed samples
// across the triangle exactly as the runtime's rho lookup does. Lower orders are truncations
// of one projection (M's rows do not depend on L), so each (rate, grid) is traced once.
TargetSearchResult searchTarget(const Scene& scene, const BakeOptions& base,
                                const TargetSearchOptions& options);

}  // namespace shrefract
