// Chart layouts (bake/chart_layout.h, paper §5.2): buildChartLayout runs the stages of
// bake/chart_internal.h in order; the last ones are here: the samples at the texel centres the
// charts cover, the unfolded mesh the runtime draws, and the layout's statistics.
#include <map>
#include <tuple>

#include "bake/chart_internal.h"
#include "common/error.h"

namespace shrefract {
namespace charts {
namespace {

SurfaceLayout emptyAtlas(LayoutKind kind, int W, int H) {
    SurfaceLayout L;
    L.kind = kind;
    L.rate = 0;
    L.muWidth = L.rhoWidth = W;
    L.muHeight = L.rhoHeight = H;
    return L;
}

// Rasterize: the first triangle to cover a texel centre owns it. Its samples, in texel order, go
// to L (position, normal, part, rho, atlas.sampleTexel, empty neighbour lists); throws InputError
// when the charts cover no texel centre.
AtlasRaster sampleCoveredTexels(const Surface& S, const Scene& scene, const OutlineEdges& open,
                                SurfaceLayout& L) {
    const int W = L.muWidth, H = L.muHeight;
    const size_t texels = size_t(W) * H;
    struct Cover {
        uint32_t tri = UINT32_MAX;
        double b[3];
    };
    std::vector<Cover> cover(texels);
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        forEachCoveredTexel(S.tris[t].uv, open[t], W, H, [&](int x, int y, const double* b) {
            Cover& c = cover[size_t(y) * W + x];
            if (c.tri != UINT32_MAX) return;
            c.tri = t;
            std::copy(b, b + 3, c.b);
        });
    // Samples in texel order.
    L.rho.assign(texels, RhoTexel{});
    AtlasRaster raster{W, H, std::vector<int>(texels, -1)};
    std::vector<int>& chartOfTexel = raster.chartOfTexel;
    for (size_t x = 0; x < texels; ++x) {
        const Cover& c = cover[x];
        if (c.tri == UINT32_MAX) continue;
        glm::dvec3 p(0.0), n(0.0);
        for (int k = 0; k < 3; ++k) {
            p += c.b[k] * S.P(scene, c.tri, k);
            n += c.b[k] * S.N(scene, c.tri, k);
        }
        const uint32_t i = uint32_t(L.position.size());
        L.position.push_back(glm::vec3(p));
        L.normal.push_back(glm::length(n) > 0 ? glm::vec3(glm::normalize(n)) : glm::vec3(0, 0, 1));
        L.part.push_back(S.tris[c.tri].part);
        L.atlas.sampleTexel.push_back(uint32_t(x));
        L.rho[x] = RhoTexel{RhoTexel::Sample, i, 0, 0};
        chartOfTexel[x] = S.tris[c.tri].chart;
    }
    const size_t N = L.position.size();
    if (N == 0) throw InputError("the charts cover no texel centre: the atlas is too small");
    L.neighbourOffset.assign(N, 0);
    L.neighbourCount.assign(N, 0);
    return raster;
}

// The unfolded mesh: one vertex per (original vertex, chart, atlas position).
void buildUnfoldedMesh(const Surface& S, const Scene& scene, int G, int charts, SurfaceLayout& L) {
    const int W = L.muWidth, H = L.muHeight;
    ChartAtlas& A = L.atlas;
    A.gutter = G;
    A.chartCount = charts;
    std::map<std::tuple<uint32_t, uint32_t, int, double, double>, uint32_t> vertexId;
    for (uint32_t t = 0; t < S.tris.size(); ++t) {
        const Surface::Tri& tr = S.tris[t];
        glm::uvec3 idx;
        for (int k = 0; k < 3; ++k) {
            auto key = std::make_tuple(tr.part, tr.original[k], tr.chart, tr.uv[k].x, tr.uv[k].y);
            auto [it, added] = vertexId.emplace(key, uint32_t(A.vertexPosition.size()));
            if (added) {
                A.vertexPosition.push_back(glm::vec3(S.P(scene, t, k)));
                A.vertexNormal.push_back(glm::vec3(glm::normalize(S.N(scene, t, k))));
                A.vertexUV.push_back(glm::vec2(glm::clamp(tr.uv[k] / glm::dvec2(W, H), 0.0, 1.0)));
                A.vertexChart.push_back(uint32_t(tr.chart));
            }
            idx[k] = it->second;
        }
        A.triangles.push_back(idx);
    }
    L.triangleCount = int(A.triangles.size());
}

// Cut edges: smooth seams, creases, borders.
void countCutEdges(const Surface& S, const Scene& scene, const OutlineEdges& open, ChartStats& st) {
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            if (!open[t][k]) continue;
            uint32_t u;
            int uk;
            if (!S.twin(t, k, &u, &uk)) ++st.borderEdges;
            else if (S.smoothAcross(scene, t, k, u, uk)) ++st.seamEdges;
            else ++st.creaseEdges;
        }
    st.seamEdges /= 2;
    st.creaseEdges /= 2;
}

// Density spread and conformal distortion over the atlas; a uv layout warns when its density
// spreads more than 4x.
void measureDistortion(const Surface& S, const Scene& scene, LayoutKind kind, ChartStats& st) {
    std::vector<std::pair<double, double>> density;  // (texels per object unit, object area)
    double totalArea = 0;
    for (uint32_t t = 0; t < S.tris.size(); ++t) {
        const double a3 = S.area3(t);
        const double a2 = std::abs(signedArea(S.tris[t].uv[0], S.tris[t].uv[1], S.tris[t].uv[2]));
        if (!(a3 > 0)) continue;
        density.push_back({std::sqrt(a2 / a3), a3});
        totalArea += a3;
        // sigma1 / sigma2 of the map from the triangle's plane to the atlas.
        const glm::dvec3 p0 = S.P(scene, t, 0), p1 = S.P(scene, t, 1), p2 = S.P(scene, t, 2);
        const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
        const glm::dvec3 x = glm::normalize(e1), yv = glm::normalize(e2 - glm::dot(e2, x) * x);
        const glm::dmat2 P(glm::dot(e1, x), glm::dot(e1, yv), glm::dot(e2, x), glm::dot(e2, yv));
        const glm::dmat2 U(S.tris[t].uv[1] - S.tris[t].uv[0], S.tris[t].uv[2] - S.tris[t].uv[0]);
        if (std::abs(glm::determinant(P)) < 1e-300) continue;
        const glm::dmat2 J = U * glm::inverse(P);
        const double a = J[0][0], b = J[1][0], c = J[0][1], d = J[1][1];
        const double s1 = std::hypot(a + d, c - b) / 2, s2 = std::hypot(a - d, b + c) / 2;
        const double big = s1 + s2, small = std::abs(s1 - s2);
        if (small > 0) st.maxConformalDistortion = std::max(st.maxConformalDistortion, big / small);
    }
    std::sort(density.begin(), density.end());
    auto percentile = [&](double q) {
        double acc = 0;
        for (const auto& [d, a] : density) {
            acc += a;
            if (acc >= q * totalArea) return d;
        }
        return density.empty() ? 1.0 : density.back().first;
    };
    if (!density.empty()) st.densitySpread = percentile(0.99) / std::max(percentile(0.01), 1e-300);
    if (kind == LayoutKind::Uv && st.densitySpread > 4.0)
        st.warnings.push_back(str(scene.parts[0].meshPath, ": texel density varies ",
                                  std::round(st.densitySpread * 10) / 10,
                                  "x over the UV atlas (1st to 99th percentile, by area): samples are "
                                  "spread unevenly over the surface"));
}

}  // namespace
}  // namespace charts

