// Chart layouts (paper §5.2, "isolated surfaces"): the surface cut into charts, each unfolded
// into the plane, packed into one atlas with gutters; the samples O_d are the texel centres the
// charts cover, so mu = rho = the atlas. docs/bake.md "Chart layouts" describes the choices.
//   Isolated  charts by region growing inside a normal cone, never across a sharp edge of the
//             mesh; each unfolded by CGAL (LSCM, ARAP where LSCM flips), split in two where it
//             is not a disk, flips, overlaps itself or stretches beyond the density bound;
//             packed at one texel density.
//   Uv        the mesh's own texture coordinates (OBJ vt, PLY u v) as the charts, checked.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "bake/parameterize.h"
#include "common/bakefile.h"
#include "common/scene.h"

namespace shrefract {

struct ChartOptions {
    LayoutKind kind = LayoutKind::Isolated;
    size_t samples = 35000;     // target covered texels, when `texels` is 0 x 0
    glm::ivec2 texels{0, 0};    // the atlas size, set directly
    int gutter = 2;             // texels kept free around every chart (isolated packing); seam
                                // sources are made for gutter texels up to this far
    double coneDegrees = 60.0;  // isolated: largest angle between a face and its chart's seed
    // Isolated: a chart whose triangles' texel density leaves [1/r, r] times the chart's mean
    // is split (the distortion bound).
    double maxDensityRatio = 2.0;
    ChartMethod method = ChartMethod::Lscm;
};

struct ChartStats {
    int charts = 0;
    int splits = 0;          // chart splits: not a disk, flipped, overlapping or too stretched
    int arapCharts = 0;      // charts that LSCM flipped and ARAP unfolded
    bool seamMesh = true;    // every part was cut on one CGAL::Seam_mesh
    double texelsPerObjectUnit = 0;  // isolated: the uniform density
    // Per-triangle texel density (sqrt of texel area over object area), area-weighted: the
    // 99th over the 1st percentile. The uv layout warns above 4.
    double densitySpread = 1;
    double maxConformalDistortion = 1;  // largest sigma1 / sigma2 of a triangle's unfolding
    size_t coveredTexels = 0, atlasTexels = 0;
    size_t seamEdges = 0;     // edges cut between two charts (or inside one) on a smooth surface
    size_t creaseEdges = 0;   // cut edges where the shading normal jumps: no seam-aware filling
    size_t borderEdges = 0;   // edges of the mesh's own border
    size_t gutterTexels = 0, seamSources = 0;
    std::vector<std::string> warnings;
};

// Builds an Isolated or Uv layout of all parts of `scene` (uv: a single part). Throws InputError
// naming the mesh for bad UVs: none, outside [0, 1], zero area, flipped against their chart,
// overlapping; and for a --texels atlas too small to hold the charts.
SurfaceLayout buildChartLayout(const Scene& scene, const ChartOptions& options,
                               ChartStats* stats = nullptr);

// Two triangles (indices into `triangles`) whose interiors overlap in the plane, by more than a
// relative tolerance (shared edges and vertices do not count); {-1, -1} when none do.
std::pair<long, long> findOverlap(const std::vector<std::array<glm::dvec2, 3>>& triangles);

}  // namespace shrefract
