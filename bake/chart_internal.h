// What the chart layout's files (bake/chart_layout.h) share and nothing else includes: the
// surface as the chart code sees it, the rasterization of a triangle onto texel centres, and the
// stages buildChartLayout runs in order. Plain types only: CGAL stays in bake/parameterize.cpp.
//   surface_topology.cpp  the welded surface, disks, chart splits, chart outlines
//   chart_unfold.cpp      isolated charts: grown, unfolded (through parameterize.h), checked
//   mesh_uv_charts.cpp    uv charts: the mesh's own texture coordinates, checked
//   atlas_packing.cpp     the atlas size and every chart's place in it
//   seam_sources.cpp      gutter texels and their seam-aware sources
//   chart_layout.cpp      buildChartLayout: the stages in order, samples, unfolded mesh, statistics
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "bake/chart_layout.h"
#include "common/bakefile.h"
#include "common/error.h"
#include "common/scene.h"

namespace shrefract::charts {

// A texel centre this close (in texels) to a chart's outline counts as outside: GL snaps vertices
// to 1/256 of a pixel (8 subpixel bits on Mesa), so a centre this far inside is rasterized by
// the decompression pass whichever way the snapping goes.
constexpr double kOutlineMargin = 1.0 / 64.0;

inline double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }
inline double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return 0.5 * cross2(b - a, c - a);
}

inline uint64_t edgeKey(uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    return (uint64_t(a) << 32) | b;
}

// ---------------------------------------------------------------------------------------------
// The surface as the chart code sees it: all parts' triangles, vertices welded by position within
// a part (global ids), the original vertex of every corner (its normal), the triangle's chart
// and its corner UVs.

struct Surface {
    struct Tri {
        uint32_t part = 0;
        glm::uvec3 original{0};  // vertex ids in the part's mesh
        glm::uvec3 welded{0};    // global welded ids
        int chart = -1;
        glm::dvec2 uv[3];        // chart coordinates, then atlas texel coordinates
    };
    std::vector<Tri> tris;
    std::vector<glm::dvec3> position;  // per welded vertex
    // Welded edge -> (triangle, corner k of the edge k -> k+1), for adjacency and twins.
    std::unordered_map<uint64_t, std::vector<std::pair<uint32_t, int>>> edges;

    glm::dvec3 P(const Scene& s, size_t t, int k) const {
        return glm::dvec3(s.parts[tris[t].part].mesh.positions[tris[t].original[k]]);
    }
    glm::dvec3 N(const Scene& s, size_t t, int k) const {
        return glm::dvec3(s.parts[tris[t].part].mesh.normals[tris[t].original[k]]);
    }
    double area3(size_t t) const {
        const glm::uvec3 w = tris[t].welded;
        return 0.5 * glm::length(glm::cross(position[w[1]] - position[w[0]],
                                            position[w[2]] - position[w[0]]));
    }
    glm::dvec3 faceNormal(size_t t) const {
        const glm::uvec3 w = tris[t].welded;
        const glm::dvec3 n =
            glm::cross(position[w[1]] - position[w[0]], position[w[2]] - position[w[0]]);
        const double l = glm::length(n);
        return l > 0 ? n / l : glm::dvec3(0, 0, 1);
    }
    // The other triangle across edge k of t, traversing it the other way (a manifold neighbour
    // of the same part), and the corner of that triangle where its copy of the edge starts.
    bool twin(size_t t, int k, uint32_t* other, int* otherK) const {
        const uint32_t a = tris[t].welded[k], b = tris[t].welded[(k + 1) % 3];
        auto it = edges.find(edgeKey(a, b));
        if (it == edges.end() || it->second.size() != 2) return false;
        for (auto [u, uk] : it->second) {
            if (u == t) continue;
            if (tris[u].welded[uk] != b || tris[u].welded[(uk + 1) % 3] != a) return false;
            *other = u;
            *otherK = uk;
            return true;
        }
        return false;
    }
    // The shading normal is continuous across edge k of t (same normals at both ends on both
    // sides): not a sharp edge of the mesh.
    bool smoothAcross(const Scene& s, size_t t, int k, uint32_t u, int uk) const {
        // t's corner k is u's corner uk + 1 and t's corner k + 1 is u's corner uk.
        return glm::dot(N(s, t, k), N(s, u, (uk + 1) % 3)) > 0.9999 &&
               glm::dot(N(s, t, (k + 1) % 3), N(s, u, uk)) > 0.9999;
    }
};