SurfaceLayout buildChartLayout(const Scene& scene, const ChartOptions& opt, ChartStats* stats) {
    using namespace charts;
    SHREFRACT_CHECK(opt.kind != LayoutKind::Joining);
    ChartStats local;
    ChartStats& st = stats ? *stats : local;
    st = ChartStats();
    const int G = std::max(0, opt.gutter);
    Surface S = gatherSurface(scene);
    if (S.tris.empty()) throw InputError("no triangles to lay out");

    // The charts, and every triangle's uv in texel coordinates of a W x H atlas.
    glm::ivec2 size;
    if (opt.kind == LayoutKind::Uv) {
        takeMeshUVs(S, scene);
        size = scaleUVsToAtlas(S, opt);
    } else {
        unfoldIsolated(S, scene, opt, st);
        size = packCharts(S, opt, G, st);
    }
    const int W = size.x, H = size.y;
    if (W < 1 || H < 1 || int64_t(W) * H > (int64_t(1) << 28))
        throw InputError(str("atlas of ", W, " x ", H, " texels is out of range"));
    const auto open = outlineEdges(S);
    const int charts = chartCount(S);

    SurfaceLayout L = emptyAtlas(opt.kind, W, H);
    const AtlasRaster raster = sampleCoveredTexels(S, scene, open, L);
    buildUnfoldedMesh(S, scene, G, charts, L);
    countCutEdges(S, scene, open, st);
    addSeamSources(S, scene, open, raster, G, L, st);
    measureDistortion(S, scene, opt.kind, st);
    st.charts = charts;
    st.coveredTexels = L.position.size();
    st.atlasTexels = size_t(W) * H;
    return L;
}

}  // namespace shrefract
