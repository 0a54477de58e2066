#include "bake/residual.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "common/bakefile.h"
#include "common/error.h"
#include "common/sh.h"

namespace shrefract {

int storedErrorOrder(int requested, int order, const DirectionGrid& grid) {
    if (requested < 0) return -1;
    int e = std::min(requested, order);
    while (e > 0 && shEvenCount(e) > grid.count()) --e;
    return e;
}

ResidualFitter::ResidualFitter(const DirectionGrid& grid, int order, int errorOrder) {
    SHREFRACT_CHECK(errorOrder >= 0 && shEvenCount(errorOrder) <= grid.count());
    const int J = grid.count(), K = shEvenCount(order);
    Y_.resize(J, K);
    std::vector<float> y(K);
    for (int j = 0; j < J; ++j) {
        shEvalEven(order, glm::vec3(grid.direction(j)), y.data());
        for (int k = 0; k < K; ++k) Y_(j, k) = y[k];
    }
    P_ = leastSquaresMatrix(grid, errorOrder).cast<float>();
}

void ResidualFitter::fit(const Eigen::Ref<const Eigen::MatrixXf>& R,
                         const Eigen::Ref<const Eigen::MatrixXf>& Wt, int B,
                         Eigen::Ref<Eigen::MatrixXf> E) const {
    const int J = int(Y_.rows());
    SHREFRACT_CHECK(R.rows() == J && R.cols() >= 4 * B && Wt.rows() >= 4 * B &&
                    Wt.cols() == Y_.cols() && E.rows() == P_.rows() && E.cols() >= B);
    // The fitted mapping at every grid direction, all B samples in one GEMM: J x 4B.
    const Eigen::MatrixXf fitted = Y_ * Wt.topRows(4 * B).transpose();
    Eigen::MatrixXf angles(J, B);
    for (int s = 0; s < B; ++s)
        for (int j = 0; j < J; ++j) {
            const glm::vec3 f(fitted(j, 4 * s), fitted(j, 4 * s + 1), fitted(j, 4 * s + 2));
            const glm::vec3 r(R(j, 4 * s), R(j, 4 * s + 1), R(j, 4 * s + 2));
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
