#include "bake/learned_basis.h"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace shrefract {
namespace {

// Principal components of the rows of X (already weighted by sqrt(a_j c_j)): the K unit vectors
// of the row space with the largest eigenvalues of X^T X, through whichever Gram matrix is
// smaller (X^T X, or X X^T and v = X^T u / sqrt(lambda)). `divide[col]` undoes the sqrt(a_j) of
// each column, so that the functions are orthonormal over the sphere.
LearnedBasis principalFunctions(const Eigen::MatrixXd& X, const std::vector<double>& divide, int K) {
    const bool columns = X.cols() <= X.rows();
    const Eigen::MatrixXd gram = columns ? Eigen::MatrixXd(X.transpose() * X) : Eigen::MatrixXd(X * X.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
    SHREFRACT_CHECK(eig.info() == Eigen::Success && K <= gram.rows());
    const double total = std::max(eig.eigenvalues().sum(), 1e-300);
    LearnedBasis b{Eigen::MatrixXf(X.cols(), K), {}};
    for (int k = 0; k < K; ++k) {
        const int col = int(gram.rows()) - 1 - k;  // the solver sorts the eigenvalues increasing
        const double lambda = std::max(eig.eigenvalues()(col), 0.0);
        b.energy.push_back(lambda / total);
        const Eigen::VectorXd v = columns ? Eigen::VectorXd(eig.eigenvectors().col(col))
                                          : Eigen::VectorXd(X.transpose() * eig.eigenvectors().col(col) /
                                                            std::sqrt(std::max(lambda, 1e-300)));
        for (Eigen::Index r = 0; r < X.cols(); ++r) b.values(r, k) = float(v(r) / divide[r]);
    }
    return b;
}

}  // namespace

LearnedBasis learnScalarBasis(const std::vector<PathResult>& paths, const DirectionGrid& grid,
                              const WeightedFitter& confidence, int K) {
    const int J = grid.count(), N = int(paths.size() / J);
    SHREFRACT_CHECK(size_t(N) * J == paths.size() && K >= 1 && K <= J);
    const std::vector<double> a = gridSolidAngles(grid);
    Eigen::MatrixXd X(3 * size_t(N), J);  // three rows per sample: exit x, y, z
    tbb::parallel_for(0, N, [&](int s) {
        std::vector<float> c(J);
        confidence.confidence(&paths[size_t(s) * J], c.data());
        for (int j = 0; j < J; ++j) {
            const glm::vec3 e = paths[size_t(s) * J + j].exit;
            const double w = std::sqrt(a[j] * c[j]);
            for (int ch = 0; ch < 3; ++ch) X(3 * size_t(s) + ch, j) = w * e[ch];
        }
    });
    std::vector<double> divide(J);
    for (int j = 0; j < J; ++j) divide[j] = std::sqrt(a[j]);
    return principalFunctions(X, divide, K);
}

LearnedBasis learnVectorBasis(const std::vector<PathResult>& paths, const DirectionGrid& grid,
                              const WeightedFitter& confidence, const std::vector<Frame>& frames, int K) {
    const int J = grid.count(), N = int(paths.size() / J);
    SHREFRACT_CHECK(size_t(N) * J == paths.size() && frames.size() == size_t(N) && K >= 1 && K <= N);
    const std::vector<double> a = gridSolidAngles(grid);
    Eigen::MatrixXd X(N, 4 * size_t(J));  // one row per sample: (local exit, length) at each direction
    tbb::parallel_for(0, N, [&](int s) {
        std::vector<float> c(J);
        confidence.confidence(&paths[size_t(s) * J], c.data());
        for (int j = 0; j < J; ++j) {
            const PathResult& p = paths[size_t(s) * J + j];
            const glm::vec3 e = frames[s].toLocal(p.exit);
            const double w = std::sqrt(a[j] * c[j]);
            X(s, 4 * j + 0) = w * e.x, X(s, 4 * j + 1) = w * e.y, X(s, 4 * j + 2) = w * e.z;
            X(s, 4 * j + 3) = w * p.length;
        }
    });
    std::vector<double> divide(4 * size_t(J));
    for (int r = 0; r < 4 * J; ++r) divide[r] = std::sqrt(a[r / 4]);
    return principalFunctions(X, divide, K);
}

Eigen::MatrixXf fitVectorBasis(const Eigen::Ref<const Eigen::MatrixXf>& B, const Eigen::MatrixXf& R,
                               const DirectionGrid& grid, std::vector<float> c, const FitWeighting& weighting) {
    const int J = grid.count(), K = int(B.cols());
    SHREFRACT_CHECK(B.rows() == 4 * J && R.rows() == J && R.cols() == 4 && c.size() == size_t(J));
    const std::vector<double> a = gridSolidAngles(grid);
    Eigen::VectorXf r(4 * J);
    for (int j = 0; j < J; ++j) r.segment<4>(4 * j) = R.row(j).transpose();
    const float cosTrim = std::cos(weighting.trimDeg * float(M_PI) / 180.0f);
    std::vector<bool> trimmed(J, false);
    Eigen::MatrixXf fitted(J, 4);
    for (int pass = 0; pass <= weighting.trimPasses; ++pass) {
        Eigen::VectorXf d(4 * J);  // sqrt(a_j c_j) on the four rows of direction j
        for (int j = 0; j < J; ++j) d.segment<4>(4 * j).setConstant(std::sqrt(float(a[j]) * c[j]));
        const Eigen::MatrixXf A = d.asDiagonal() * B;
        Eigen::MatrixXf G = Eigen::MatrixXf::Zero(K, K);
        G.selfadjointView<Eigen::Lower>().rankUpdate(A.transpose());
        const Eigen::VectorXf w = G.selfadjointView<Eigen::Lower>().llt().solve(A.transpose() * (d.asDiagonal() * r));
        const Eigen::VectorXf f = B * w;
        bool changed = false;
        for (int j = 0; j < J; ++j) {
            fitted.row(j) = f.segment<4>(4 * j).transpose();
            const glm::vec3 fj(f(4 * j), f(4 * j + 1), f(4 * j + 2)), rj(R(j, 0), R(j, 1), R(j, 2));
            const float lf = glm::length(fj), lr = glm::length(rj);
            const bool miss = !(lf > 0 && lr > 0) || glm::dot(fj, rj) < cosTrim * lf * lr;
            if (miss && !trimmed[j]) trimmed[j] = true, c[j] *= weighting.trimmed, changed = true;
        }
        if (!changed) break;
    }
    return fitted;
}

}  // namespace shrefract
