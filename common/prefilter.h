// The environment as spread shading looks it up (issue 8, docs/runtime.md "Spread shading"): a
// cube-map mip chain whose level l is the base convolved with a von Mises-Fisher lobe of angular
// width sigma_l, and the map from the SH reconstruction's length to a lobe width. The runtime
// uploads exactly these levels (runtime/src/environment.cpp) and shaders/shading.glsl holds the
// GLSL twins of spreadSigma() and lodForSigma(); the CPU twin serves tests and CPU renderers.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "common/latlong.h"

namespace shrefract {

struct PrefilteredCube {
    // levels[0] is the base (unfiltered); levels[l] has faceSize base >> l, down to 1 x 1.
    std::vector<CubeMapImage> levels;
    // Lobe width of level l, radians: 0 for l = 0, else one texel of that level,
    // sigma_l = (pi / 2) / faceSize_l = sigma_1 2^(l - 1).
    float sigma(int level) const;
};

// Level l >= 1 from level l - 1 by a vMF lobe of width sqrt(sigma_l^2 - sigma_{l-1}^2) (widths
// add in quadrature under convolution, exactly for small lobes), sampled at `samples`
// stratified points of the lobe (filtered importance sampling: the source level's own blur is
// about half the lobe). Parallel (std::thread). A constant image stays constant; energy is kept.
PrefilteredCube prefilterCube(const CubeMapImage& base, int samples = 128);

// The fractional mip level whose lobe is sigma wide: sigma / sigma_1 below sigma_1 (a blend of
// the sharp base and level 1), 1 + log2(sigma / sigma_1) above, clamped to [0, levels - 1].
// `faceSize` is the base's; shading.glsl environmentLod() is the same formula.
float lodForSigma(float sigma, int faceSize, int levels);

// GL_LINEAR_MIPMAP_LINEAR at a given level of detail: seamless bilinear lookups (sampleCube) in
// levels floor(lod) and floor(lod) + 1, blended by the fraction.
glm::vec3 sampleCubeLod(const PrefilteredCube& cube, glm::vec3 d, float lod);

// The width (radians) of the vMF lobe whose mean resultant length is `resultant`: the length
// of the unnormalized SH reconstruction of a unit exit direction, which falls below 1 where the
// mapping scatters. kappa(R) = R (3 - R^2) / (1 - R^2) (Banerjee et al. 2005), sigma =
// scale / sqrt(kappa); 0 at R >= 1, very wide as R -> 0. shading.glsl spreadSigma() is the twin.
float spreadSigma(float resultant, float scale = 1.0f);
// The inverse direction, exactly: the mean resultant length coth(kappa) - 1 / kappa of the vMF
// lobe with kappa = 1 / sigma^2, 1 for sigma < 1e-3 (within float rounding). How the runtime
// carries the bake's predicted error in the length of the exit vector (shaders/error_fold.frag
// is the twin); spreadSigma(resultantOfSigma(s)) is s within Banerjee's approximation.
float resultantOfSigma(float sigma);

}  // namespace shrefract
