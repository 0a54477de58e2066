#include "eval/pixel_fit.h"

#include <cmath>

#include "common/error.h"
#include "common/frame.h"

namespace shrefract {

PixelFit::PixelFit(const BakeData& bake, PixelExits kind) : kind_(kind), order_(bake.order) {
    SHREFRACT_CHECK(kind != PixelExits::Exact);
    const nlohmann::json& m = bake.manifest;
    if (!m.is_object() || !m.contains("grid") || !m["grid"].is_array() || m["grid"].size() != 2)
        throw InputError("the bake's manifest has no direction grid: a pixel fit needs it");
    const std::string problem = gridProblem(m["grid"][0].get<int>(), m["grid"][1].get<int>());
    if (!problem.empty()) throw InputError("the bake's manifest grid: " + problem);
    grid_.nTheta = m["grid"][0].get<int>();
    grid_.nPhi = m["grid"][1].get<int>();
    const Fit fit = parseInput<Fit>(m.value("fit", std::string("projection")));
    const std::string weightingText = m.value("fitWeighting", std::string());
    const FitWeighting weighting =
        weightingText.empty() ? FitWeighting{} : FitWeighting::parse(weightingText, "the manifest's fitWeighting");
    if (!fitCanSolve(fit, order_, grid_))
        throw InputError(str("the bake's ", nameOf(fit), " fit cannot make order ", order_, " from its grid"));
    fit_ = std::make_unique<SampleFit>(grid_, order_, fit, weighting, m.value("filterWidth", 0.0), "");
    if (kind == PixelExits::Split) {
        confidence_ = std::make_unique<WeightedFitter>(grid_, order_, weighting);
        split_ = std::make_unique<SplitFitter>(grid_, kSplitBranchOrder, kSplitIndicatorOrder,
                                               uint32_t(kPathTIR), weighting);
    }
}

PixelFit::~PixelFit() = default;

namespace {

double angleBetween(glm::vec3 fitted, glm::vec3 traced) {
    const float len = glm::length(fitted);
    return len > 0 ? std::acos(std::clamp(double(glm::dot(fitted / len, traced)), -1.0, 1.0)) : M_PI;
}

}  // namespace

PathResult PixelFit::exit(const Tracer& tracer, glm::vec3 p, glm::vec3 n, glm::vec3 omega,
                          int part) const {
    // The grid from this very point, in the frame a sample with this normal has (common/frame.h).
    const Frame f = Frame::fromNormal(n);
    const int J = grid_.count();
    std::vector<PathResult> paths(J);
    Eigen::MatrixXf R(J, 4);
    for (int j = 0; j < J; ++j) {
        paths[j] = tracer.trace(p, n, f.fromLocal(glm::vec3(grid_.direction(j))), part);
        R.row(j) << paths[j].exit.x, paths[j].exit.y, paths[j].exit.z, paths[j].length;
    }
    const glm::vec3 w = f.toLocal(omega);
    glm::vec4 e(0.0f);
    if (kind_ == PixelExits::Grid) {
        int index[4];
        double weight[4];
        const int count = grid_.interpolate(glm::dvec3(w), index, weight);
        for (int q = 0; q < count; ++q)
            e += float(weight[q]) * glm::vec4(R(index[q], 0), R(index[q], 1), R(index[q], 2), R(index[q], 3));
    } else {
        Eigen::MatrixXf Wt(4, fit_->coefficients());
        fit_->fit(R, fit_->needsPaths() ? paths.data() : nullptr, 1, Wt);
        const Eigen::MatrixXf W = Wt.transpose();
        e = evaluateFit(order_, W, w);
        if (kind_ == PixelExits::Split) {
            // The pick, as the bake would make it: the split only where it misses the grid's own
            // exits by less (confidence-weighted mean) than the bake's fit does.
            const SplitModel s = split_->fit(R, paths.data());
            std::vector<float> c(J);
            confidence_->confidence(paths.data(), c.data());
            double errSplit = 0, errFit = 0;
            for (int j = 0; j < J; ++j) {
                const glm::vec3 wj(grid_.direction(j));
                errSplit += c[j] * angleBetween(glm::vec3(split_->evaluate(s, wj)), paths[j].exit);
                errFit += c[j] * angleBetween(glm::vec3(evaluateFit(order_, W, wj)), paths[j].exit);
            }
            if (errSplit < errFit) e = split_->evaluate(s, w);
        }
    }
    PathResult r;
    const float len = glm::length(glm::vec3(e));
    r.exit = len > 0 ? glm::vec3(e) / len : n;  // a fit that vanishes here (not seen): straight on
    r.length = e.w;
    return r;
}

}  // namespace shrefract
