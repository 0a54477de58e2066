// The joining-surfaces layout (paper §5.3): every triangle sampled on a regular barycentric grid
// of `rate` steps per edge, samples on shared vertices and edges shared, packed densely in mu and
// as interleaved right triangles with correction texels in rho.
#pragma once

#include <cstddef>

#include "common/bakefile.h"
#include "common/scene.h"

namespace shrefract {

// Unique samples of a scene at rate r: vertices + (r-1) per edge + (r-1)(r-2)/2 per triangle.
size_t joiningSampleCount(const Scene& scene, int rate);
// The smallest rate whose unique sample count reaches `target` (at least 1, at most
// limits::kMaxRate).
int rateForSampleCount(const Scene& scene, size_t target);
// Builds mu, rho and the smoothing neighbour lists for all parts of the scene.
SurfaceLayout buildJoiningLayout(const Scene& scene, int rate);
// rho texels over unique samples: the price of seamless filtering (paper §5.3.1).
double rhoOverhead(const SurfaceLayout& layout);

}  // namespace shrefract
