// Isolated charts (paper §5.2, docs/bake.md "Chart layouts"): region growing in a normal cone,
// then CGAL (bake/parameterize.h), then the checks; a chart that fails them is split and unfolded
// again. Also the overlap test that the unfoldings and the mesh's own UVs are checked with.
#include <numeric>
#include <queue>
#include <stdexcept>

#include "bake/chart_internal.h"

namespace shrefract::charts {
namespace {

void growCharts(Surface& S, const Scene& scene, double coneDegrees) {
    const double cosCone = std::cos(coneDegrees * M_PI / 180.0);
    std::vector<glm::dvec3> normal(S.tris.size());
    for (size_t t = 0; t < S.tris.size(); ++t) normal[t] = S.faceNormal(t);
    int next = 0;
    for (uint32_t seed = 0; seed < S.tris.size(); ++seed) {
        if (S.tris[seed].chart >= 0) continue;
        const int c = next++;
        const glm::dvec3 axis = normal[seed];
        // Most aligned faces first, so that charts grow round rather than in strands.
        using Item = std::pair<double, uint32_t>;
        std::priority_queue<Item> queue;
        queue.push({1.0, seed});
        while (!queue.empty()) {
            const uint32_t t = queue.top().second;
            queue.pop();
            if (S.tris[t].chart >= 0) continue;
            S.tris[t].chart = c;
            for (int k = 0; k < 3; ++k) {
                uint32_t u;
                int uk;
                // Never across a sharp edge of the mesh or a non-manifold or border edge.
                if (!S.twin(t, k, &u, &uk) || S.tris[u].chart >= 0 ||
                    S.tris[u].part != S.tris[t].part || !S.smoothAcross(scene, t, k, u, uk))
                    continue;
                const double c2 = glm::dot(normal[u], axis);
                if (c2 >= cosCone) queue.push({c2, u});
            }
        }
    }
}

// What is wrong with a chart's unfolding after normalizing its scale (UV area = object area):
// "" when its triangles all keep their orientation, do not overlap and have a texel density
// within [1/r, r] times the chart's. May mirror the chart to make it counter-clockwise.
std::string checkUnfolding(Surface& S, const std::vector<uint32_t>& faces, double maxRatio) {
    double a3 = 0, a2 = 0;
    int negative = 0;
    for (uint32_t t : faces) {
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(S.tris[t].uv[k].x) || !std::isfinite(S.tris[t].uv[k].y))
                return "not finite";
        const double a = signedArea(S.tris[t].uv[0], S.tris[t].uv[1], S.tris[t].uv[2]);
        a2 += a;
        a3 += S.area3(t);
        negative += a < 0;
    }
    if (negative * 2 > int(faces.size())) {  // LSCM may return the mirror image
        for (uint32_t t : faces)
            for (int k = 0; k < 3; ++k) S.tris[t].uv[k].x = -S.tris[t].uv[k].x;
        a2 = -a2;
    }
    if (!(a2 > 0) || !(a3 > 0)) return "collapsed";
    const double scale = std::sqrt(a3 / a2);
    for (uint32_t t : faces)
        for (int k = 0; k < 3; ++k) S.tris[t].uv[k] *= scale;
    std::vector<std::array<glm::dvec2, 3>> tris;
    for (uint32_t t : faces) {
        const Surface::Tri& tr = S.tris[t];
        const double a = signedArea(tr.uv[0], tr.uv[1], tr.uv[2]);
        const double area = S.area3(t);
        // Triangles of no area in 3D have no density to keep; orientation still counts.
        if (!(a > 1e-14 * a3)) return "flipped";
        if (area > 1e-12 * a3) {
            const double density = std::sqrt(a / area);
            if (density > maxRatio || density < 1.0 / maxRatio) return "stretched";
        }
        tris.push_back({tr.uv[0], tr.uv[1], tr.uv[2]});
    }
    if (findOverlap(tris).first >= 0) return "overlapping";
    return "";
}

}  // namespace

