// The discontinuity across seams in screen space (paper Figure 7, docs/evaluation.md "Seams"):
// the pairs of adjacent pixels that straddle a visible smooth seam of a chart layout, and the
// jump of the exit direction between the two pixels of each pair, for any method's render.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "bake/tracer.h"
#include "common/bakefile.h"
#include "eval/reference.h"

namespace shrefract {

// Two 4-adjacent pixels (indices y * width + x, row 0 at the top).
struct PixelPair {
    int a, b;
};

// Every pair of 4-adjacent pixels of `view` whose centres lie on the two sides of a smooth seam
// of `layout` (common/decompress.h smoothSeams) and whose primary rays both hit the surface next
// to it: the seam edges are projected (the reference camera), walked at a quarter pixel, and a
// candidate pair is kept when the segment between its two primary hits passes within a quarter
// of its length of the seam edge (so occluded seams and silhouettes drop out).
std::vector<PixelPair> seamPixelPairs(const Tracer& tracer, const SurfaceLayout& layout,
                                      const ReferenceView& view);

// The angle in degrees between the exit directions (xyz of `directions`, 4 floats per pixel,
// coverage in w) of the two pixels of every pair both cover.
std::vector<double> pairJumps(const std::vector<float>& directions,
                              const std::vector<PixelPair>& pairs);

// {"pairs", "count", "mean", "median", "p95", "max"} of the jumps.
nlohmann::json jumpStats(const std::vector<PixelPair>& pairs, std::vector<double> jumps);

}  // namespace shrefract
