#include "bake/residual.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error.h"
#include "common/sh.h"

namespace shrefract {

int storedErrorOrder(int requested, Basis basis, int order, const DirectionGrid& grid) {
    if (requested < 0) return -1;
    const int checks = basis == Basis::Grid ? int(cellCorners(grid).directions.size()) : grid.count();
    int e = basis == Basis::Grid ? requested : std::min(requested, order);
    while (e >= 0 && shEvenCount(e) > checks) --e;
    return e;
}

ResidualFitter::ResidualFitter(Basis basis, const DirectionGrid& grid, int order, int errorOrder)
    : basis_(basis) {
    SHREFRACT_CHECK(errorOrder >= 0);
    if (basis == Basis::Grid) {
        const CellCorners corners = cellCorners(grid);
        const int n = int(corners.directions.size());
        SHREFRACT_CHECK(shEvenCount(errorOrder) <= n);
        std::vector<Eigen::Triplet<float>> entries;
        for (int c = 0; c < n; ++c) {
            int index[4];
            double weight[4];
            const int count = grid.interpolate(corners.directions[c], index, weight);
            for (int t = 0; t < count; ++t) entries.emplace_back(c, index[t], float(weight[t]));
            check_.push_back(glm::vec3(corners.directions[c]));
        }
        read_.resize(n, grid.count());
        read_.setFromTriplets(entries.begin(), entries.end());  // sums a corner's repeated indices
        P_ = leastSquaresMatrix(corners.directions, corners.solidAngle, errorOrder).cast<float>();
        return;
    }
    SHREFRACT_CHECK(shEvenCount(errorOrder) <= grid.count());
    const int J = grid.count(), K = shEvenCount(order);
    Y_.resize(J, K);
    std::vector<float> y(K);
    for (int j = 0; j < J; ++j) {
        shEvalEven(order, glm::vec3(grid.direction(j)), y.data());
        for (int k = 0; k < K; ++k) Y_(j, k) = y[k];
    }
    P_ = leastSquaresMatrix(grid, errorOrder).cast<float>();
}

void ResidualFitter::fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const Eigen::Ref<const Eigen::MatrixXf>& C,
                         const Eigen::Ref<const Eigen::MatrixXf>& Wt, int B, Eigen::Ref<Eigen::MatrixXf> E) const {
    const bool grid = basis_ == Basis::Grid;
    // The truth at the check directions, and the stored model's prediction there, all B samples
    // in one product: checks x 4B.
    const Eigen::Ref<const Eigen::MatrixXf>& truth = grid ? C : R;
    const int J = int(P_.cols());
    SHREFRACT_CHECK(truth.rows() == J && truth.cols() >= 4 * B && Wt.rows() >= 4 * B &&
                    E.rows() == P_.rows() && E.cols() >= B);
    const Eigen::MatrixXf predicted = grid ? Eigen::MatrixXf(read_ * Wt.topRows(4 * B).transpose())
                                           : Eigen::MatrixXf(Y_ * Wt.topRows(4 * B).transpose());
    Eigen::MatrixXf angles(J, B);
    for (int s = 0; s < B; ++s)
        for (int j = 0; j < J; ++j) {
            const glm::vec3 f(predicted(j, 4 * s), predicted(j, 4 * s + 1), predicted(j, 4 * s + 2));
            const glm::vec3 r(truth(j, 4 * s), truth(j, 4 * s + 1), truth(j, 4 * s + 2));
            const float lf = glm::length(f), lr = glm::length(r);
            // No direction on either side: as far off as a random guess on the hemisphere.
            const float c = lf > 0 && lr > 0 ? glm::dot(f, r) / (lf * lr) : 0.0f;
            angles(j, s) = std::acos(std::clamp(c, -1.0f, 1.0f));
        }
    // The model fits ln(angle + kErrorOffset): a skewed quantity (a few directions off by 90
    // degrees, most by one) whose least-squares mean in log space is close to its median, so the
    // prediction ranks and sizes the typical error instead of the outliers' mean (docs/bake.md
    // "Error model": Spearman 0.70 on bunny00 at order 4, against 0.67 fitting the angle itself).
    angles = (angles.array() + kErrorOffset).log().matrix();
    E.leftCols(B).noalias() = P_ * angles;
}

}  // namespace shrefract