void unfoldIsolated(Surface& S, const Scene& scene, const ChartOptions& opt, ChartStats& st) {
    growCharts(S, scene, opt.coneDegrees);
    int charts = chartCount(S);
    // Charts that are not disks are split until they are (a single triangle is one).
    for (int round = 0; round < 64; ++round) {
        bool changed = false;
        const auto faces = facesByChart(S, charts);
        for (int c = 0; c < int(faces.size()); ++c) {
            if (faces[c].size() > 1 && !isDisk(S, faces[c])) {
                splitChart(S, faces[c], charts++);
                ++st.splits;
                changed = true;
            }
        }
        if (!changed) break;
    }
    // Unfold every chart; those that flip try ARAP, and what still fails is split and tried
    // again. Each part is its own CGAL mesh.
    std::vector<int> todo(static_cast<size_t>(charts));
    std::iota(todo.begin(), todo.end(), 0);
    std::vector<char> arap(size_t(charts), 0);
    for (int round = 0; !todo.empty(); ++round) {
        if (round > 200) throw std::runtime_error("chart unfolding did not converge");
        std::vector<int> next;
        for (uint32_t p = 0; p < scene.parts.size(); ++p) {
            // The part's triangles with welded vertices renumbered from 0.
            ChartedMesh cm;
            std::vector<uint32_t> tri;
            std::unordered_map<uint32_t, uint32_t> local;
            std::vector<char> wanted(size_t(charts), 0);
            for (int c : todo) wanted[size_t(c)] = 1;
            std::vector<int> asked;
            std::vector<char> seen(size_t(charts), 0);
            for (uint32_t t = 0; t < S.tris.size(); ++t) {
                if (S.tris[t].part != p || !wanted[size_t(S.tris[t].chart)]) continue;
                glm::uvec3 idx;
                for (int k = 0; k < 3; ++k) {
                    auto [it, added] = local.emplace(S.tris[t].welded[k], uint32_t(cm.positions.size()));
                    if (added) cm.positions.push_back(S.position[S.tris[t].welded[k]]);
                    idx[k] = it->second;
                }
                cm.triangles.push_back(idx);
                cm.chartOf.push_back(S.tris[t].chart);
                tri.push_back(t);
                if (!seen[size_t(S.tris[t].chart)]) {
                    seen[size_t(S.tris[t].chart)] = 1;
                    asked.push_back(S.tris[t].chart);
                }
            }
            if (asked.empty()) continue;
            std::vector<int> lscm, viaArap;
            for (int c : asked) (arap[size_t(c)] ? viaArap : lscm).push_back(c);
            for (int pass = 0; pass < 2; ++pass) {
                const std::vector<int>& which = pass == 0 ? lscm : viaArap;
                if (which.empty()) continue;
                const ChartMethod method =
                    pass == 0 ? opt.method : ChartMethod::Arap;
                const ChartUVs uv = parameterizeCharts(cm, which, method);
                st.seamMesh = st.seamMesh && uv.seamMesh;
                std::vector<char> inWhich(size_t(charts), 0);
                for (int c : which) inWhich[size_t(c)] = 1;
                for (size_t i = 0; i < tri.size(); ++i)
                    if (inWhich[size_t(cm.chartOf[i])])
                        for (int k = 0; k < 3; ++k) S.tris[tri[i]].uv[k] = uv.cornerUV[3 * i + k];
            }
            const auto faces = facesByChart(S, charts);
            for (int c : asked) {
                const std::string problem =
                    faces[c].size() == 1 ? std::string() : checkUnfolding(S, faces[c], opt.maxDensityRatio);
                if (faces[c].size() == 1) checkUnfolding(S, faces[c], 1e30);  // normalize only
                if (problem.empty()) {
                    st.arapCharts += arap[size_t(c)];
                    continue;
                }
                if (problem == "flipped" && !arap[size_t(c)] && opt.method == ChartMethod::Lscm) {
                    arap[size_t(c)] = 1;
                    next.push_back(c);
                    continue;
                }
                const int added = charts++;
                splitChart(S, faces[c], added);
                ++st.splits;
                arap.resize(size_t(charts), 0);
                arap[size_t(c)] = 0;
                next.push_back(c);
                next.push_back(added);
            }
        }
        todo = next;
    }
}

}  // namespace shrefract::charts

namespace shrefract {

std::pair<long, long> findOverlap(const std::vector<std::array<glm::dvec2, 3>>& tris) {
    if (tris.size() < 2) return {-1, -1};
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    double meanSize = 0;
    for (const auto& t : tris) {
        for (const auto& p : t) lo = glm::min(lo, p), hi = glm::max(hi, p);
        const glm::dvec2 a = glm::min(t[0], glm::min(t[1], t[2])), b = glm::max(t[0], glm::max(t[1], t[2]));
        meanSize += std::max(b.x - a.x, b.y - a.y);
    }
    meanSize /= double(tris.size());
    const double extent = std::max(hi.x - lo.x, hi.y - lo.y);
    const double eps = 1e-9 * std::max(extent, 1e-300);
    const double cell = std::max(meanSize * 2.0, extent / 4096.0);
    const int nx = std::max(1, int((hi.x - lo.x) / cell) + 1), ny = std::max(1, int((hi.y - lo.y) / cell) + 1);
    std::unordered_map<int64_t, std::vector<long>> grid;
    auto cellOf = [&](glm::dvec2 p) {
        return glm::ivec2(std::clamp(int((p.x - lo.x) / cell), 0, nx - 1), std::clamp(int((p.y - lo.y) / cell), 0, ny - 1));
    };
    // Separating axis: the interiors overlap unless some edge normal separates the two (touching
    // within eps counts as separated).
    auto overlap = [&](const std::array<glm::dvec2, 3>& a, const std::array<glm::dvec2, 3>& b) {
        for (const auto* tri : {&a, &b})
            for (int k = 0; k < 3; ++k) {
                const glm::dvec2 e = (*tri)[(k + 1) % 3] - (*tri)[k];
                const glm::dvec2 n(-e.y, e.x);
                const double len = glm::length(n);
                if (len == 0) continue;
                double a0 = INFINITY, a1 = -INFINITY, b0 = INFINITY, b1 = -INFINITY;
                for (const auto& p : a) a0 = std::min(a0, glm::dot(p, n) / len), a1 = std::max(a1, glm::dot(p, n) / len);
                for (const auto& p : b) b0 = std::min(b0, glm::dot(p, n) / len), b1 = std::max(b1, glm::dot(p, n) / len);
                if (a1 <= b0 + eps || b1 <= a0 + eps) return false;
            }
        return true;
    };
    for (long i = 0; i < long(tris.size()); ++i) {
        const auto& t = tris[size_t(i)];
        const glm::ivec2 c0 = cellOf(glm::min(t[0], glm::min(t[1], t[2])));
        const glm::ivec2 c1 = cellOf(glm::max(t[0], glm::max(t[1], t[2])));
        for (int y = c0.y; y <= c1.y; ++y)
            for (int x = c0.x; x <= c1.x; ++x) {
                std::vector<long>& here = grid[int64_t(y) * nx + x];
                for (long j : here)
                    if (overlap(t, tris[size_t(j)])) return {j, i};
                here.push_back(i);
            }
    }
    return {-1, -1};
}

}  // namespace shrefract
