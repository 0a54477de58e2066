// Checking a bake against fresh traces, and answering point queries as the runtime would.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common/bakefile.h"
#include "common/error.h"
#include "common/scene.h"

namespace shrefract {

// The scene a bake was made from: its manifest's input path (or `overridePath` if not empty),
// loaded with the baked medium. Throws InputError if it is missing or its mesh checksum
// differs from the one baked.
Scene sceneOfBake(const BakeData& bake, const std::string& bakePath, const std::string& overridePath = "");

// Random (sample, omega) pairs, omega uniform over the outer hemisphere (so almost surely
// between grid directions), decompressed against a fresh trace of the same path. Angular error
// in degrees: mean, median, p95, p99, max; path-length error; the shares of TIR, capped and
// re-entering paths, each with its own error. `order` < 0: all stored bands. "prediction": how
// well the bake's error model (predictedError) ranks the measured angles (Spearman, and the median
// measured error in each decile of the prediction), beside the old proxy, 1 - the resultant
// length |D.xyz| of the reconstruction. cos(theta) of omega
// is drawn uniformly in [zMin, zMax): [0, 0.1) probes grazing entry alone.
// `sampleOrder`, if given, is the order used at each sample (per-sample adaptive order).
nlohmann::json evaluateDirections(const BakeData& bake, const Scene& scene, size_t pairs,
                                  uint64_t seed, int order = -1, float zMin = 0.0f, float zMax = 1.0f,
                                  const std::vector<int>* sampleOrder = nullptr);

// Why queryBake refused a query: its index in p and w, and the problem.
struct QueryRefused : InputError {
    QueryRefused(size_t i, const std::string& problem) : InputError(problem), index(i) {}
    size_t index;
};

// For each object-space surface point p and view direction w (toward the viewer): the exit
// direction (normalized) and length the runtime would use there, interpolated across the
// nearest triangle exactly as the rho layout does (interpolateRho); for chart bakes looked up in
// the atlas as the runtime's refraction map holds it (chartRefractionMap: the bake's gutter,
// seam-aware). Viewer at infinity along w.
// Refuses (QueryRefused), on either layout, a point farther than `maxDistance` from the surface
// (object units; < 0: kQueryDistance of the samples' bounding-box diagonal) and a view direction
// below the surface there (w . n < -1e-4 |w|, n the nearest triangle's outward geometric normal):
// the bake knows nothing there, and an answer would look as good as any other.
constexpr float kQueryDistance = 1e-3f;
std::vector<glm::vec4> queryBake(const BakeData& bake, const std::vector<glm::vec3>& p,
                                 const std::vector<glm::vec3>& w, float maxDistance = -1.0f);

// Spearman's rank correlation of a and b (ties take their mean rank); 0 when either is constant.
double spearman(const std::vector<double>& a, const std::vector<double>& b);

// Summary statistics of a list of errors: mean, median, p95, p99, max, count.
nlohmann::json errorStats(std::vector<double> e);

}  // namespace shrefract
