// Bakes built in memory for runtime tests: a welded octahedron (closed, sphere normals) laid out
// by the bake's joining layout, with random SH weights. No tracing: the tests check that the GL
// pipeline reproduces the CPU decompressor, whatever the weights are.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bake/joining_layout.h"
#include "common/bakefile.h"
#include "common/decompress.h"
#include "common/scene.h"
#include "common/sh.h"
#include "shrefract/runtime.h"

namespace shrefract::test {

inline Mesh octahedron() {
    Mesh m;
    m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.normals = m.positions;
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return m;
}

// A bake of `layout` (any kind) with random weights in [-1, 1] for x, y, z and [0, 2] for the
// length; band 0 biased so the exit direction is rarely near zero.
inline BakeData randomBake(SurfaceLayout layout, int order, unsigned seed = 7) {
    BakeData d;
    d.order = order;
    d.layout = std::move(layout);
    d.manifest = {{"media", {{{"name", "glass"}, {"ior", 1.5}, {"absorption", {0.1, 0.2, 0.3}}}}}};
    const size_t n = d.layout.position.size();
    d.weights.resize(shEvenCount(order) * n * 4);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (size_t k = 0; k < static_cast<size_t>(shEvenCount(order)); ++k)
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 4; ++c) {
                float w = u(rng) / (1.0f + k);  // decaying like a band-limited signal
                if (k == 0) w += c == 2 ? 3.0f : (c == 3 ? 2.0f : 0.0f);
                d.weights[(k * n + i) * 4 + c] = w;
            }
    return d;
}

// The octahedron's joining layout at `rate`.
inline SurfaceLayout octahedronLayout(int rate) {
    Scene scene;
    Part part;
    part.name = "octahedron";
    part.mesh = octahedron();
    scene.parts.push_back(part);
    return buildJoiningLayout(scene, rate);
}

// The octahedron's joining layout at `rate`, random weights.
inline BakeData randomBake(int order, int rate, unsigned seed = 7) {
    return randomBake(octahedronLayout(rate), order, seed);
}

// A grid-basis bake (BakeData::basis Grid) of the octahedron at `rate`: every sample's exit at
// every direction of `grid` random, x, y, z in [-1, 1] around +z and the length in [0, 2].
inline BakeData randomGridBake(DirectionGrid grid, int rate, unsigned seed = 7) {
    BakeData d;
    d.basis = Basis::Grid;
    d.order = 0;
    d.grid = grid;
    d.layout = octahedronLayout(rate);
    d.manifest = {{"media", {{{"name", "glass"}, {"ior", 1.5}, {"absorption", {0.1, 0.2, 0.3}}}}}};
    const size_t n = d.layout.position.size();
    d.weights.resize(size_t(grid.count()) * n * 4);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (float& w : d.weights) w = u(rng);
    for (size_t t = 0; t < size_t(grid.count()) * n; ++t) d.weights[t * 4 + 2] += 2.0f, d.weights[t * 4 + 3] += 1.0f;
    return d;
}

// Updates `r` for `eye` and reads its directional map back (RGBA per mu sample): the largest
// |GL - CPU| over every sample and channel, against the CPU decompressor at the same eye, bands
// 0..order (-1: all).
inline float worstAgainstCpu(Refractor& r, const BakeData& data, glm::vec3 eye, int order = -1) {
    r.update(FrameView::fromEye(eye));
    const std::vector<float> gl = r.readDirectionalMap();
    float worst = 0;
    for (int i = 0; i < data.layout.sampleCount(); ++i) {
        const glm::vec4 cpu = decompressSample(data, i, localViewFromEye(data.layout, i, eye), order);
        for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(gl[4 * i + c] - cpu[c]));
    }
    return worst;
}

}  // namespace shrefract::test
