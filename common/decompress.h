// The CPU decompressor: the same math as the runtime's GLSL passes, for tests, evaluation and
// apps without GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/bakefile.h"

namespace shrefract {

// Local view direction of sample i for a viewer in direction `omega` (object space, unit,
// pointing from the surface toward the viewer): the sample's frame (common/frame.h) applied.
glm::vec3 localViewDirection(const SurfaceLayout& layout, int i, glm::vec3 omega);
// Local view direction of sample i for a viewer at the object-space point `eye`.
glm::vec3 localViewFromEye(const SurfaceLayout& layout, int i, glm::vec3 eye);

// D_mu at sample i for the local view direction wLocal: sum over stored coefficients through
// order `order` (-1: all stored) of weight x y_k(wLocal); for a grid-basis bake, the bilinear
// interpolation of the traced grid (DirectionGrid::interpolate; `order` is ignored). Returns (exit x, y, z, length), the
// exit direction in object space and NOT normalized (the runtime normalizes after filtering).
glm::vec4 decompressSample(const BakeData& bake, int i, glm::vec3 wLocal, int order = -1);

// The bake's predicted angular error (radians, >= 0) of sample i's exit at the local view
// direction wLocal: its error model (BakeData::errors) evaluated there, exp(.) - kErrorOffset,
// clamped at 0. -1 when
// the bake has no error model (files before version 3, or baked with --error-order -1).
float predictedError(const BakeData& bake, int i, glm::vec3 wLocal);

// D at sample i as the runtime's texture-space passes leave it for interpolation (the CPU twin of
// decompression plus shaders/error_fold.frag): decompressSample, and where the bake has an error
// model, the exit vector's length set to resultantOfSigma(predictedError), the vMF lobe the
// shading reads back.
glm::vec4 foldedSample(const BakeData& bake, int i, glm::vec3 wLocal);

// Where a point lies in the rho interpolation: triangle t, barycentric (u, v) for corners 1, 2.
// Returns the value the runtime's bilinear lookup in rho yields there (with interpolation
// correction): bilinear over the grid cell, the cell's missing corner past the hypotenuse being
// v10 + v01 - v00. `values` gives D per mu sample (4 floats each).
glm::vec4 interpolateRho(const SurfaceLayout& layout, const glm::vec4* values, int t, float u,
                         float v);

// The isolated pipeline after decompression (paper §5.2, Figure 6) on the CPU, as the runtime
// runs it on the GPU (runtime/src/chart_pipeline.cpp) for chart layouts:
//   D+ : D in the covered texels, expanded `dilation` rings into the gutters, ring k taking the
//        mean of its 8-neighbours of rings below k (the paper's dynamic gutters);
//   seam-aware: gutter texels of rings 1..dilation that have a seam source take the mix of the
//        samples across the cut instead (beyond the paper, docs/runtime.md);
//   smoothing: optional 3 x 3 binomial filter over the filled texels, normalized.
struct ChartMapOptions {
    int dilation = 2;
    bool seamAware = true;
    bool smoothing = false;
};
// Per atlas texel: 0 covered, k = 1..width the gutter ring (8-neighbour steps from the nearest
// covered texel), kNoRing beyond.
constexpr uint8_t kNoRing = 255;
std::vector<uint8_t> gutterRings(const SurfaceLayout& layout, int width);
// The refraction map of a chart layout: muWidth x muHeight texels, row-major, 0 where unfilled.
// `values` gives D per sample.
std::vector<glm::vec4> chartRefractionMap(const SurfaceLayout& layout, const glm::vec4* values,
                                          const ChartMapOptions& options);
// GL_LINEAR with GL_CLAMP_TO_EDGE at uv in [0, 1]^2 (texel centres at (x + 0.5) / width).
glm::vec4 sampleBilinear(const std::vector<glm::vec4>& image, int width, int height, glm::vec2 uv);

// The smooth seams of a chart layout: every edge cut between two charts (or inside one) where
// the shading normal is continuous, as its two sides in the atlas, a0 -> a1 and b0 -> b1 (uv),
// both running from the surface point p0 to p1. Creases (sharp edges, whose sides differ by
// design) and the mesh's own border are left out.
struct SeamEdge {
    glm::vec2 a0, a1, b0, b1;
    glm::vec3 p0, p1;
};
std::vector<SeamEdge> smoothSeams(const SurfaceLayout& layout);
// The discontinuity of a refraction map across the smooth seams: at `steps` points inside every
// seam edge, the angle in degrees between the directions (xyz) the map gives there on its two
// sides, looked up as the shading pass does (bilinear).
std::vector<double> seamJumps(const SurfaceLayout& layout, const std::vector<glm::vec4>& map,
                              int steps = 8);

}  // namespace shrefract
