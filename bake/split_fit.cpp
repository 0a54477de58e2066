#include "bake/split_fit.h"

#include <vector>

#include "common/sh.h"

namespace shrefract {

namespace {
FitWeighting withoutFlags(FitWeighting w, uint32_t flags) {
    w.flags &= ~flags;
    return w;
}
}  // namespace

SplitFitter::SplitFitter(const DirectionGrid& grid, int branchOrder, int indicatorOrder, uint32_t classFlags,
                         FitWeighting weighting)
    : J_(grid.count()),
      branchOrder_(branchOrder),
      indicatorOrder_(indicatorOrder),
      classFlags_(classFlags),
      branchFitter_(grid, branchOrder, withoutFlags(weighting, classFlags)),
      indicatorMatrix_(leastSquaresMatrix(grid, indicatorOrder).cast<float>()) {}

int SplitFitter::floats() const { return 2 * 4 * shEvenCount(branchOrder_) + shEvenCount(indicatorOrder_); }

SplitModel SplitFitter::fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const PathResult* paths) const {
    SplitModel m;
    Eigen::VectorXf inClass(J_);
    for (int j = 0; j < J_; ++j) inClass(j) = (paths[j].flags & classFlags_) ? 1.0f : 0.0f;
    m.indicator = indicatorMatrix_ * inClass;
    std::vector<float> c(J_), side(J_);
    branchFitter_.confidence(paths, c.data());
    for (int b = 0; b < 2; ++b) {
        for (int j = 0; j < J_; ++j) side[j] = c[j] * ((inClass(j) > 0.5f) == (b == 1) ? 1.0f : kAcross);
        m.branch[b].resize(shEvenCount(branchOrder_), 4);
        branchFitter_.fit(R, side.data(), m.branch[b]);
    }
    return m;
}

glm::vec4 SplitFitter::evaluate(const SplitModel& m, glm::vec3 w) const {
    std::vector<float> y(shEvenCount(indicatorOrder_));
    shEvalEven(indicatorOrder_, w, y.data());
    float inside = 0.0f;
    for (int k = 0; k < m.indicator.size(); ++k) inside += y[k] * m.indicator(k);
    return evaluateFit(branchOrder_, m.branch[inside > 0.5f ? 1 : 0], w);
}

}  // namespace shrefract
