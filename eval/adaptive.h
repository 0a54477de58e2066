// Per-sample adaptive order (docs/bake.md "Per-sample adaptive order"): which bands each sample
// needs, and the bake a per-sample order would draw, so that its images can be measured before
// the format and the runtime carry variable-length coefficients.
#pragma once

#include <vector>

#include "common/bakefile.h"
#include "common/scene.h"

namespace shrefract {

// For each sample the smallest order whose reconstruction differs from the full-order one by at
// most `toleranceDeg` on average over 64 fixed directions of the hemisphere (the SH themselves are
// the yardstick, so no tracing is needed).
std::vector<int> adaptiveOrders(const BakeData& bake, double toleranceDeg);

// What a per-sample order would store and draw, one bake per entry of `orders` (each a sample's
// order, as adaptiveOrders gives): every sample's paths at the grid directions traced afresh in
// `scene` as the bake traced them, fitted at the sample's own order by the bake's fit (its
// weighting and filter), every higher band zero, so the runtime sums exactly the bands of a
// variable-length file; and the error model (when `bake` has one) fitted to what those bands
// miss of the traced paths. The files keep every band (and their bytes): only the images and the
// model are a per-sample order's. An SH bake with its grid and fit in the manifest.
std::vector<BakeData> perSampleOrderBakes(const BakeData& bake, const Scene& scene,
                                         const std::vector<std::vector<int>>& orders);

}  // namespace shrefract
