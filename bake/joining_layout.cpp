#include "bake/joining_layout.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <unordered_map>
#include <utility>

#include "common/error.h"
#include "common/limits.h"

namespace shrefract {
namespace {

uint64_t edgeKey(uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    return (uint64_t(a) << 32) | b;
}

// Counts the vertices and edges that triangles actually reference, over all parts.
struct Topology {
    size_t vertices = 0, edges = 0, triangles = 0;
};
Topology topology(const Scene& scene) {
    Topology tp;
    for (const Part& p : scene.parts) {
        std::vector<char> used(p.mesh.positions.size(), 0);
        std::set<uint64_t> edges;
        for (const glm::uvec3& t : p.mesh.triangles) {
            for (int k = 0; k < 3; ++k) {
                used[t[k]] = 1;
                edges.insert(edgeKey(t[k], t[(k + 1) % 3]));
            }
        }
        tp.vertices += std::count(used.begin(), used.end(), 1);
        tp.edges += edges.size();
        tp.triangles += p.mesh.triangles.size();
    }
    return tp;
}

}  // namespace

size_t joiningSampleCount(const Scene& scene, int rate) {
    Topology tp = topology(scene);
    size_t r = static_cast<size_t>(rate);
    return tp.vertices + tp.edges * (r - 1) + tp.triangles * (r - 1) * (r >= 2 ? r - 2 : 0) / 2;
}

int rateForSampleCount(const Scene& scene, size_t target) {
    Topology tp = topology(scene);
    for (int r = 1; r < limits::kMaxRate; ++r) {
        size_t rr = r;
        size_t n = tp.vertices + tp.edges * (rr - 1) + tp.triangles * (rr - 1) * (rr >= 2 ? rr - 2 : 0) / 2;
        if (n >= target) return r;
    }
    return limits::kMaxRate;
}

SurfaceLayout buildJoiningLayout(const Scene& scene, int rate) {
    SHREFRACT_CHECK(rate >= 1);
    const int r = rate;
    SurfaceLayout L;
    L.rate = r;
    // Two triangles per block, the second rotated 180 degrees. In block coordinates the first
    // one's samples lie on diagonals x + y <= r and its corrections on r + 1; the partner's
    // corrections on w + h - r - 3 and its samples from w + h - r - 2 up. w + h = 2r + 5 makes
    // those r + 2 and r + 3: no texel is shared. Width r + 1 is the least that holds a row of
    // r + 1 samples, so the block is (r + 1) x (r + 4).
    L.blockWidth = r + 1;
    L.blockHeight = r + 4;

    size_t triangles = 0;
    for (const Part& p : scene.parts) triangles += p.mesh.triangles.size();
    L.triangleCount = static_cast<int>(triangles);
    const size_t blocks = (triangles + 1) / 2;
    double side = std::sqrt(double(blocks) * L.blockWidth * L.blockHeight);
    L.blocksPerRow = std::max(1, static_cast<int>(std::ceil(side / L.blockWidth)));
    L.rhoWidth = L.blocksPerRow * L.blockWidth;
    L.rhoHeight = static_cast<int>((blocks + L.blocksPerRow - 1) / L.blocksPerRow) * L.blockHeight;
    L.rho.assign(size_t(L.rhoWidth) * L.rhoHeight, RhoTexel{});

    // Unique sample ids are given in order of first use while walking the triangles, so samples
    // of one triangle sit close together in mu.
    std::vector<std::pair<uint32_t, uint32_t>> gridEdges;  // neighbour pairs (a < b)
    size_t tGlobal = 0;
    for (size_t partIndex = 0; partIndex < scene.parts.size(); ++partIndex) {
        const Mesh& m = scene.parts[partIndex].mesh;
        std::vector<uint32_t> vertexId(m.positions.size(), UINT32_MAX);
        std::unordered_map<uint64_t, uint32_t> edgeBase;  // first id of r-1 samples from min vertex
        auto newSample = [&](glm::vec3 p, glm::vec3 n) {
            L.position.push_back(p);
            float len = glm::length(n);
            L.normal.push_back(len > 0 ? n / len : glm::vec3(0, 0, 1));
            L.part.push_back(static_cast<uint32_t>(partIndex));
            return static_cast<uint32_t>(L.position.size() - 1);
        };
        for (size_t tl = 0; tl < m.triangles.size(); ++tl, ++tGlobal) {
            const glm::uvec3 tri = m.triangles[tl];
            const glm::vec3 P[3] = {m.positions[tri[0]], m.positions[tri[1]], m.positions[tri[2]]};
            const glm::vec3 N[3] = {m.normals[tri[0]], m.normals[tri[1]], m.normals[tri[2]]};
            // Grid sample (i, j) lies at barycentrics (1 - i/r - j/r, i/r, j/r); its shading
            // normal is the interpolated vertex normal, as the tracer computes it.
            auto at = [&](int i, int j, glm::vec3* p, glm::vec3* n) {
                float u = float(i) / r, v = float(j) / r, w = 1.0f - u - v;
                *p = w * P[0] + u * P[1] + v * P[2];
                *n = w * N[0] + u * N[1] + v * N[2];
            };
            // Sample k in 1..r-1 along the edge from corner a to corner b, shared by both
            // triangles of the edge: counted from the edge's lower vertex index.
            auto edgeSample = [&](int ca, int cb, int k) {
                uint32_t va = tri[ca], vb = tri[cb];
                uint64_t key = edgeKey(va, vb);
                auto it = edgeBase.find(key);
                if (it == edgeBase.end()) {
                    uint32_t lo = std::min(va, vb), hi = std::max(va, vb);
                    uint32_t base = static_cast<uint32_t>(L.position.size());
                    for (int s = 1; s < r; ++s) {
                        float f = float(s) / r;
                        glm::vec3 plo = m.positions[lo], phi = m.positions[hi];
                        newSample(plo + f * (phi - plo), (1 - f) * m.normals[lo] + f * m.normals[hi]);
                    }
                    it = edgeBase.emplace(key, base).first;
                }
                int fromLo = (va < vb) ? k : r - k;
                return it->second + static_cast<uint32_t>(fromLo - 1);
            };
            auto id = [&](int i, int j) -> uint32_t {
                int corner = (i == 0 && j == 0) ? 0 : (i == r && j == 0) ? 1 : (i == 0 && j == r) ? 2 : -1;
                if (corner >= 0) {
                    uint32_t& vid = vertexId[tri[corner]];
                    if (vid == UINT32_MAX) vid = newSample(m.positions[tri[corner]], m.normals[tri[corner]]);
                    return vid;
                }
                if (j == 0) return edgeSample(0, 1, i);// corner 0 -> 1
                if (i == 0) return edgeSample(0, 2, j);// corner 0 -> 2
                if (i + j == r) return edgeSample(1, 2, j);// corner 1 -> 2
                glm::vec3 p, n;
                at(i, j, &p, &n);
                return newSample(p, n);
            };
            std::vector<uint32_t> ids((r + 1) * (r + 1), UINT32_MAX);
            const int t = static_cast<int>(tGlobal);
            for (int j = 0; j <= r; ++j) {
                for (int i = 0; i + j <= r; ++i) {
                    uint32_t s = id(i, j);
                    ids[j * (r + 1) + i] = s;
                    glm::ivec2 x = L.rhoTexel(t, i, j);
                    RhoTexel& tx = L.rho[size_t(x.y) * L.rhoWidth + x.x];
                    SHREFRACT_CHECK_EQ(tx.kind, uint32_t(RhoTexel::Empty));
                    tx = RhoTexel{RhoTexel::Sample, s, 0, 0};
                }
            }
            // Correction texels just outside the hypotenuse: v11 = v10 + v01 - v00.
            for (int i = 1; i <= r; ++i) {
                int j = r + 1 - i;
                uint32_t v10 = ids[(j - 1) * (r + 1) + i], v01 = ids[j * (r + 1) + i - 1];
                uint32_t v00 = ids[(j - 1) * (r + 1) + i - 1];
                glm::ivec2 x = L.rhoTexel(t, i, j);
                RhoTexel& tx = L.rho[size_t(x.y) * L.rhoWidth + x.x];
                SHREFRACT_CHECK_EQ(tx.kind, uint32_t(RhoTexel::Empty));
                tx = RhoTexel{RhoTexel::Correction, v10, v01, v00};
            }
            // Grid neighbours for smoothing: the three edges of every upright grid triangle
            // (i, j), (i+1, j), (i, j+1) cover every edge of the grid.
            auto link = [&](uint32_t a, uint32_t b) {
                gridEdges.emplace_back(std::min(a, b), std::max(a, b));
            };
            for (int j = 0; j < r; ++j) {
                for (int i = 0; i + j < r; ++i) {
                    uint32_t a = ids[j * (r + 1) + i], b = ids[j * (r + 1) + i + 1];
                    uint32_t c = ids[(j + 1) * (r + 1) + i];
                    link(a, b);
                    link(a, c);
                    link(b, c);
                }
            }
        }
    }
    const size_t n = L.position.size();
    L.muWidth = std::max(1, static_cast<int>(std::ceil(std::sqrt(double(n)))));
    L.muHeight = static_cast<int>((n + L.muWidth - 1) / L.muWidth);

    // Neighbour lists with Gaussian weights over distance (sigma = mean neighbour distance),
    // the sample itself first with weight exp(0) = 1, then normalized to sum to 1.
    std::sort(gridEdges.begin(), gridEdges.end());
    gridEdges.erase(std::unique(gridEdges.begin(), gridEdges.end()), gridEdges.end());
    std::vector<std::vector<uint32_t>> adj(n);
    double meanDist = 0;
    for (auto [a, b] : gridEdges) {
        if (a == b) continue;
        adj[a].push_back(b);
        adj[b].push_back(a);
        meanDist += glm::length(L.position[a] - L.position[b]);
    }
    meanDist = gridEdges.empty() ? 1.0 : meanDist / gridEdges.size();
    const double inv2s2 = 1.0 / (2.0 * meanDist * meanDist + 1e-30);
    L.neighbourOffset.resize(n);
    L.neighbourCount.resize(n);
    for (size_t i = 0; i < n; ++i) {
        L.neighbourOffset[i] = static_cast<uint32_t>(L.neighbourIndex.size());
        L.neighbourCount[i] = static_cast<uint32_t>(adj[i].size() + 1);
        std::vector<double> w{1.0};
        for (uint32_t b : adj[i]) {
            double d = glm::length(L.position[i] - L.position[b]);
            w.push_back(std::exp(-d * d * inv2s2));
        }
        double sum = std::accumulate(w.begin(), w.end(), 0.0);
        L.neighbourIndex.push_back(static_cast<uint32_t>(i));
        L.neighbourWeight.push_back(float(w[0] / sum));
        for (size_t k = 0; k < adj[i].size(); ++k) {
            L.neighbourIndex.push_back(adj[i][k]);
            L.neighbourWeight.push_back(float(w[k + 1] / sum));
        }
    }
    return L;
}

double rhoOverhead(const SurfaceLayout& layout) {
    return double(layout.rho.size()) / double(std::max(1, layout.sampleCount()));
}

}  // namespace shrefract
