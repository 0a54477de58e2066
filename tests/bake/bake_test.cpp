// The bake's projection stage on cases with known answers.
#include "bake/bake.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "test_meshes.h"

namespace shrefract {
namespace {

// Band l of the k-th stored coefficient, from the even order's definition (k = l(l+1)/2 +
// (m+l)/2, docs/format.md), not from the code's tables.
int bandOf(int k) {
    int l = 0;
    while ((l + 1) * (l + 2) / 2 <= k) ++l;
    return l;
}

// The semi-Gaussian low-pass (paper §4.3) multiplies every coefficient of band l by
// exp(-(l / width)^2 / 2) and changes nothing else: the filtered weights are the unfiltered ones
// times that factor, coefficient by coefficient, to float rounding (the filter is folded into M
// before the float GEMM). Deviation per coefficient, relative to its largest weight: measured
// 1.4e-5; threshold 1e-4. Filtering a coefficient by another band's factor is off by 21% (band 1 by
// band 2) or more.
TEST(Bake, FilterScalesEachBandByItsSemiGaussian) {
    const Scene scene = test::sceneOf(test::icosphere(1), 1.5);
    BakeOptions o;
    o.order = 6;
    o.rate = 1;
    o.grid = DirectionGrid{8, 16};
    o.threads = 1;
    const BakeData plain = bake(scene, o, "<memory>").data;
    o.filterWidth = 2.5;
    const BakeData filtered = bake(scene, o, "<memory>").data;
    ASSERT_EQ(plain.weights.size(), filtered.weights.size());
    const size_t n = plain.layout.position.size();
    int checked = 0;
    double worstOverall = 0.0;
    for (int k = 0; k < plain.coefficientCount(); ++k) {
        const double l = bandOf(k), h = std::exp(-0.5 * (l / 2.5) * (l / 2.5));
        double scale = 0.0, worst = 0.0;
        for (size_t v = 0; v < 4 * n; ++v) scale = std::max(scale, std::abs(double(plain.weights[k * 4 * n + v])));
        if (scale < 1e-6) continue;  // a coefficient zero everywhere says nothing
        for (size_t v = 0; v < 4 * n; ++v) {
            const double a = plain.weights[k * 4 * n + v], b = filtered.weights[k * 4 * n + v];
            worst = std::max(worst, std::abs(b - h * a) / (h * scale));
        }
        EXPECT_LT(worst, 1e-4) << "coefficient " << k << " (band " << l << "): factor " << h;
        worstOverall = std::max(worstOverall, worst);
        ++checked;
    }
    std::printf("  filter: worst deviation from the band factor %.2g of the coefficient's scale\n",
                worstOverall);
    EXPECT_GE(checked, 20);
}

}  // namespace
}  // namespace shrefract