// Per triangle, whether its edge k -> k+1 lies on its chart's outline (surface_topology.cpp).
using OutlineEdges = std::vector<std::array<bool, 3>>;

// ---------------------------------------------------------------------------------------------
// surface_topology.cpp

Surface gatherSurface(const Scene& scene);
// A chart is a topological disk: connected, Euler characteristic V - E + F = 1 and one boundary
// loop in which every vertex has exactly two boundary edges.
bool isDisk(const Surface& S, const std::vector<uint32_t>& faces);
// Splits a chart in two: its faces nearer the second of two far-apart faces go to `newChart`.
void splitChart(Surface& S, const std::vector<uint32_t>& faces, int newChart);
std::vector<std::vector<uint32_t>> facesByChart(const Surface& S, int charts);
int chartCount(const Surface& S);
// Whether the edge k -> k+1 of each triangle is on its chart's outline (a cut or a border):
// no triangle of the same chart continues across it with the same UVs.
OutlineEdges outlineEdges(const Surface& S);

// ---------------------------------------------------------------------------------------------
// Rasterization, shared by the atlas sizing and the sampling.

// Texel centres covered by triangle t (texel coordinates in `uv`): inside, or on an edge inside
// the chart; at least kOutlineMargin inside the chart's outline.
template <class F>
void forEachCoveredTexel(const glm::dvec2 uv[3], const std::array<bool, 3>& open, int width,
                         int height, F f) {
    const double area = signedArea(uv[0], uv[1], uv[2]);
    if (area == 0.0) return;
    const glm::dvec2 lo = glm::min(uv[0], glm::min(uv[1], uv[2]));
    const glm::dvec2 hi = glm::max(uv[0], glm::max(uv[1], uv[2]));
    const int x0 = std::max(0, int(std::floor(lo.x - 0.5))), x1 = std::min(width - 1, int(std::ceil(hi.x - 0.5)));
    const int y0 = std::max(0, int(std::floor(lo.y - 0.5))), y1 = std::min(height - 1, int(std::ceil(hi.y - 0.5)));
    // Barycentric k is the area opposite corner k; its edge is (k+1, k+2) = edge index k+1.
    double minBary[3];
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2 e = uv[(k + 2) % 3] - uv[(k + 1) % 3];
        const double h = 2.0 * std::abs(area) / std::max(glm::length(e), 1e-300);
        minBary[k] = open[(k + 1) % 3] ? kOutlineMargin / h : 0.0;
    }
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const glm::dvec2 c(x + 0.5, y + 0.5);
            const double b[3] = {signedArea(c, uv[1], uv[2]) / area, signedArea(uv[0], c, uv[2]) / area,
                                 signedArea(uv[0], uv[1], c) / area};
            bool inside = true;
            for (int k = 0; k < 3; ++k) inside = inside && (open[(k + 1) % 3] ? b[k] > minBary[k] : b[k] >= 0.0);
            if (inside) f(x, y, b);
        }
}

// The atlas as rasterized: its size and, per texel, the chart whose triangle covers the texel's
// centre (-1: none).
struct AtlasRaster {
    int width = 0, height = 0;
    std::vector<int> chartOfTexel;
};

// ---------------------------------------------------------------------------------------------
// The stages of buildChartLayout, in order.

// mesh_uv_charts.cpp: the charts of a single mesh's own UVs; throws InputError for bad UVs.
void takeMeshUVs(Surface& S, const Scene& scene);
// chart_unfold.cpp: isolated charts grown, unfolded, checked and split until they pass.
void unfoldIsolated(Surface& S, const Scene& scene, const ChartOptions& opt, ChartStats& st);

// atlas_packing.cpp: the atlas size, with every triangle's uv moved to texel coordinates in it.
// Uv charts: the least square atlas whose covered texels reach opt.samples, or opt.texels.
glm::ivec2 scaleUVsToAtlas(Surface& S, const ChartOptions& opt);
// Isolated charts: rotated and shelf-packed with `gutter` texels around each, at the one density
// that reaches opt.samples or fills opt.texels (st.texelsPerObjectUnit).
glm::ivec2 packCharts(Surface& S, const ChartOptions& opt, int gutter, ChartStats& st);

// seam_sources.cpp: the gutter texels within `gutter` of a chart, and for each that continues a
// smooth cut, the covered texels across the cut it is filled from (layout.atlas.seam).
void addSeamSources(const Surface& S, const Scene& scene, const OutlineEdges& open,
                    const AtlasRaster& raster, int gutter, SurfaceLayout& layout, ChartStats& st);

}  // namespace shrefract::charts
