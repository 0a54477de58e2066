// The CPU twin of the chart pipeline (common/decompress.h): gutter rings, dilation, seam
// sources, bilinear lookup and the seam jump, on tiny atlases whose answers are worked out by
// hand.
#include "common/decompress.h"
#include "common/sh.h"

#include <gtest/gtest.h>

#include <cmath>

namespace shrefract {
namespace {

// A W x H chart layout whose samples sit at `texels` (y * W + x), with no mesh.
SurfaceLayout atlas(int W, int H, const std::vector<uint32_t>& texels) {
    SurfaceLayout L;
    L.kind = LayoutKind::Isolated;
    L.muWidth = L.rhoWidth = W;
    L.muHeight = L.rhoHeight = H;
    L.rho.assign(size_t(W) * H, RhoTexel{});
    for (uint32_t i = 0; i < texels.size(); ++i) {
        L.position.push_back(glm::vec3(float(i)));
        L.normal.push_back({0, 0, 1});
        L.part.push_back(0);
        L.atlas.sampleTexel.push_back(texels[i]);
        L.rho[texels[i]] = RhoTexel{RhoTexel::Sample, i, 0, 0};
    }
    return L;
}

TEST(ChartMap, RingsCountEightNeighbourSteps) {
    // 7 x 5, one covered texel at (1, 2): rings are Chebyshev distances, cut at the width.
    const SurfaceLayout L = atlas(7, 5, {2 * 7 + 1});
    const std::vector<uint8_t> r = gutterRings(L, 2);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) {
            const int d = std::max(std::abs(x - 1), std::abs(y - 2));
            EXPECT_EQ(r[size_t(y) * 7 + x], d <= 2 ? d : kNoRing) << x << "," << y;
        }
}

TEST(ChartMap, DilationTakesTheMeanOfLowerRings) {
    // Covered (2, 1) = a and (4, 1) = b in a 7 x 3 atlas. Ring 1: (3, 1) touches both: (a + b) / 2;
    // (1, 0) only a. Ring 2: (0, 0) touches only ring 1 texels (1, 0), (1, 1), (0, 1)... all = a.
    const SurfaceLayout L = atlas(7, 3, {1 * 7 + 2, 1 * 7 + 4});
    const glm::vec4 a(1, 0, 0, 2), b(0, 1, 0, 4);
    const glm::vec4 values[2] = {a, b};
    ChartMapOptions o;
    o.dilation = 2, o.seamAware = false;
    const std::vector<glm::vec4> m = chartRefractionMap(L, values, o);
    auto at = [&](int x, int y) { return m[size_t(y) * 7 + x]; };
    EXPECT_EQ(at(2, 1), a);
    EXPECT_EQ(at(4, 1), b);
    EXPECT_EQ(at(3, 1), 0.5f * (a + b));
    EXPECT_EQ(at(3, 0), 0.5f * (a + b));
    EXPECT_EQ(at(1, 0), a);
    EXPECT_EQ(at(5, 2), b);
    // Ring 2 at (0, 1): its lower neighbours are (1, 0), (1, 1), (1, 2), all a.
    EXPECT_EQ(at(0, 1), a);
    // Without dilation the gutters stay empty.
    o.dilation = 0;
    EXPECT_EQ(chartRefractionMap(L, values, o)[1 * 7 + 3], glm::vec4(0.0f));
}

TEST(ChartMap, SeamSourcesReplaceGutterTexelsWithinTheWidth) {
    SurfaceLayout L = atlas(9, 1, {2, 6});
    const glm::vec4 values[2] = {{1, 0, 0, 1}, {0, 1, 0, 3}};
    SeamSource near, far;
    near.texel = 3, near.sample[0] = 1, near.sample[1] = 0, near.weight[0] = 0.75f, near.weight[1] = 0.25f;
    far.texel = 0, far.sample[0] = 1, far.weight[0] = 1.0f;  // ring 2
    L.atlas.seam = {near, far};
    ChartMapOptions o;
    o.dilation = 1;
    const std::vector<glm::vec4> m = chartRefractionMap(L, values, o);
    EXPECT_EQ(m[3], 0.75f * values[1] + 0.25f * values[0]);
    EXPECT_EQ(m[1], values[0]);            // ring 1, no source: dilated
    EXPECT_EQ(m[0], glm::vec4(0.0f));      // ring 2 is beyond the width: its source waits
    o.seamAware = false;
    EXPECT_EQ(chartRefractionMap(L, values, o)[3], values[0]);
}

TEST(ChartMap, BilinearLookupIsExactOnALinearRamp) {
    const int W = 8, H = 4;
    std::vector<glm::vec4> img(size_t(W) * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) img[size_t(y) * W + x] = glm::vec4(x + 0.5f, y + 0.5f, 2.0f * x - y, 1);
    for (glm::vec2 uv : {glm::vec2(0.3f, 0.4f), glm::vec2(0.71f, 0.55f), glm::vec2(0.5f, 0.5f)}) {
        const glm::vec4 v = sampleBilinear(img, W, H, uv);
        const float x = uv.x * W, y = uv.y * H;  // texel units: centres at +0.5
        EXPECT_NEAR(v.x, x, 1e-5f);
        EXPECT_NEAR(v.y, y, 1e-5f);
        EXPECT_NEAR(v.z, 2.0f * (x - 0.5f) - (y - 0.5f), 1e-5f);
    }
    // Clamped at the border like GL_CLAMP_TO_EDGE.
    EXPECT_NEAR(sampleBilinear(img, W, H, {0.0f, 0.0f}).x, 0.5f, 1e-6f);
}

// Two one-triangle charts share an edge of the surface (same positions and normals) at different
// places in the atlas; a map holding +x on one chart's side and +y on the other's jumps by 90
// degrees at every point along the seam, and not at all when both sides hold the same.
TEST(ChartMap, SeamJumpIsTheAngleAcrossTheCut) {
    SurfaceLayout L = atlas(16, 8, {});
    ChartAtlas& A = L.atlas;
    A.chartCount = 2;
    const glm::vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    // Chart 0 in the left half, chart 1 mirrored into the right half; edge p0-p1 is the seam.
    const glm::vec2 uv0[3] = {{0.1f, 0.2f}, {0.4f, 0.2f}, {0.1f, 0.8f}};
    const glm::vec2 uv1[3] = {{0.6f, 0.2f}, {0.9f, 0.2f}, {0.9f, 0.8f}};
    for (int c = 0; c < 2; ++c)
        for (int k = 0; k < 3; ++k) {
            A.vertexPosition.push_back(k == 2 && c == 1 ? glm::vec3(0, -1, 0) : p[k]);
            A.vertexNormal.push_back({0, 0, 1});
            A.vertexUV.push_back(c == 0 ? uv0[k] : uv1[k]);
            A.vertexChart.push_back(uint32_t(c));
        }
    A.triangles = {{0, 1, 2}, {4, 3, 5}};  // the second runs p1 -> p0 along the shared edge
    ASSERT_EQ(smoothSeams(L).size(), 1u);
    std::vector<glm::vec4> map(16 * 8, glm::vec4(0.0f));
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) map[size_t(y) * 16 + x] = x < 8 ? glm::vec4(1, 0, 0, 0) : glm::vec4(0, 1, 0, 0);
    for (double j : seamJumps(L, map)) EXPECT_NEAR(j, 90.0, 1e-4);
    for (auto& v : map) v = glm::vec4(0.6f, 0.8f, 0, 0);
    for (double j : seamJumps(L, map)) EXPECT_NEAR(j, 0.0, 1e-2);
    // A crease (the normals differ across the edge) is no smooth seam.
    A.vertexNormal[3] = A.vertexNormal[4] = glm::vec3(0, 1, 0);
    EXPECT_TRUE(smoothSeams(L).empty());
}

