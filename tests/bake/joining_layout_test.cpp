// Invariants of the joining-surfaces layout (paper §5.3, docs/design.md#surface-layouts).
#include "bake/joining_layout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "common/decompress.h"
#include "test_meshes.h"

namespace shrefract {
namespace {

// Position of grid sample (i, j) of triangle t computed from its own corners.
glm::vec3 gridPosition(const Scene& s, int t, int i, int j, int r) {
    const Mesh& m = s.parts[0].mesh;
    glm::uvec3 tri = m.triangles[t];
    float u = float(i) / r, v = float(j) / r;
    return (1 - u - v) * m.positions[tri[0]] + u * m.positions[tri[1]] + v * m.positions[tri[2]];
}

class LayoutAtRate : public ::testing::TestWithParam<int> {};

TEST_P(LayoutAtRate, SharedEdgeSamplesAreOneSampleAndCountsAreExact) {
    const int r = GetParam();
    Scene s = test::sceneOf(test::icosphere(1));  // 42 vertices, 120 edges, 80 triangles
    SurfaceLayout L = buildJoiningLayout(s, r);
    // Closed mesh: V + E (r-1) + T (r-1)(r-2)/2 unique samples.
    size_t expected = 42 + 120 * (r - 1) + 80 * (r - 1) * (r - 2) / 2;
    EXPECT_EQ(size_t(L.sampleCount()), expected);
    EXPECT_EQ(joiningSampleCount(s, r), expected);

    // Every grid sample of every triangle is the sample at that very position, and no two
    // samples share a position: shared vertices and edges are the same sample o_i.
    std::map<std::tuple<long, long, long>, uint32_t> byPosition;
    auto key = [](glm::vec3 p) {
        return std::make_tuple(std::lround(p.x * 1e5), std::lround(p.y * 1e5), std::lround(p.z * 1e5));
    };
    for (int t = 0; t < L.triangleCount; ++t)
        for (int j = 0; j <= r; ++j)
            for (int i = 0; i + j <= r; ++i) {
                uint32_t id = L.sampleAt(t, i, j);
                glm::vec3 p = gridPosition(s, t, i, j, r);
                EXPECT_LT(glm::length(L.position[id] - p), 1e-6f);
                auto [it, inserted] = byPosition.emplace(key(p), id);
                EXPECT_EQ(it->second, id) << "two samples at one position";
            }
    EXPECT_EQ(byPosition.size(), size_t(L.sampleCount()));
}

TEST_P(LayoutAtRate, EveryMuSampleIsUsedAndTexelKindsAddUp) {
    const int r = GetParam();
    Scene s = test::sceneOf(test::icosphere(1));
    SurfaceLayout L = buildJoiningLayout(s, r);
    std::vector<int> uses(L.sampleCount(), 0);
    size_t samples = 0, corrections = 0;
    for (const RhoTexel& t : L.rho) {
        if (t.kind == RhoTexel::Sample) ++samples, ++uses[t.a];
        if (t.kind == RhoTexel::Correction) ++corrections;
    }
    EXPECT_EQ(samples, size_t(L.triangleCount) * (r + 1) * (r + 2) / 2);
    EXPECT_EQ(corrections, size_t(L.triangleCount) * r);  // none lost to a partner's texel
    for (int i = 0; i < L.sampleCount(); ++i) EXPECT_GT(uses[i], 0) << "sample " << i;
    EXPECT_GE(L.muWidth * L.muHeight, L.sampleCount());
    EXPECT_LT(L.muWidth * (L.muHeight - 1), L.sampleCount());  // no spare row: dense packing
}

// Hardware bilinear filtering of the rho texture (texel centres at integer + 1/2), written out.
glm::vec4 bilinear(const std::vector<glm::vec4>& img, int w, int h, glm::vec2 xy) {
    glm::vec2 f = xy - 0.5f;
    int x0 = int(std::floor(f.x)), y0 = int(std::floor(f.y));
    float a = f.x - x0, b = f.y - y0;
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, w - 1), y = std::clamp(y, 0, h - 1);
        return img[size_t(y) * w + x];
    };
    return (1 - a) * (1 - b) * at(x0, y0) + a * (1 - b) * at(x0 + 1, y0) + (1 - a) * b * at(x0, y0 + 1) +
           a * b * at(x0 + 1, y0 + 1);
}

// The refraction map as the runtime's unpack pass writes it, from values per mu sample.
std::vector<glm::vec4> unpackRho(const SurfaceLayout& L, const std::vector<glm::vec4>& D, bool correct) {
    std::vector<glm::vec4> img(L.rho.size(), glm::vec4(0));
    for (size_t k = 0; k < L.rho.size(); ++k) {
        const RhoTexel& t = L.rho[k];
        if (t.kind == RhoTexel::Sample) img[k] = D[t.a];
        if (t.kind == RhoTexel::Correction && correct) img[k] = D[t.a] + D[t.b] - D[t.c];
    }
    return img;
}

