// Seam-aware gutter texels (docs/bake.md "Chart layouts"): the texels within the gutter of a
// chart, and for each that lies across a smooth cut, the covered texels it is filled from: it
// continues its chart's nearest outline edge across the cut, into the chart on the other side,
// where it takes the bilinear mix of the covered texels around that point.
#include <deque>

#include "bake/chart_internal.h"

namespace shrefract::charts {
namespace {

// Gutter texels within G of a chart (8-neighbour steps), owned by the chart they grew from.
struct Gutter {
    std::vector<int> ring;   // steps from the nearest covered texel: 0 covered, -1 beyond G
    std::vector<int> owner;  // the chart that texel grew from, -1 beyond G
};

Gutter growGutter(const AtlasRaster& raster, int G) {
    const int W = raster.width, H = raster.height;
    const size_t texels = size_t(W) * H;
    Gutter gutter{std::vector<int>(texels, -1), std::vector<int>(texels, -1)};
    std::vector<int>& ring = gutter.ring;
    std::vector<int>& owner = gutter.owner;
    const std::vector<int>& chartOfTexel = raster.chartOfTexel;
    std::deque<size_t> queue;
    for (size_t x = 0; x < texels; ++x)
        if (chartOfTexel[x] >= 0) ring[x] = 0, owner[x] = chartOfTexel[x], queue.push_back(x);
    while (!queue.empty()) {
        const size_t x = queue.front();
        queue.pop_front();
        if (ring[x] >= G) continue;
        const int tx = int(x % W), ty = int(x / W);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int nx = tx + dx, ny = ty + dy;
                if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                const size_t q = size_t(ny) * W + nx;
                if (ring[q] >= 0) continue;
                ring[q] = ring[x] + 1, owner[q] = owner[x];
                queue.push_back(q);
            }
    }
    return gutter;
}

struct OutlineEdge {
    uint32_t t;
    int k;
};

// Every outline edge, listed in each cell of a coarse grid over the atlas that its bounding box
// touches, for the nearest-edge search.
struct OutlineEdgeGrid {
    static constexpr double cellSize = 4.0;
    int gx = 0, gy = 0;
    std::unordered_map<int64_t, std::vector<OutlineEdge>> cells;

    OutlineEdgeGrid(const Surface& S, const OutlineEdges& open, int W, int H)
        : gx(W / int(cellSize) + 1), gy(H / int(cellSize) + 1) {
        for (uint32_t t = 0; t < S.tris.size(); ++t)
            for (int k = 0; k < 3; ++k) {
                if (!open[t][k]) continue;
                const glm::dvec2 a = S.tris[t].uv[k], b = S.tris[t].uv[(k + 1) % 3];
                const glm::dvec2 lo = glm::min(a, b), hi = glm::max(a, b);
                for (int cy = std::max(0, int(lo.y / cellSize)); cy <= std::min(gy - 1, int(hi.y / cellSize)); ++cy)
                    for (int cx = std::max(0, int(lo.x / cellSize)); cx <= std::min(gx - 1, int(hi.x / cellSize)); ++cx)
                        cells[int64_t(cy) * gx + cx].push_back({t, k});
            }
    }