// predictedError evaluates the error model's SH, undoes its logarithm and clamps at 0. Sample 1:
// ln(err + 0.01) = ln 0.21 + y_2^0(w), y_2^0 = sqrt(5 / (16 pi)) (3 z^2 - 1); sample 0: a
// constant below ln 0.01, so no error anywhere.
TEST(Decompress, PredictedErrorIsTheModelClampedAtZero) {
    BakeData d;
    d.layout.position = {{0, 0, 0}, {1, 0, 0}};
    d.errorOrder = 2;
    d.errors.assign(size_t(shEvenCount(2)) * 2, 0.0f);
    const float root4pi = std::sqrt(4.0f * float(M_PI));
    d.errors[0] = std::log(0.005f) * root4pi;      // sample 0, band 0
    d.errors[1] = std::log(0.21f) * root4pi;       // sample 1, band 0
    d.errors[size_t(shEvenIndex(2, 0)) * 2 + 1] = 1.0f;
    const float c = std::sqrt(5.0f / (16.0f * float(M_PI)));
    EXPECT_NEAR(predictedError(d, 1, {0, 0, 1}), 0.21f * std::exp(2 * c) - 0.01f, 1e-5f);
    EXPECT_NEAR(predictedError(d, 1, glm::normalize(glm::vec3(1, 0, 1))), 0.21f * std::exp(0.5f * c) - 0.01f, 1e-5f);
    EXPECT_NEAR(predictedError(d, 1, {1, 0, 0}), 0.21f * std::exp(-c) - 0.01f, 1e-5f);
    EXPECT_EQ(predictedError(d, 0, {0, 0, 1}), 0.0f);
    d.errorOrder = -1;
    d.errors.clear();
    EXPECT_EQ(predictedError(d, 1, {0, 0, 1}), -1.0f);  // no model
}

}  // namespace
}  // namespace shrefract
