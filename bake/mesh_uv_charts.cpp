// Uv charts (docs/bake.md "Chart layouts"): the mesh's own texture coordinates (OBJ vt, PLY u v),
// joined into charts where both ends of an edge carry the same UVs on both sides, and checked:
// inside [0, 1], of some area, none flipped against its chart, none overlapping.
#include <functional>
#include <map>
#include <numeric>

#include "bake/chart_internal.h"
#include "common/error.h"

namespace shrefract::charts {

void takeMeshUVs(Surface& S, const Scene& scene) {
    const std::string& path = scene.parts[0].meshPath;
    if (scene.parts.size() != 1)
        throw InputError("--layout uv takes one mesh: the " + std::to_string(scene.parts.size()) +
                         " parts of a scene each have their own UV space");
    const Mesh& mesh = scene.parts[0].mesh;
    if (mesh.uvs.empty())
        throw inputError(path, "has no texture coordinates (OBJ vt, PLY u v): --layout uv needs them");
    // Charts: triangles joined by edges whose two ends have the same UVs on both sides.
    std::vector<uint32_t> parent(S.tris.size());
    std::iota(parent.begin(), parent.end(), 0u);
    std::function<uint32_t(uint32_t)> root = [&](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (uint32_t t = 0; t < S.tris.size(); ++t) {
        const Surface::Tri& tr = S.tris[t];
        for (int k = 0; k < 3; ++k) {
            const glm::dvec2 uv = tr.uv[k];
            if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1))
                throw inputError(path, str("texture coordinate (", uv.x, ", ", uv.y, ") of triangle ", t,
                                           " corner ", k, " lies outside [0, 1]"));
            uint32_t u;
            int uk;
            if (S.twin(t, k, &u, &uk) && S.tris[u].uv[(uk + 1) % 3] == tr.uv[k] &&
                S.tris[u].uv[uk] == tr.uv[(k + 1) % 3])
                parent[root(t)] = root(u);
        }
        const double a = signedArea(tr.uv[0], tr.uv[1], tr.uv[2]);
        if (!(std::abs(a) > 1e-14))
            throw inputError(path, str("triangle ", t, " has no area in UV space (corners (",
                                       tr.uv[0].x, ", ", tr.uv[0].y, "), (", tr.uv[1].x, ", ",
                                       tr.uv[1].y, "), (", tr.uv[2].x, ", ", tr.uv[2].y, "))"));
    }
    std::map<uint32_t, int> chartOfRoot;
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        S.tris[t].chart = chartOfRoot.emplace(root(t), int(chartOfRoot.size())).first->second;
    // Flipped: a triangle that runs the other way round from most of its chart (a whole chart
    // mirrored is fine: nothing here depends on the UV handedness).
    const int charts = int(chartOfRoot.size());
    std::vector<double> balance(size_t(charts), 0.0);
    for (const auto& tr : S.tris) balance[size_t(tr.chart)] += signedArea(tr.uv[0], tr.uv[1], tr.uv[2]) > 0 ? 1 : -1;
    size_t flipped = 0, first = 0;
    for (uint32_t t = 0; t < S.tris.size(); ++t) {
        const auto& tr = S.tris[t];
        const double a = signedArea(tr.uv[0], tr.uv[1], tr.uv[2]);
        if ((a > 0) != (balance[size_t(tr.chart)] > 0)) {
            if (flipped++ == 0) first = t;
        }
    }
    if (flipped > 0)
        throw inputError(path, str(flipped, " triangles are flipped in UV space (they run the other "
                                   "way round from the rest of their chart), the first is triangle ",
                                   first));
    std::vector<std::array<glm::dvec2, 3>> tris;
    for (const auto& tr : S.tris) tris.push_back({tr.uv[0], tr.uv[1], tr.uv[2]});
    const auto [a, b] = findOverlap(tris);
    if (a >= 0) {
        const glm::dvec2 c = (tris[a][0] + tris[a][1] + tris[a][2]) / 3.0;
        throw inputError(path, str("triangles ", a, " and ", b, " overlap in UV space (near (", c.x,
                                   ", ", c.y, ")): one texel cannot hold two surface points"));
    }
}

}  // namespace shrefract::charts
