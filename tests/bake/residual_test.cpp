// The bake's error model (bake/residual.h) against closed forms: a fit that is exact has no
// error, and a fit that misses every traced exit by the same angle predicts that angle everywhere.
// The model is ln(angle + kErrorOffset); predicted() undoes it as common/decompress.h does.
#include "bake/residual.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/bakefile.h"
#include "common/sh.h"

namespace shrefract {
namespace {

// Two samples. Sample 0's weights are the constant exit (0, 0, 1) (y_0 = 1 / sqrt(4 pi)), sample
// 1's the constant (1, 0, 0); both with length 2.
Eigen::MatrixXf constantExits(int K) {
    const float c = std::sqrt(4.0f * float(M_PI));
    Eigen::MatrixXf Wt = Eigen::MatrixXf::Zero(8, K);
    Wt(2, 0) = c, Wt(3, 0) = 2 * c;      // sample 0: z, length
    Wt(4, 0) = c, Wt(7, 0) = 2 * c;      // sample 1: x, length
    return Wt;
}

// The model of sample s evaluated at w, in radians.
float predicted(const Eigen::MatrixXf& E, int s, glm::vec3 w) {
    std::vector<float> y(E.rows());
    shEvalEven(2, w, y.data());
    float p = 0;
    for (int k = 0; k < int(E.rows()); ++k) p += y[k] * E(k, s);
    return std::exp(p) - kErrorOffset;
}

TEST(Residual, ExactFitPredictsNoError) {
    const DirectionGrid grid{8, 16};
    const ResidualFitter fitter(Basis::Sh, grid, 4, 2);
    Eigen::MatrixXf R(grid.count(), 8);
    for (int j = 0; j < grid.count(); ++j) R.row(j) << 0, 0, 1, 2, 1, 0, 0, 2;
    Eigen::MatrixXf E(fitter.errorCoefficients(), 2);
    fitter.fit(R, R, constantExits(shEvenCount(4)), 2, E);
    // acos near 1 in float: ~3e-4 rad at most.
    for (int s = 0; s < 2; ++s) EXPECT_LT(std::abs(predicted(E, s, glm::vec3(0.6f, 0, 0.8f))), 1e-3f);
}

TEST(Residual, ConstantMissIsPredictedEverywhere) {
    const DirectionGrid grid{8, 16};
    const ResidualFitter fitter(Basis::Sh, grid, 4, 2);
    const float a0 = 0.3f, a1 = 1.1f;  // radians
    Eigen::MatrixXf R(grid.count(), 8);
    // Sample 0 traced at a0 from +z, sample 1 at a1 from +x, at every grid direction.
    for (int j = 0; j < grid.count(); ++j)
        R.row(j) << std::sin(a0), 0, std::cos(a0), 2, std::cos(a1), std::sin(a1), 0, 2;
    Eigen::MatrixXf E(fitter.errorCoefficients(), 2);
    fitter.fit(R, R, constantExits(shEvenCount(4)), 2, E);
    // The constant ln(a + offset) is in the model's span, so least squares reproduces it: every
    // coefficient but e_0 is 0, and the prediction is a at any direction.
    for (glm::vec3 w : {glm::vec3(0, 0, 1), glm::normalize(glm::vec3(1, 2, 0.3f)), glm::vec3(1, 0, 0)})
        for (int s = 0; s < 2; ++s) EXPECT_NEAR(predicted(E, s, w), s == 0 ? a0 : a1, 1e-4f) << "sample " << s;
}

// The grid basis checks its bilinear read at the cells' corners, against exits traced there
// apart (C): a grid of the constant exit (0, 0, 1) reads it exactly at every corner, so corners
// traced a1 away from it predict a1 everywhere, and corners traced at (0, 0, 1) predict nothing.
// Planted: checking at the grid directions (C's rows read as R's) predicts 0 for sample 0.
TEST(Residual, GridBasisChecksItsReadAtTheCorners) {
    const DirectionGrid grid{6, 12};
    const ResidualFitter fitter(Basis::Grid, grid, 0, 2);
    const int n = int(cellCorners(grid).directions.size());
    ASSERT_EQ(int(fitter.checkDirections().size()), n);
    ASSERT_EQ(n, 5 * 12);
    const float a1 = 0.4f;
    Eigen::MatrixXf R(grid.count(), 8), C(n, 8);
    for (int j = 0; j < grid.count(); ++j) R.row(j) << 0, 0, 1, 2, 0, 0, 1, 2;
    for (int c = 0; c < n; ++c) C.row(c) << std::sin(a1), 0, std::cos(a1), 2, 0, 0, 1, 2;
    Eigen::MatrixXf E(fitter.errorCoefficients(), 2);
    fitter.fit(R, C, R.transpose(), 2, E);
    for (glm::vec3 w : {glm::vec3(0, 0, 1), glm::normalize(glm::vec3(1, 2, 0.3f))}) {
        EXPECT_NEAR(predicted(E, 0, w), a1, 1e-4f);
        EXPECT_LT(std::abs(predicted(E, 1, w)), 1e-3f);
    }
}

// The stored order: the one asked for, capped by the weights' order (SH only) and by the
// directions it is checked at ((E+1)(E+2)/2 coefficients need at least as many). A 2x4 grid (8
// directions) holds order 2 (6 coefficients) but not 3 (10); before the cap such a bake stopped
// on the fitter's CHECK. A grid-basis bake of 2x4 has 4 corners: order 1 (3 coefficients).
TEST(Residual, StoredOrderIsCappedByTheWeightsAndTheChecks) {
    EXPECT_EQ(storedErrorOrder(kDefaultErrorOrder, Basis::Sh, 12, DirectionGrid{32, 64}), kDefaultErrorOrder);
    EXPECT_EQ(storedErrorOrder(6, Basis::Sh, 4, DirectionGrid{32, 64}), 4);
    EXPECT_EQ(storedErrorOrder(6, Basis::Sh, 8, DirectionGrid{2, 4}), 2);
    EXPECT_EQ(storedErrorOrder(2, Basis::Sh, 8, DirectionGrid{2, 4}), 2);
    EXPECT_EQ(storedErrorOrder(-1, Basis::Sh, 8, DirectionGrid{32, 64}), -1);
    EXPECT_EQ(storedErrorOrder(6, Basis::Sh, 0, DirectionGrid{32, 64}), 0);
    EXPECT_EQ(storedErrorOrder(6, Basis::Grid, 0, DirectionGrid{16, 32}), 6);
    EXPECT_EQ(storedErrorOrder(6, Basis::Grid, 0, DirectionGrid{2, 4}), 1);
    EXPECT_EQ(storedErrorOrder(-1, Basis::Grid, 0, DirectionGrid{16, 32}), -1);
}

}  // namespace
}  // namespace shrefract
