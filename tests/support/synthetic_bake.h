// Small bakes made in memory, every part of the format filled (tests of the file format and the
// glTF export).
#pragma once

#include <cstdint>
#include <random>

#include <nlohmann/json.hpp>

#include "common/bakefile.h"

namespace shrefract::test {

using nlohmann::json;

// Order 4 (15 stored coefficients), 37 samples in a 7 x 6 mu layout on 3 parts, 3 triangles at
// rate 2 in (r + 1) x (r + 4) = 3 x 6 blocks (2 per row) of a 6 x 12 rho layout holding all three
// texel kinds where the format puts them, and neighbour lists of 1..4 entries. Weights in [-1, 1]
// for x, y, z and lengths in [0, 3].
inline BakeData syntheticBake(Precision precision, uint32_t seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), length(0.0f, 3.0f);
    BakeData d;
    d.order = 4;
    d.precision = precision;
    SurfaceLayout& L = d.layout;
    const int N = 37;
    L.rate = 2;
    L.muWidth = 7, L.muHeight = 6;
    for (int i = 0; i < N; ++i) {
        L.position.push_back({unit(rng), unit(rng), unit(rng)});
        L.normal.push_back(glm::normalize(glm::vec3(unit(rng), unit(rng), 1.5f)));
        L.part.push_back(uint32_t(i % 3));
    }
    L.rhoWidth = 6, L.rhoHeight = 12;
    L.blockWidth = 3, L.blockHeight = 6, L.blocksPerRow = 2;
    L.triangleCount = 3;
    L.rho.resize(size_t(L.rhoWidth) * L.rhoHeight);
    // Triangle t's six grid samples are mu samples 6t + 1 .. 6t + 6 (sample 0 and those past 18
    // are on no triangle); its two corrections v11 = v01 + v10 - v00 refer to its own samples.
    for (int t = 0; t < L.triangleCount; ++t) {
        uint32_t next = uint32_t(6 * t + 1);
        for (int j = 0; j <= L.rate; ++j)
            for (int i = 0; i + j <= L.rate; ++i) {
                const glm::ivec2 x = L.rhoTexel(t, i, j);
                L.rho[size_t(x.y) * L.rhoWidth + x.x] = {RhoTexel::Sample, next++, 0, 0};
            }
        for (int i = 1; i <= L.rate; ++i) {
            const int j = L.rate + 1 - i;
            const glm::ivec2 x = L.rhoTexel(t, i, j);
            L.rho[size_t(x.y) * L.rhoWidth + x.x] = {RhoTexel::Correction, L.sampleAt(t, i - 1, j),
                                                     L.sampleAt(t, i, j - 1),
                                                     L.sampleAt(t, i - 1, j - 1)};
        }
    }
    for (int i = 0; i < N; ++i) {
        const uint32_t count = 1 + uint32_t(i % 4);
        L.neighbourOffset.push_back(uint32_t(L.neighbourIndex.size()));
        L.neighbourCount.push_back(count);
        for (uint32_t j = 0; j < count; ++j) {
            L.neighbourIndex.push_back(uint32_t((i + 3 * j) % N));  // itself first
            L.neighbourWeight.push_back(1.0f / float(count));
        }
    }
    const int K = d.coefficientCount();
    d.weights.resize(size_t(K) * N * 4);
    for (size_t v = 0; v < d.weights.size(); ++v)
        d.weights[v] = v % 4 == 3 ? length(rng) : unit(rng);
    d.manifest = {
        {"grid", {{"theta", 32}, {"phi", 64}}},
        {"filter", {{"kind", "semi-gaussian"}, {"width", 0.25}}},
        {"media", json::array({{{"name", "glass"}, {"ior", 1.5}},
                               {{"name", "water"}, {"ior", 1.33}},
                               {{"name", "air bubble"}, {"ior", 1.0}}})},
        {"meshChecksum", "fnv1a64:0123456789abcdef"},
        {"shConvention", "real, orthonormal, no Condon-Shortley phase"},
        {"stats", {{"tirPaths", 12}, {"cappedPaths", 0}}},
        {"order", 99},  // stale: writeBake overrides it
        {"u8", "stale"},
    };
    return d;
}

// A chart layout (isolated): a 6 x 5 atlas with two charts, 9 samples at scattered texels (not in
// texel order: sample i is not texel i), 5 vertices, 3 triangles, two seam sources.
inline BakeData syntheticChartBake(Precision precision, uint32_t seed = 5) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), length(0.0f, 3.0f);
    BakeData d;
    d.order = 2;
    d.precision = precision;
    SurfaceLayout& L = d.layout;
    L.kind = LayoutKind::Isolated;
    L.rate = 0;
    L.muWidth = L.rhoWidth = 6;
    L.muHeight = L.rhoHeight = 5;
    L.rho.assign(30, RhoTexel{});
    const uint32_t texel[9] = {7, 8, 13, 14, 2, 27, 21, 22, 28};
    for (uint32_t i = 0; i < 9; ++i) {
        L.position.push_back({unit(rng), unit(rng), unit(rng)});
        L.normal.push_back(glm::normalize(glm::vec3(unit(rng), unit(rng), 1.5f)));
        L.part.push_back(0);
        L.atlas.sampleTexel.push_back(texel[i]);
        L.rho[texel[i]] = RhoTexel{RhoTexel::Sample, i, 0, 0};
    }
    L.neighbourOffset.assign(9, 0);
    L.neighbourCount.assign(9, 0);
    ChartAtlas& A = L.atlas;
    A.gutter = 1;
    A.chartCount = 2;
    for (int v = 0; v < 5; ++v) {
        A.vertexPosition.push_back({unit(rng), unit(rng), unit(rng)});
        A.vertexNormal.push_back(glm::normalize(glm::vec3(unit(rng), 0.5f, 1.0f)));
        A.vertexUV.push_back({0.1f + 0.2f * v, 0.9f - 0.15f * v});
        A.vertexChart.push_back(v < 3 ? 0 : 1);
    }
    A.triangles = {{0, 1, 2}, {2, 1, 3}, {3, 4, 2}};
    L.triangleCount = 3;
    SeamSource a;
    a.texel = 1;
    a.sample[0] = 4, a.sample[1] = 2, a.weight[0] = 0.75f, a.weight[1] = 0.25f;
    SeamSource b;
    b.texel = 29;
    b.sample[0] = 8, b.weight[0] = 1.0f;
    A.seam = {a, b};
    const int K = d.coefficientCount();
    d.weights.resize(size_t(K) * 9 * 4);
    for (size_t v = 0; v < d.weights.size(); ++v) d.weights[v] = v % 4 == 3 ? length(rng) : unit(rng);
    d.manifest = {{"layout", {{"kind", "stale"}, {"method", "lscm"}}}};
    return d;
}

}  // namespace shrefract::test
