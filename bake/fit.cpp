#include "bake/fit.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/sh.h"

namespace shrefract {

bool fitCanSolve(Fit fit, int L, const DirectionGrid& grid) {
    return fit == Fit::Projection || shEvenCount(L) <= grid.count();
}

glm::vec4 evaluateFit(int L, const Eigen::Ref<const Eigen::MatrixXf>& W, glm::vec3 w) {
    std::vector<float> y(shEvenCount(L));
    shEvalEven(L, w, y.data());
    glm::vec4 e(0.0f);
    for (int k = 0; k < W.rows(); ++k) e += y[k] * glm::vec4(W(k, 0), W(k, 1), W(k, 2), W(k, 3));
    return e;
}

std::vector<int> evenBands(int L) {
    std::vector<int> bands;
    for (const ShLM& f : shEvenFunctions(L)) bands.push_back(f.l);
    return bands;
}

FitWeighting FitWeighting::none() {
    FitWeighting w;
    w.flagged = 1.0f;
    w.flags = 0;
    w.disagreeDeg = 0.0f;
    w.trimPasses = 0;
    return w;
}

FitWeighting FitWeighting::parse(const std::string& text, const std::string& what) {
    FitWeighting w;
    std::istringstream in(text);
    char c[6] = {};
    const bool ok = bool(in >> w.flagged >> c[0] >> w.disagreeDeg >> c[1] >> w.disagreeing >> c[2] >>
                         w.trimDeg >> c[3] >> w.trimmed >> c[4] >> w.trimPasses);
    if (ok && in >> c[5]) in >> w.ridge;
    const bool colons = std::all_of(c, c + 5, [](char x) { return x == ':'; });
    if (!ok || !colons || !in.eof() || !(w.flagged > 0 && w.flagged <= 1) ||
        !(w.disagreeing > 0 && w.disagreeing <= 1) || !(w.trimmed > 0 && w.trimmed <= 1) ||
        w.trimPasses < 0 || w.trimPasses > 8 || !(w.ridge >= 0) || !(w.disagreeDeg >= 0) || !(w.trimDeg > 0))
        throw InputError(what + ": expected FLAGGED:DEG:DISAGREEING:TRIMDEG:TRIMMED:PASSES[:RIDGE] "
                                "with factors in (0, 1], passes 0..8, got '" + text + "'");
    return w;
}

std::string FitWeighting::ToString() const {
    std::ostringstream os;
    os << flagged << ":" << disagreeDeg << ":" << disagreeing << ":" << trimDeg << ":" << trimmed
       << ":" << trimPasses;
    if (ridge > 0) os << ":" << ridge;
    return os.str();
}

RecordedFit recordedFit(const nlohmann::json& manifest) {
    RecordedFit r;
    r.fit = parseInput<Fit>(manifest.value("fit", "projection"));
    if (r.fit == Fit::Weighted) r.weighting = FitWeighting::parse(manifest.value("fitWeighting", ""), "fitWeighting");
    r.filterWidth = manifest.value("filterWidth", 0.0);
    return r;
}

namespace {

// The order-L functions at the grid directions (J x K, even order).
Eigen::MatrixXf shAtGrid(const DirectionGrid& grid, int order) {
    const int K = shEvenCount(order), J = grid.count();
    Eigen::MatrixXf Y(J, K);
    const std::vector<ShLM> fs = shEvenFunctions(order);
    std::vector<double> all(shCount(order));
    for (int j = 0; j < J; ++j) {
        shEvalAllRecurrence(order, grid.direction(j), all.data());
        for (int k = 0; k < K; ++k) Y(j, k) = float(all[shIndex(fs[k].l, fs[k].m)]);
    }
    return Y;
}

}  // namespace

WeightedFitter::WeightedFitter(const DirectionGrid& grid, int order, const FitWeighting& weighting)
    : WeightedFitter(grid, shAtGrid(grid, order), weighting) {
    const std::vector<ShLM> fs = shEvenFunctions(order);
    for (int k = 0; k < coefficients(); ++k) ridge_(k) = weighting.ridge * float(fs[k].l * (fs[k].l + 1));
}

WeightedFitter::WeightedFitter(const DirectionGrid& grid, Eigen::MatrixXf basisAtGrid,
                               const FitWeighting& weighting)
    : grid_(grid), weighting_(weighting), Y_(std::move(basisAtGrid)) {
    const int J = grid.count(), K = int(Y_.cols());
    SHREFRACT_CHECK(Y_.rows() == J && J >= K);
    const std::vector<double> a = gridSolidAngles(grid);
    a_ = Eigen::Map<const Eigen::VectorXd>(a.data(), J).cast<float>();
    Gall_ = Y_.transpose() * a_.asDiagonal() * Y_;
    ridge_ = Eigen::VectorXf::Zero(K);
}

void WeightedFitter::confidence(const PathResult* paths, float* c) const {
    const int J = directions();
    for (int j = 0; j < J; ++j) c[j] = (paths[j].flags & weighting_.flags) ? weighting_.flagged : 1.0f;
    if (weighting_.disagreeDeg <= 0) return;
    // Neighbours in theta (same phi) and in phi (same ring, wrapping): both of a pair whose exits
    // differ by more than the threshold disagree.
    const float cosMax = std::cos(weighting_.disagreeDeg * float(M_PI) / 180.0f);
    const float d = weighting_.disagreeing;
    auto lower = [&](int j) { c[j] = std::min(c[j], d); };
    const int nT = grid_.nTheta, nP = grid_.nPhi;
    for (int i = 0; i < nT; ++i)
        for (int k = 0; k < nP; ++k) {
            const int j = i * nP + k;
            const int right = i * nP + (k + 1) % nP, up = (i + 1) * nP + k;
            // Exits may be footprint means (shorter than 1): compare their directions.
            auto turns = [&](int a, int b) {
                const glm::vec3 ea = paths[a].exit, eb = paths[b].exit;
                return glm::dot(ea, eb) < cosMax * glm::length(ea) * glm::length(eb);
            };
            if (turns(j, right)) lower(j), lower(right);
            if (i + 1 < nT && turns(j, up)) lower(j), lower(up);
        }
}

void WeightedFitter::fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const float* c,
                         Eigen::Ref<Eigen::MatrixXf> W) const {
    const int J = directions();
    // G = Y^T diag(a c) Y = Gall - sum_j a_j (1 - c_j) y_j y_j^T: only the directions with c_j < 1
    // cost a rank update (about half of them on a busy mesh, few on a simple one), and each trim
    // pass only the directions it trims.
    const std::vector<float> ones(J, 1.0f);
    Eigen::MatrixXf G = Gall_;
    G.diagonal() += ridge_;
    lowerConfidence(G, ones.data(), c);
    solve(G, R, c, W);
    const float cosTrim = std::cos(weighting_.trimDeg * float(M_PI) / 180.0f);
    std::vector<float> ct(c, c + J);
    for (int pass = 0; pass < weighting_.trimPasses; ++pass) {
        const Eigen::MatrixXf fitted = Y_ * W;  // J x 4
        const std::vector<float> before = ct;
        bool changed = false;
        for (int j = 0; j < J; ++j) {
            const glm::vec3 f(fitted(j, 0), fitted(j, 1), fitted(j, 2)), r(R(j, 0), R(j, 1), R(j, 2));
            const float lf = glm::length(f), lr = glm::length(r);
            const bool miss = !(lf > 0 && lr > 0) || glm::dot(f, r) < cosTrim * lf * lr;
            // Each direction is trimmed once: c_j * trimmed, never trimmed again.
            if (miss && ct[j] == c[j]) ct[j] = c[j] * weighting_.trimmed, changed = true;
        }
        if (!changed) break;
        lowerConfidence(G, before.data(), ct.data());
        solve(G, R, ct.data(), W);
    }
}

