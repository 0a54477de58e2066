// A basis learned from the mesh itself, in place of the SH bands: studied by shrefract-fit-study
// (--learned, --learned-vector) and not built into the bake, because at the default's bytes it
// does not beat the bands (docs/bake.md "A learned basis").
//
// Both kinds are principal components of traced grids (every sample's exits at the J grid
// directions), each direction weighted by a_j c_j: its cell's solid angle and the weighted fit's
// confidence in its path (bake/fit.h), so that a basis spends itself where the fit would.
//  - scalar: K functions over the grid, shared by the four channels (exit x, y, z, length) as the
//    SH bands are; a sample stores 4 K weights. The frame the exits are written in does not
//    matter: rotating a sample's three exit rows leaves their Gram matrix as it is.
//  - vector: K functions from the grid to (exit x, y, z in the sample's local frame, length), one
//    weight each; a sample stores K. The local frame (common/frame.h, from the normal alone) makes
//    samples alike: an exit turns with its normal, and the basis need not learn every orientation.
// A learned function is known at the grid directions only; between them it is read as the grid
// is, bilinearly (DirectionGrid::interpolate).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bake/fit.h"
#include "bake/tracer.h"
#include "common/direction_grid.h"
#include "common/frame.h"

namespace shrefract {

struct LearnedBasis {
    // Scalar: J x K, row j = direction j. Vector: 4J x K, row 4 j + channel. Column k = function k,
    // largest share of the training exits' weighted energy first; orthonormal over the sphere
    // (sum_j a_j b_k(j) . b_l(j) = delta_kl).
    Eigen::MatrixXf values;
    std::vector<double> energy;  // each function's share of the total weighted energy
};

// From `paths`, the traced grids of N training samples (N x J, sample-major); `confidence`
// gives c_j (WeightedFitter::confidence). K <= J.
LearnedBasis learnScalarBasis(const std::vector<PathResult>& paths, const DirectionGrid& grid,
                              const WeightedFitter& confidence, int K);
// The same for the vector kind, each sample's exits seen from `frames[s]`. K <= N.
LearnedBasis learnVectorBasis(const std::vector<PathResult>& paths, const DirectionGrid& grid,
                              const WeightedFitter& confidence, const std::vector<Frame>& frames, int K);

// One sample's weighted fit in a vector basis B (4J x K): w = argmin sum_j a_j c_j |B_j w - r_j|^2,
// R (J x 4) its local exits and lengths, with `weighting`'s trim passes (a direction the fit misses
// by more than trimDeg is fitted again at c_j * trimmed, once). Returns the fitted grid, J x 4.
// The scalar kind needs no function of its own: WeightedFitter takes any basis at the grid.
Eigen::MatrixXf fitVectorBasis(const Eigen::Ref<const Eigen::MatrixXf>& B, const Eigen::MatrixXf& R,
                               const DirectionGrid& grid, std::vector<float> c, const FitWeighting& weighting);

}  // namespace shrefract
