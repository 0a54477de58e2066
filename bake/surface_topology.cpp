// The surface the chart code works on (bake/chart_internal.h): every part's triangles welded by
// position, and its topology: whether a set of faces is a disk, splitting a chart in two, which
// faces each chart holds and where a chart's outline runs.
#include <deque>
#include <map>
#include <tuple>

#include "bake/chart_internal.h"

namespace shrefract::charts {

Surface gatherSurface(const Scene& scene) {
    Surface S;
    for (uint32_t p = 0; p < scene.parts.size(); ++p) {
        const Mesh& m = scene.parts[p].mesh;
        std::map<std::tuple<float, float, float>, uint32_t> weld;
        std::vector<uint32_t> id(m.positions.size());
        for (size_t v = 0; v < m.positions.size(); ++v) {
            const glm::vec3 q = m.positions[v];
            auto [it, added] = weld.emplace(std::make_tuple(q.x, q.y, q.z), uint32_t(S.position.size()));
            if (added) S.position.push_back(glm::dvec3(q));
            id[v] = it->second;
        }
        for (size_t t = 0; t < m.triangles.size(); ++t) {
            Surface::Tri tri;
            tri.part = p;
            tri.original = m.triangles[t];
            for (int k = 0; k < 3; ++k) {
                tri.welded[k] = id[m.triangles[t][k]];
                if (!m.uvs.empty()) tri.uv[k] = glm::dvec2(m.uvs[3 * t + k]);
            }
            S.tris.push_back(tri);
        }
    }
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        for (int k = 0; k < 3; ++k)
            S.edges[edgeKey(S.tris[t].welded[k], S.tris[t].welded[(k + 1) % 3])].push_back({t, k});
    return S;
}

bool isDisk(const Surface& S, const std::vector<uint32_t>& faces) {
    if (faces.empty()) return false;
    std::unordered_map<uint64_t, int> edgeUse;
    std::unordered_map<uint32_t, int> vertexIndex;
    for (uint32_t t : faces)
        for (int k = 0; k < 3; ++k) {
            edgeUse[edgeKey(S.tris[t].welded[k], S.tris[t].welded[(k + 1) % 3])]++;
            vertexIndex.emplace(S.tris[t].welded[k], int(vertexIndex.size()));
        }
    const long chi = long(vertexIndex.size()) - long(edgeUse.size()) + long(faces.size());
    if (chi != 1) return false;
    std::unordered_map<uint32_t, std::vector<uint32_t>> boundary;
    size_t boundaryEdges = 0;
    for (auto [key, use] : edgeUse) {
        if (use > 2) return false;
        if (use != 1) continue;
        const uint32_t a = uint32_t(key >> 32), b = uint32_t(key & 0xffffffffu);
        boundary[a].push_back(b);
        boundary[b].push_back(a);
        ++boundaryEdges;
    }
    if (boundaryEdges == 0) return false;
    for (const auto& [v, n] : boundary)
        if (n.size() != 2) return false;
    // One loop: walk it.
    const uint32_t start = boundary.begin()->first;
    uint32_t prev = start, cur = boundary.begin()->second[0];
    size_t steps = 1;
    while (cur != start && steps <= boundaryEdges) {
        const std::vector<uint32_t>& n = boundary[cur];
        const uint32_t next = n[0] == prev ? n[1] : n[0];
        prev = cur;
        cur = next;
        ++steps;
    }
    if (steps != boundaryEdges) return false;
    // Connected through shared edges.
    std::unordered_map<uint32_t, char> in;
    for (uint32_t t : faces) in[t] = 0;
    std::vector<uint32_t> stack{faces[0]};
    in[faces[0]] = 1;
    size_t reached = 0;
    while (!stack.empty()) {
        const uint32_t t = stack.back();
        stack.pop_back();
        ++reached;
        for (int k = 0; k < 3; ++k) {
            auto it = S.edges.find(edgeKey(S.tris[t].welded[k], S.tris[t].welded[(k + 1) % 3]));
            for (auto [u, uk] : it->second) {
                auto f = in.find(u);
                if (f != in.end() && !f->second) {
                    f->second = 1;
                    stack.push_back(u);
                }
            }
        }
    }
    return reached == faces.size();
}

// Splits a chart in two: breadth-first distances over shared edges from two far-apart faces
// (the farthest from any face, and the farthest from that), each face to the nearer one.
void splitChart(Surface& S, const std::vector<uint32_t>& faces, int newChart) {
    std::unordered_map<uint32_t, int> local;
    for (size_t i = 0; i < faces.size(); ++i) local[faces[i]] = int(i);
    auto bfs = [&](std::vector<uint32_t> seeds, std::vector<int>& dist, std::vector<int>* label) {
        dist.assign(faces.size(), -1);
        std::deque<uint32_t> queue;
        for (size_t s = 0; s < seeds.size(); ++s) {
            dist[local[seeds[s]]] = 0;
            if (label) (*label)[local[seeds[s]]] = int(s);
            queue.push_back(seeds[s]);
        }
        uint32_t last = seeds[0];
        while (!queue.empty()) {
            const uint32_t t = queue.front();
            queue.pop_front();
            last = t;
            for (int k = 0; k < 3; ++k) {
                auto it = S.edges.find(edgeKey(S.tris[t].welded[k], S.tris[t].welded[(k + 1) % 3]));
                for (auto [u, uk] : it->second) {
                    auto f = local.find(u);
                    if (f == local.end() || dist[f->second] >= 0) continue;
                    dist[f->second] = dist[local[t]] + 1;
                    if (label) (*label)[f->second] = (*label)[local[t]];
                    queue.push_back(u);
                }
            }
        }
        return last;
    };
    std::vector<int> dist, label(faces.size(), 0);
    const uint32_t a = bfs({faces[0]}, dist, nullptr);
    const uint32_t b = bfs({a}, dist, nullptr);
    bfs({a, b}, dist, &label);
    for (size_t i = 0; i < faces.size(); ++i)
        if (label[i] == 1 || dist[i] < 0) S.tris[faces[i]].chart = newChart;
}

std::vector<std::vector<uint32_t>> facesByChart(const Surface& S, int charts) {
    std::vector<std::vector<uint32_t>> f(size_t(std::max(charts, 0)));
    for (uint32_t t = 0; t < S.tris.size(); ++t) f[size_t(S.tris[t].chart)].push_back(t);
    return f;
}

int chartCount(const Surface& S) {
    int n = 0;
    for (const auto& t : S.tris) n = std::max(n, t.chart + 1);
    return n;
}

OutlineEdges outlineEdges(const Surface& S) {
    OutlineEdges open(S.tris.size());
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t u;
            int uk;
            open[t][k] = !(S.twin(t, k, &u, &uk) && S.tris[u].chart == S.tris[t].chart &&
                           S.tris[u].uv[(uk + 1) % 3] == S.tris[t].uv[k] &&
                           S.tris[u].uv[uk] == S.tris[t].uv[(k + 1) % 3]);
        }
    return open;
}

}  // namespace shrefract::charts