    // The outline edge of `chart` nearest to p among the cells within `reach` cells of p's;
    // {UINT32_MAX, 0} when there is none.
    OutlineEdge nearest(const Surface& S, glm::dvec2 p, int chart, int reach) const {
        const int cx = int(p.x / cellSize), cy = int(p.y / cellSize);
        double best = INFINITY;
        OutlineEdge nearest{UINT32_MAX, 0};
        for (int yy = std::max(0, cy - reach); yy <= std::min(gy - 1, cy + reach); ++yy)
            for (int xx = std::max(0, cx - reach); xx <= std::min(gx - 1, cx + reach); ++xx) {
                auto it = cells.find(int64_t(yy) * gx + xx);
                if (it == cells.end()) continue;
                for (const OutlineEdge& e : it->second) {
                    if (S.tris[e.t].chart != chart) continue;
                    const glm::dvec2 a = S.tris[e.t].uv[e.k], b = S.tris[e.t].uv[(e.k + 1) % 3];
                    const double len2 = glm::dot(b - a, b - a);
                    const double s = len2 > 0 ? std::clamp(glm::dot(p - a, b - a) / len2, 0.0, 1.0) : 0.0;
                    const double d = glm::length(p - (a + s * (b - a)));
                    if (d < best) best = d, nearest = e;
                }
            }
        return nearest;
    }
};

// The point `s` across the outline edge `edge` (in the atlas) that continues p, and the chart it
// lies in; false where the edge is a border or a crease, degenerate, or p lies on its own
// chart's side of it (an uncovered texel inside its own chart: plain dilation).
bool acrossTheCut(const Surface& S, const Scene& scene, OutlineEdge edge, glm::dvec2 p,
                  glm::dvec2* across, int* chart) {
    uint32_t u;
    int uk;
    if (!S.twin(edge.t, edge.k, &u, &uk) || !S.smoothAcross(scene, edge.t, edge.k, u, uk))
        return false;
    // The similarity across the edge: p = a0 + alpha (a1 - a0) + beta |a1 - a0| outA, with outA
    // pointing away from t's third corner; s = b0 + alpha (b1 - b0) + beta |b1 - b0| inB, with
    // inB pointing to u's third corner. b0 is the same surface point as a0.
    const Surface::Tri& ta = S.tris[edge.t];
    const Surface::Tri& tb = S.tris[u];
    const glm::dvec2 a0 = ta.uv[edge.k], a1 = ta.uv[(edge.k + 1) % 3], a2 = ta.uv[(edge.k + 2) % 3];
    const glm::dvec2 b0 = tb.uv[(uk + 1) % 3], b1 = tb.uv[uk], b2 = tb.uv[(uk + 2) % 3];
    const glm::dvec2 ea = a1 - a0, eb = b1 - b0;
    const double la = glm::length(ea), lb = glm::length(eb);
    if (!(la > 0) || !(lb > 0)) return false;
    glm::dvec2 outA(-ea.y / la, ea.x / la);
    if (glm::dot(outA, a2 - a0) > 0) outA = -outA;
    glm::dvec2 inB(-eb.y / lb, eb.x / lb);
    if (glm::dot(inB, b2 - b0) < 0) inB = -inB;
    const double alpha = glm::dot(p - a0, ea) / (la * la);
    const double beta = glm::dot(p - a0, outA) / la;
    if (beta <= 0) return false;
    *across = b0 + alpha * eb + beta * lb * inB;
    *chart = tb.chart;
    return true;
}

// The samples and weights of `src` at s: bilinear weights of the texel centres around s, over
// the covered texels of `chart`; where those carry too little weight, the nearest covered texel
// of `chart` near s. False when there is none.
bool sourceAt(glm::dvec2 s, int chart, const AtlasRaster& raster, const std::vector<RhoTexel>& rho,
              SeamSource* src) {
    const int W = raster.width, H = raster.height;
    const std::vector<int>& chartOfTexel = raster.chartOfTexel;
    const double fx = s.x - 0.5, fy = s.y - 0.5;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    const double ax = fx - x0, ay = fy - y0;
    double total = 0;
    int used = 0;
    for (int j = 0; j < 4; ++j) {
        const int qx = x0 + (j & 1), qy = y0 + (j >> 1);
        const double w = ((j & 1) ? ax : 1 - ax) * ((j >> 1) ? ay : 1 - ay);
        if (qx < 0 || qy < 0 || qx >= W || qy >= H || w <= 0) continue;
        const size_t q = size_t(qy) * W + qx;
        if (chartOfTexel[q] != chart) continue;
        src->sample[used] = rho[q].a;
        src->weight[used] = float(w);
        total += w;
        ++used;
    }
    if (total < 0.05) {  // s sits off the covered texels: the nearest covered one near it
        used = 0;
        double bestD = 2.5;
        for (int qy = int(fy) - 2; qy <= int(fy) + 3; ++qy)
            for (int qx = int(fx) - 2; qx <= int(fx) + 3; ++qx) {
                if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
                const size_t q = size_t(qy) * W + qx;
                const double d = glm::length(glm::dvec2(qx + 0.5, qy + 0.5) - s);
                if (chartOfTexel[q] != chart || d >= bestD) continue;
                bestD = d;
                src->sample[0] = rho[q].a;
                used = 1;
            }
        if (used == 0) return false;
        src->weight[0] = 1.0f;
        for (int j = 1; j < 4; ++j) src->sample[j] = 0, src->weight[j] = 0.0f;
    } else {
        for (int j = 0; j < used; ++j) src->weight[j] = float(src->weight[j] / total);
    }
    return true;
}

}  // namespace

void addSeamSources(const Surface& S, const Scene& scene, const OutlineEdges& open,
                    const AtlasRaster& raster, int G, SurfaceLayout& L, ChartStats& st) {
    const int W = raster.width, H = raster.height;
    const size_t texels = size_t(W) * H;
    const Gutter gutter = growGutter(raster, G);
    const OutlineEdgeGrid grid(S, open, W, H);
    const int reach = int(std::ceil((G + 2) / OutlineEdgeGrid::cellSize));
    for (size_t x = 0; x < texels; ++x) {
        if (gutter.ring[x] <= 0) continue;
        ++st.gutterTexels;
        const glm::dvec2 p(double(x % W) + 0.5, double(x / W) + 0.5);
        const OutlineEdge nearest = grid.nearest(S, p, gutter.owner[x], reach);
        if (nearest.t == UINT32_MAX) continue;
        glm::dvec2 s;
        int chart;
        if (!acrossTheCut(S, scene, nearest, p, &s, &chart)) continue;
        SeamSource src;
        src.texel = uint32_t(x);
        if (!sourceAt(s, chart, raster, L.rho, &src)) continue;
        L.atlas.seam.push_back(src);
    }
    st.seamSources = L.atlas.seam.size();
}

}  // namespace shrefract::charts