// Texel-space position of barycentric (u, v) in triangle t: corners at texel centres.
glm::vec2 rhoPoint(const SurfaceLayout& L, int t, float u, float v) {
    const int r = L.rate;
    glm::vec2 c0 = glm::vec2(L.rhoTexel(t, 0, 0)) + 0.5f, c1 = glm::vec2(L.rhoTexel(t, r, 0)) + 0.5f,
              c2 = glm::vec2(L.rhoTexel(t, 0, r)) + 0.5f;
    return (1 - u - v) * c0 + u * c1 + v * c2;
}

TEST_P(LayoutAtRate, CorrectionMakesBilinearFilteringBarycentric) {
    const int r = GetParam();
    Scene s = test::sceneOf(test::icosphere(1));
    SurfaceLayout L = buildJoiningLayout(s, r);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(-1, 1);
    std::vector<glm::vec4> D(L.sampleCount());
    for (auto& d : D) d = {U(rng), U(rng), U(rng), U(rng)};
    std::vector<glm::vec4> img = unpackRho(L, D, true), raw = unpackRho(L, D, false);
    std::uniform_real_distribution<float> U01(0, 1);
    float worstOn = 0, worstOff = 0;
    for (int t = 0; t < L.triangleCount; ++t) {
        for (int k = 0; k < 20; ++k) {
            float u = U01(rng), v = U01(rng);
            if (u + v > 1) u = 1 - u, v = 1 - v;
            glm::vec2 xy = rhoPoint(L, t, u, v);
            glm::vec4 ref = interpolateRho(L, D.data(), t, u, v);
            worstOn = std::max(worstOn, glm::length(bilinear(img, L.rhoWidth, L.rhoHeight, xy) - ref));
            worstOff = std::max(worstOff, glm::length(bilinear(raw, L.rhoWidth, L.rhoHeight, xy) - ref));
        }
        // On the hypotenuse (the seam with the neighbouring triangle) the value must be the
        // linear blend of the two edge samples alone.
        for (float f : {0.1f, 0.37f, 0.5f, 0.93f}) {
            glm::vec2 xy = rhoPoint(L, t, 1 - f, f);
            glm::vec4 expect = (1 - f) * D[L.sampleAt(t, r, 0)] + f * D[L.sampleAt(t, 0, r)];
            if (r == 1) EXPECT_LT(glm::length(bilinear(img, L.rhoWidth, L.rhoHeight, xy) - expect), 1e-5f);
        }
    }
    // Float rounding only: measured 1.5e-5 at rate 5, where texel coordinates reach ~1e2.
    EXPECT_LT(worstOn, 5e-5f);
    EXPECT_GT(worstOff, 1e-2f);  // without correction the half-cells are wrong
}

INSTANTIATE_TEST_SUITE_P(Rates, LayoutAtRate, ::testing::Values(1, 2, 3, 5));

TEST(Layout, RateForSampleCountIsTheSmallestReachingTheTarget) {
    Scene s = test::sceneOf(test::icosphere(2));
    for (size_t target : {1ul, 162ul, 163ul, 1000ul, 5000ul}) {
        int r = rateForSampleCount(s, target);
        EXPECT_GE(joiningSampleCount(s, r), target);
        if (r > 1) EXPECT_LT(joiningSampleCount(s, r - 1), target);
    }
}

TEST(Layout, NeighbourWeightsSumToOneAndAreSymmetricNeighbours) {
    Scene s = test::sceneOf(test::icosphere(1));
    SurfaceLayout L = buildJoiningLayout(s, 3);
    std::set<std::pair<uint32_t, uint32_t>> links;
    for (int i = 0; i < L.sampleCount(); ++i) {
        float sum = 0;
        EXPECT_EQ(L.neighbourIndex[L.neighbourOffset[i]], uint32_t(i));  // itself first
        for (uint32_t k = 0; k < L.neighbourCount[i]; ++k) {
            sum += L.neighbourWeight[L.neighbourOffset[i] + k];
            links.emplace(i, L.neighbourIndex[L.neighbourOffset[i] + k]);
        }
        EXPECT_NEAR(sum, 1.0f, 1e-5f);
        EXPECT_GE(L.neighbourCount[i], 5u);  // a closed triangulated surface: valence >= 3, +1
    }
    for (auto [a, b] : links) EXPECT_TRUE(links.count({b, a})) << a << " " << b;
}

}  // namespace
}  // namespace shrefract