void WeightedFitter::lowerConfidence(Eigen::MatrixXf& G, const float* from, const float* to) const {
    const int J = directions();
    Eigen::MatrixXf down(coefficients(), J);
    int nd = 0;
    for (int j = 0; j < J; ++j)
        if (to[j] < from[j]) down.col(nd++) = std::sqrt(a_(j) * (from[j] - to[j])) * Y_.row(j).transpose();
    if (nd > 0) G.selfadjointView<Eigen::Lower>().rankUpdate(down.leftCols(nd), -1.0f);
}

void WeightedFitter::solve(const Eigen::MatrixXf& G, const Eigen::Ref<const Eigen::MatrixXf>& R,
                           const float* c, Eigen::Ref<Eigen::MatrixXf> W) const {
    const int J = directions(), K = coefficients();
    SHREFRACT_CHECK(R.rows() == J && R.cols() == 4 && W.rows() == K && W.cols() == 4);
    // B = Y^T diag(a c) R.
    Eigen::VectorXf ac(J);
    for (int j = 0; j < J; ++j) ac(j) = a_(j) * c[j];
    const Eigen::LLT<Eigen::MatrixXf, Eigen::Lower> llt(G.selfadjointView<Eigen::Lower>());
    // cond(G) >= (max L_ii / min L_ii)^2: past 1e4, float's 6e-8 no longer gives the solution
    // to 1e-3.
    const Eigen::VectorXf pivots = llt.matrixLLT().diagonal();
    if (llt.info() == Eigen::Success && pivots.minCoeff() > 1e-2f * pivots.maxCoeff()) {
        W = llt.solve(Y_.transpose() * (ac.asDiagonal() * R));
        if (W.allFinite()) return;
    }
    // The slow path, for the samples that need it. Close to as many coefficients as directions,
    // the problem can be rank-deficient (order 14 on an 8x16 grid: cos 14 phi and cos 2 phi agree
    // at 16 azimuths), and with most directions discounted the float update Gall -
    // sum a (1 - c) y y^T cancels to a matrix that is badly conditioned or not positive definite
    // (a tetrahedron there gave NaN). So: the same problem in double, from the weighted design
    // matrix, rows sqrt(a_j c_j) y_j (never forming G, which squares the condition), plus rows
    // sqrt(ridge_k) e_k; its minimum-norm solution by a complete orthogonal decomposition, which
    // drops what the directions determine to less than 1e-6 of the best-determined part. Small
    // coefficients, so the float weights keep what they sum to.
    const int ridged = int((ridge_.array() > 0).count());
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(J + ridged, K), B = Eigen::MatrixXd::Zero(J + ridged, 4);
    for (int j = 0; j < J; ++j) {
        const double w = std::sqrt(double(ac(j)));
        A.row(j) = w * Y_.row(j).cast<double>();
        B.row(j) = w * R.row(j).cast<double>();
    }
    for (int k = 0, r = J; k < K; ++k)
        if (ridge_(k) > 0) A(r++, k) = std::sqrt(double(ridge_(k)));
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(1e-6);
    cod.compute(A);
    W = cod.solve(B).cast<float>();
}

