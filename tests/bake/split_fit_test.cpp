// The split fit (bake/split_fit.h) against a closed form with an edge: a mapping whose exit jumps
// where the view direction crosses a tilted cone, the paths inside flagged TIR, as at the border
// of a TIR band. Measured at random off-grid directions against the closed form itself.
#include "bake/split_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "common/sh.h"

namespace shrefract {
namespace {

const glm::vec3 kAxis = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
const float kBorder = std::cos(glm::radians(45.0f));

// Inside the cone (angle to kAxis above 45 degrees, toward grazing): TIR, exit mostly sideways;
// outside: exit mostly down. Both smooth in w; about 80 degrees apart at the border.
bool inside(glm::vec3 w) { return glm::dot(w, kAxis) < kBorder; }
glm::vec3 exitOf(glm::vec3 w) {
    return inside(w) ? glm::normalize(glm::vec3(w.x, w.y, 0.3f)) : glm::normalize(glm::vec3(0.2f * w.x, 0.2f * w.y, -1.0f));
}

double angleDeg(glm::vec3 a, glm::vec3 b) {
    return glm::degrees(std::acos(std::clamp(double(glm::dot(glm::normalize(a), b)), -1.0, 1.0)));
}

double quantile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[size_t(q * (v.size() - 1))];
}

TEST(SplitFit, KeepsTheEdgeThatTheWholeHemisphereFitBlurs) {
    const DirectionGrid g{32, 64};
    const int J = g.count();
    std::vector<PathResult> paths(J);
    Eigen::MatrixXf R(J, 4);
    for (int j = 0; j < J; ++j) {
        const glm::vec3 w(g.direction(j));
        paths[j].exit = exitOf(w);
        paths[j].length = 1.0f;
        paths[j].flags = inside(w) ? kPathTIR : 0u;
        R.row(j) << paths[j].exit.x, paths[j].exit.y, paths[j].exit.z, 1.0f;
    }
    // Fewer floats: the split 6:12 stores 2 x 4 x 28 + 91 = 315, order 12 stores 4 x 91 = 364.
    const SplitFitter split(g, 6, 12, kPathTIR);
    ASSERT_EQ(split.floats(), 315);
    const SplitModel m = split.fit(R, paths.data());
    const WeightedFitter whole(g, 12, FitWeighting{});
    std::vector<float> c(J);
    whole.confidence(paths.data(), c.data());
    Eigen::MatrixXf W(shEvenCount(12), 4);
    whole.fit(R, c.data(), W);
    std::vector<float> y(shEvenCount(12));

    // Near the border: within 3 degrees of the cone (about one grid cell).
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    std::vector<double> splitFar, splitNear, wholeNear;
    while (splitNear.size() < 2000 || splitFar.size() < 2000) {
        const float z = U(rng), phi = 6.2831853f * U(rng), r = std::sqrt(1 - z * z);
        const glm::vec3 w(r * std::cos(phi), r * std::sin(phi), z);
        const double fromBorder = std::abs(glm::degrees(std::acos(glm::dot(w, kAxis))) - 45.0);
        const glm::vec3 truth = exitOf(w);
        if (fromBorder < 3.0) {
            splitNear.push_back(angleDeg(glm::vec3(split.evaluate(m, w)), truth));
            shEvalEven(12, w, y.data());
            glm::vec3 e(0.0f);
            for (int k = 0; k < W.rows(); ++k) e += y[k] * glm::vec3(W(k, 0), W(k, 1), W(k, 2));
            wholeNear.push_back(angleDeg(e, truth));
        } else if (fromBorder > 10.0) {
            splitFar.push_back(angleDeg(glm::vec3(split.evaluate(m, w)), truth));
        }
    }
    const double farP95 = quantile(splitFar, 0.95), nearMedian = quantile(splitNear, 0.5),
                 wholeMedian = quantile(wholeNear, 0.5);
    auto wrong = [](const std::vector<double>& e) {  // the share off by more than 30 degrees
        return double(std::count_if(e.begin(), e.end(), [](double a) { return a > 30.0; })) / e.size();
    };
    std::printf("[ measured ] split: p95 %.3f deg away from the border, near it median %.3f wrong %.3f; "
                "order 12 near it median %.3f wrong %.3f\n", farP95, nearMedian, wrong(splitNear),
                wholeMedian, wrong(wholeNear));
    // Measured: away from the border p95 0.26 deg; within 3 degrees of it the median 0.44 deg,
    // and 6.9 % on the wrong side (off by more than 30 degrees), where order 12 has a median of
    // 53.9 deg and 53 % off by more than 30. About 2x margins; branches swapped, or fitted without
    // the other side discounted (kAcross 1), fail them.
    EXPECT_LT(farP95, 0.5);
    EXPECT_LT(nearMedian, 1.0);
    EXPECT_LT(wrong(splitNear), 0.15);
    EXPECT_GT(wholeMedian, 25.0);
    EXPECT_GT(wrong(wholeNear), 0.3);
}

}  // namespace
}  // namespace shrefract
