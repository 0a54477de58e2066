// The bake's model of its own error (docs/bake.md "Error model"). The fit sees the traced exit
// r_j at every grid direction w_j; where the fitted SH miss it, the runtime should not pretend to
// know the exit. Per sample the angle e_j between the fitted and the traced exit is projected onto
// the even-parity SH through a low order E (solid-angle-weighted least squares, as
// leastSquaresMatrix), so that the runtime can predict the angular error at any view direction
// from (E+1)(E+2)/2 numbers: err(w) = sum_k e_k y_k(w), in radians, clamped at 0 where read.
#pragma once

#include <Eigen/Core>

#include "common/direction_grid.h"

namespace shrefract {

// The order of the error model a bake stores unless told otherwise: 28 numbers per sample beside
// the 91 of order-12 weights (one R16F layer each on the GPU, 15 % of the u8 weights' bytes),
// chosen by `shrefract-eval directions`' Spearman correlation between predicted and measured
// error on bunny00's default bake: 0.69 at order 4, 0.76 at order 6, 0.80 at order 8
// (docs/bake.md "Error model").
constexpr int kDefaultErrorOrder = 6;

// The error model's order a bake with these settings stores: `requested` (< 0: none), but no
// higher than the weights' `order` (the runtime's direct path and the web material evaluate both
// from one SH evaluation through the larger) and with no more coefficients than the grid has
// directions to fit them from.
int storedErrorOrder(int requested, int order, const DirectionGrid& grid);

// Build once per (grid, weight order, error order); use from many threads.
class ResidualFitter {
public:
    ResidualFitter(const DirectionGrid& grid, int order, int errorOrder);
    int errorCoefficients() const { return int(P_.rows()); }
    // For B samples at once: R (J x 4B, sample s in columns 4s..4s+3: exit x, y, z, length) as
    // traced and Wt (4B x K, sample s in rows 4s..4s+3) as fitted; writes E (Ke x B), the error
    // model of sample s in column s.
    void fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const Eigen::Ref<const Eigen::MatrixXf>& Wt,
             int B, Eigen::Ref<Eigen::MatrixXf> E) const;

private:
    Eigen::MatrixXf Y_;  // J x K: the stored functions through the weights' order at the grid
    Eigen::MatrixXf P_;  // Ke x J: least-squares projection onto the error model's functions
};

}  // namespace shrefract