SampleFit::SampleFit(const DirectionGrid& grid, int order, Fit fit, const FitWeighting& weighting,
                     double filterWidth, const std::string& cacheDir)
    : K_(shEvenCount(order)) {
    const std::vector<double> h = shBandFilter(order, filterWidth);
    const std::vector<int> band = evenBands(order);
    for (int k = 0; k < K_; ++k) h_.push_back(float(h[band[k]]));
    if (fit == Fit::Weighted) {
        fitter_ = std::make_unique<WeightedFitter>(grid, order, weighting);
    } else {
        Eigen::MatrixXd M = fit == Fit::LeastSquares ? leastSquaresMatrix(grid, order)
                                                     : compressionMatrixCached(grid, order, cacheDir);
        for (int k = 0; k < K_; ++k) M.row(k) *= h[band[k]];
        Mt_ = M.transpose().cast<float>();
    }
}

SampleFit::~SampleFit() = default;

void SampleFit::fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const PathResult* paths, int B,
                    Eigen::Ref<Eigen::MatrixXf> Wt) const {
    SHREFRACT_CHECK(R.cols() >= 4 * B && Wt.rows() >= 4 * B && Wt.cols() == K_);
    if (!fitter_) {
        Wt.topRows(4 * B).noalias() = R.leftCols(4 * B).transpose() * Mt_;
        return;
    }
    const int J = fitter_->directions();
    std::vector<float> confidence(J);
    Eigen::MatrixXf W(K_, 4);
    for (int s = 0; s < B; ++s) {
        fitter_->confidence(paths + size_t(s) * J, confidence.data());
        fitter_->fit(R.middleCols(4 * s, 4), confidence.data(), W);
        for (int k = 0; k < K_; ++k) W.row(k) *= h_[k];
        Wt.middleRows(4 * s, 4) = W.transpose();
    }
}

}  // namespace shrefract
