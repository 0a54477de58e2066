// The CPU decompressor: the same math as the runtime's GLSL passes, for tests, evaluation and
// apps without GL.
#pragma once

#include <glm/glm.hpp>

#include "common/bakefile.h"

namespace shrefract {

// Local view direction of sample i for a viewer in direction `omega` (object space, unit,
// pointing from the surface toward the viewer): the sample's frame (common/frame.h) applied.
glm::vec3 localViewDirection(const SurfaceLayout& layout, int i, glm::vec3 omega);
// Local view direction of sample i for a viewer at the object-space point `eye`.
glm::vec3 localViewFromEye(const SurfaceLayout& layout, int i, glm::vec3 eye);

// D_mu at sample i for the local view direction wLocal: sum over stored coefficients through
// order `order` (-1: all stored) of weight x y_k(wLocal). Returns (exit x, y, z, length), the
// exit direction in object space and NOT normalized (the runtime normalizes after filtering).
glm::vec4 decompressSample(const BakeData& bake, int i, glm::vec3 wLocal, int order = -1);

// Where a point lies in the rho interpolation: triangle t, barycentric (u, v) for corners 1, 2.
// Returns the value the runtime's bilinear lookup in rho yields there (with interpolation
// correction): bilinear over the grid cell, the cell's missing corner past the hypotenuse being
// v10 + v01 - v00. `values` gives D per mu sample (4 floats each).
glm::vec4 interpolateRho(const SurfaceLayout& layout, const glm::vec4* values, int t, float u,
                         float v);

}  // namespace shrefract
