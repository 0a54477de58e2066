// The bake's model of its own error (docs/bake.md "Error model"). Per sample the angle between
// what the stored model predicts and the traced exit, at a set of check directions, is projected
// onto the even-parity SH through a low order E (solid-angle-weighted least squares, as
// leastSquaresMatrix), so that the runtime can predict the angular error at any view direction
// from (E+1)(E+2)/2 numbers: err(w) = sum_k e_k y_k(w), in radians, clamped at 0 where read.
//
// An SH bake checks its fit at the grid directions it was fitted from: the fit sees the traced
// exit there and misses it where the SH cannot follow. A grid-basis bake stores the grid itself,
// so it misses nothing there: it checks its bilinear read at the cells' corners (cellCorners),
// traced for the purpose and then dropped.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <glm/glm.hpp>

#include "common/bakefile.h"
#include "common/direction_grid.h"

namespace shrefract {

// The order of the error model a bake stores unless told otherwise: 28 numbers per sample beside
// the 91 of order-12 weights (one R16F layer each on the GPU, 15 % of the u8 weights' bytes),
// chosen by `shrefract-eval directions`' Spearman correlation between predicted and measured
// error on bunny00's default bake: 0.69 at order 4, 0.76 at order 6, 0.80 at order 8
// (docs/bake.md "Error model").
constexpr int kDefaultErrorOrder = 6;

// The error model's order a bake with these settings stores: `requested` (< 0: none), with no
// more coefficients than it has check directions to fit them from. An SH bake's is no higher
// than the weights' `order` either (the runtime's direct path and the web material evaluate both
// from one SH evaluation through the larger).
int storedErrorOrder(int requested, Basis basis, int order, const DirectionGrid& grid);

// Build once per (basis, grid, weight order, error order); use from many threads.
class ResidualFitter {
public:
    ResidualFitter(Basis basis, const DirectionGrid& grid, int order, int errorOrder);
    int errorCoefficients() const { return int(P_.rows()); }
    // The directions (local frame) where the truth must be traced apart from the grid: the cell
    // corners for the grid basis, none for SH (it checks at the grid directions).
    const std::vector<glm::vec3>& checkDirections() const { return check_; }
    // For B samples at once: R (J x 4B, sample s in columns 4s..4s+3: exit x, y, z, length) as
    // traced at the grid, C the same at checkDirections() (ignored for SH), and Wt (4B x K,
    // sample s in rows 4s..4s+3) as stored; writes E (Ke x B), sample s's error model in column s.
    void fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const Eigen::Ref<const Eigen::MatrixXf>& C,
             const Eigen::Ref<const Eigen::MatrixXf>& Wt, int B, Eigen::Ref<Eigen::MatrixXf> E) const;

private:
    Basis basis_;
    Eigen::MatrixXf Y_;  // SH: J x K, the stored functions through the weights' order at the grid
    Eigen::SparseMatrix<float, Eigen::RowMajor> read_;  // grid: corners x J, the bilinear read
    std::vector<glm::vec3> check_;
    Eigen::MatrixXf P_;  // Ke x checks: least-squares projection onto the error model's functions
};

}  // namespace shrefract
