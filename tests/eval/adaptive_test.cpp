// Per-sample adaptive order (eval/adaptive.h): the bake a per-sample order would draw.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bake/bake.h"
#include "common/sh.h"
#include "eval/adaptive.h"

namespace shrefract {
namespace {

// The icosphere at rate 1, order 4, f32, with its error model (order 4): small enough for a test.
struct Icosphere {
    Scene scene;
    BakeData data;
};
const Icosphere& icosphere() {
    static Icosphere b = [] {
        Icosphere r;
        const std::string path = std::string(SHREFRACT_DATA_DIR) + "/scenes/icosphere.off";
        r.scene = loadScene(path);
        BakeOptions o;
        o.order = 4, o.rate = 1, o.precision = Precision::F32, o.errorOrder = 4;
        o.grid = DirectionGrid{8, 16};
        r.data = bake(r.scene, o, path).data;
        return r;
    }();
    return b;
}

// Every sample at its full order is the bake itself: the paths traced afresh and fitted again
// give the bake's weights and error model (a round trip through a second trace of every path);
// every sample at order 0 has band 0 alone, every band above it exactly zero.
TEST(Adaptive, PerSampleOrderBakesRefitEachSampleAtItsOrder) {
    const Icosphere& b = icosphere();
    const BakeData& d = b.data;
    ASSERT_EQ(d.errorOrder, 4);
    const size_t n = size_t(d.layout.sampleCount());
    const int K = d.coefficientCount();
    const std::vector<BakeData> t = perSampleOrderBakes(
        d, b.scene, {std::vector<int>(n, d.order), std::vector<int>(n, 0)});
    ASSERT_EQ(t.size(), 2u);
    double worstWeight = 0, worst = 0;
    for (size_t k = 0; k < d.weights.size(); ++k)
        worstWeight = std::max(worstWeight, double(std::abs(t[0].weights[k] - d.weights[k])));
    for (size_t k = 0; k < d.errors.size(); ++k) worst = std::max(worst, double(std::abs(t[0].errors[k] - d.errors[k])));
    // Measured 0 (the bake solves the same per-sample problems); 1e-4 leaves room for another
    // summation order, and a wrong direction order or frame changes weights by order 1.
    EXPECT_LT(worstWeight, 1e-4);
    // Measured 5.7e-6 (the same paths and fit, summed in batches of 1 instead of 32); a wrong
    // frame or direction order misses by whole units of ln(angle).
    EXPECT_LT(worst, 1e-4);
    size_t nonzero = 0;
    for (int k = 1; k < K; ++k)
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 4; ++c) nonzero += t[1].weights[(size_t(k) * n + i) * 4 + c] != 0.0f;
    EXPECT_EQ(nonzero, 0u);
    for (size_t i = 0; i < n; ++i)  // band 0 fitted: an exit direction and a length
        EXPECT_GT(std::abs(t[1].weights[i * 4 + 0]) + std::abs(t[1].weights[i * 4 + 1]) +
                      std::abs(t[1].weights[i * 4 + 2]), 0.1f) << "sample " << i;
    // Band 0 alone points every exit the same way, whatever the view: the refitted model must
    // predict far more error than the full order's. Its constant term (k = 0, times y_0) is the
    // mean of ln(angle + offset) over the hemisphere, times sqrt(4 pi): measured -10.6 at the full
    // order and -5.7 at band 0 (the typical error 4.0 times larger); the test asks 1.
    double meanFull = 0, meanZero = 0;
    for (size_t i = 0; i < n; ++i) meanFull += d.errors[i], meanZero += t[1].errors[i];
    EXPECT_GT(meanZero / n, meanFull / n + 1.0) << "mean constant terms " << meanFull / n << " and " << meanZero / n;
}

// The order each sample needs: all of them at tolerance 0 (nothing may change), none above band 0
// at a tolerance no reconstruction can exceed (180 degrees).
TEST(Adaptive, OrdersFollowTheTolerance) {
    const BakeData& d = icosphere().data;
    for (int o : adaptiveOrders(d, 180.0)) EXPECT_EQ(o, 0);
    size_t full = 0;
    for (int o : adaptiveOrders(d, 0.0)) full += o == d.order;
    // A sample whose top band is exactly zero could stop below it; a fitted icosphere has none.
    EXPECT_EQ(full, size_t(d.layout.sampleCount()));
}

}  // namespace
}  // namespace shrefract
