#include "bake/charts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <numeric>
#include <queue>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "common/error.h"

namespace shrefract {
namespace {

// A texel centre this close (in texels) to a chart's outline counts as outside: GL snaps vertices
// to 1/256 of a pixel (8 subpixel bits on Mesa), so a centre this far inside is rasterized by
// the decompression pass whichever way the snapping goes.
constexpr double kOutlineMargin = 1.0 / 64.0;

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }
double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return 0.5 * cross2(b - a, c - a);
}

template <class... T>
std::string str(const T&... parts) {
    std::ostringstream os;
    (os << ... << parts);
    return os.str();
}

uint64_t edgeKey(uint32_t a, uint32_t b) {
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

// ---------------------------------------------------------------------------------------------
// Topology of a set of triangles.

// A chart is a topological disk: connected, Euler characteristic V - E + F = 1 and one boundary
// loop in which every vertex has exactly two boundary edges.
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

// ---------------------------------------------------------------------------------------------
// Isolated charts: region growing in a normal cone, then CGAL, then the checks.

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

// ---------------------------------------------------------------------------------------------
// Uv charts: the mesh's own texture coordinates, checked.

void takeMeshUVs(Surface& S, const Scene& scene, ChartStats& st) {
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
    (void)st;
}

// ---------------------------------------------------------------------------------------------
// The atlas: placement, rasterization, samples.

struct ChartBox {
    glm::dvec2 lo, hi;  // in chart units after rotation
};

// Rotates each chart to its least-area bounding rectangle (an edge of its convex hull lies on the
// rectangle), lying wider than tall, and moves its corner to the origin.
std::vector<ChartBox> orientCharts(Surface& S, int charts) {
    const auto faces = facesByChart(S, charts);
    std::vector<ChartBox> boxes(static_cast<size_t>(charts));
    for (int c = 0; c < charts; ++c) {
        std::vector<glm::dvec2> pts;
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) pts.push_back(S.tris[t].uv[k]);
        std::sort(pts.begin(), pts.end(), [](auto a, auto b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
        pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
        std::vector<glm::dvec2> hull;  // monotone chain
        for (int pass = 0; pass < 2; ++pass) {
            const size_t base = hull.size();
            for (size_t i = 0; i < pts.size(); ++i) {
                const glm::dvec2 p = pass == 0 ? pts[i] : pts[pts.size() - 1 - i];
                while (hull.size() >= base + 2 &&
                       cross2(hull.back() - hull[hull.size() - 2], p - hull[hull.size() - 2]) <= 0)
                    hull.pop_back();
                hull.push_back(p);
            }
            hull.pop_back();
        }
        double bestArea = INFINITY;
        glm::dvec2 bestAxis(1, 0);
        for (size_t i = 0; i < hull.size(); ++i) {
            glm::dvec2 e = hull[(i + 1) % hull.size()] - hull[i];
            if (glm::length(e) <= 0) continue;
            e = glm::normalize(e);
            double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
            for (const auto& p : hull) {
                lo0 = std::min(lo0, glm::dot(p, e)), hi0 = std::max(hi0, glm::dot(p, e));
                const double q = cross2(e, p);
                lo1 = std::min(lo1, q), hi1 = std::max(hi1, q);
            }
            if ((hi0 - lo0) * (hi1 - lo1) < bestArea) {
                bestArea = (hi0 - lo0) * (hi1 - lo1);
                bestAxis = (hi0 - lo0) >= (hi1 - lo1) ? e : glm::dvec2(-e.y, e.x);
            }
        }
        // Rotation taking bestAxis to +x keeps the orientation (counter-clockwise stays so).
        ChartBox box{glm::dvec2(INFINITY), glm::dvec2(-INFINITY)};
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) {
                const glm::dvec2 p = S.tris[t].uv[k];
                const glm::dvec2 r(glm::dot(p, bestAxis), cross2(bestAxis, p));
                S.tris[t].uv[k] = r;
                box.lo = glm::min(box.lo, r), box.hi = glm::max(box.hi, r);
            }
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) S.tris[t].uv[k] -= box.lo;
        box.hi -= box.lo;
        box.lo = glm::dvec2(0.0);
        boxes[c] = box;
    }
    return boxes;
}

// Whether the edge k -> k+1 of each triangle is on its chart's outline (a cut or a border):
// no triangle of the same chart continues across it with the same UVs.
std::vector<std::array<bool, 3>> outlineEdges(const Surface& S) {
    std::vector<std::array<bool, 3>> open(S.tris.size());
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

// Covered texels of every chart at `scale` texels per chart unit, each at (gutter, gutter) of its
// own box: the count does not depend on where the packer puts the box (whole texels).
// Texel centres covered by the triangles `tris` placed by `place` in a width x height grid, each
// counted once (a centre on an edge inside a chart is covered by both of its triangles).
template <class Place>
size_t countCovered(const Surface& S, const std::vector<std::array<bool, 3>>& open,
                    const std::vector<uint32_t>& tris, Place place, int width, int height) {
    std::vector<char> covered(size_t(width) * height, 0);
    size_t n = 0;
    for (uint32_t t : tris) {
        glm::dvec2 uv[3];
        for (int k = 0; k < 3; ++k) uv[k] = place(S.tris[t].uv[k]);
        forEachCoveredTexel(uv, open[t], width, height, [&](int x, int y, const double*) {
            char& c = covered[size_t(y) * width + x];
            n += !c;
            c = 1;
        });
    }
    return n;
}

// Covered texels of every chart at `scale` texels per chart unit, each at (gutter, gutter) of its
// own box: the count does not depend on where the packer puts the box (whole texels).
size_t coveredAtScale(const Surface& S, const std::vector<std::array<bool, 3>>& open,
                      const std::vector<std::vector<uint32_t>>& faces,
                      const std::vector<ChartBox>& boxes, double scale, int gutter) {
    size_t n = 0;
    for (size_t c = 0; c < faces.size(); ++c) {
        const int w = int(std::ceil(boxes[c].hi.x * scale)) + 2 * gutter + 1;
        const int h = int(std::ceil(boxes[c].hi.y * scale)) + 2 * gutter + 1;
        n += countCovered(S, open, faces[c], [&](glm::dvec2 uv) { return uv * scale + double(gutter); }, w, h);
    }
    return n;
}

struct Packing {
    int width = 0, height = 0;
    std::vector<glm::ivec2> origin;  // per chart, of its box (the chart starts gutter further in)
};

// Shelf packing of the chart boxes at `scale`, rows at most `rowWidth` wide, tallest first.
Packing pack(const std::vector<ChartBox>& boxes, double scale, int gutter, int rowWidth) {
    const int charts = int(boxes.size());
    std::vector<glm::ivec2> size(static_cast<size_t>(charts));
    for (int c = 0; c < charts; ++c)
        size[c] = glm::ivec2(int(std::ceil(boxes[c].hi.x * scale)) + 2 * gutter,
                             int(std::ceil(boxes[c].hi.y * scale)) + 2 * gutter);
    std::vector<int> order(static_cast<size_t>(charts));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size[a].y > size[b].y; });
    Packing p;
    p.origin.assign(size_t(charts), glm::ivec2(0));
    int x = 0, y = 0, shelf = 0;
    for (int c : order) {
        if (x > 0 && x + size[c].x > rowWidth) {
            y += shelf;
            x = shelf = 0;
        }
        p.origin[c] = glm::ivec2(x, y);
        x += size[c].x;
        shelf = std::max(shelf, size[c].y);
        p.width = std::max(p.width, x);
    }
    p.height = y + shelf;
    return p;
}

Packing packSquare(const std::vector<ChartBox>& boxes, double scale, int gutter) {
    double area = 0, widest = 0;
    for (const auto& b : boxes) {
        const double w = std::ceil(b.hi.x * scale) + 2 * gutter, h = std::ceil(b.hi.y * scale) + 2 * gutter;
        area += w * h;
        widest = std::max(widest, w);
    }
    return pack(boxes, scale, gutter, int(std::max(widest, std::ceil(std::sqrt(area) * 1.05))));
}

}  // namespace

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

SurfaceLayout buildChartLayout(const Scene& scene, const ChartOptions& opt, ChartStats* stats) {
    SHREFRACT_CHECK(opt.kind != LayoutKind::Joining);
    ChartStats local;
    ChartStats& st = stats ? *stats : local;
    st = ChartStats();
    const int G = std::max(0, opt.gutter);
    Surface S = gatherSurface(scene);
    if (S.tris.empty()) throw InputError("no triangles to lay out");

    int W = 0, H = 0;
    if (opt.kind == LayoutKind::Uv) {
        takeMeshUVs(S, scene, st);
        const auto open = outlineEdges(S);
        std::vector<uint32_t> all(S.tris.size());
        std::iota(all.begin(), all.end(), 0u);
        auto covered = [&](int w, int h) {
            return countCovered(S, open, all, [&](glm::dvec2 uv) { return uv * glm::dvec2(w, h); }, w, h);
        };
        if (opt.texels.x > 0) {
            W = opt.texels.x, H = opt.texels.y;
        } else {  // the least square atlas whose covered texels reach the target
            int lo = 1, hi = 2;
            while (covered(hi, hi) < opt.samples && hi < 16384) hi *= 2;
            while (lo < hi) {
                const int mid = (lo + hi) / 2;
                if (covered(mid, mid) >= opt.samples) hi = mid;
                else lo = mid + 1;
            }
            W = H = hi;
        }
        for (auto& tr : S.tris)
            for (int k = 0; k < 3; ++k) tr.uv[k] *= glm::dvec2(W, H);
    } else {
        unfoldIsolated(S, scene, opt, st);
        const int charts = chartCount(S);
        const std::vector<ChartBox> boxes = orientCharts(S, charts);
        const auto open = outlineEdges(S);
        double area3 = 0;
        for (uint32_t t = 0; t < S.tris.size(); ++t) area3 += S.area3(t);
        double scale;
        Packing packing;
        if (opt.texels.x > 0) {  // the largest density whose packing fits the atlas
            double lo = 0, hi = std::sqrt(double(opt.texels.x) * opt.texels.y / area3);
            for (int i = 0; i < 60; ++i) {
                const double mid = 0.5 * (lo + hi);
                const Packing p = pack(boxes, mid, G, opt.texels.x);
                (p.width <= opt.texels.x && p.height <= opt.texels.y ? lo : hi) = mid;
            }
            scale = lo;
            packing = pack(boxes, scale, G, opt.texels.x);
            if (!(scale > 0) || packing.width > opt.texels.x || packing.height > opt.texels.y)
                throw InputError(str("--texels ", opt.texels.x, "x", opt.texels.y, " cannot hold the ",
                                     charts, " charts with gutters of ", G, " texels"));
            W = opt.texels.x, H = opt.texels.y;
        } else {  // the least density whose charts cover the target number of texels
            double lo = 0, hi = std::sqrt(double(opt.samples) / area3);
            const auto faces = facesByChart(S, charts);
            while (coveredAtScale(S, open, faces, boxes, hi, G) < opt.samples) hi *= 1.25;
            for (int i = 0; i < 50 && hi - lo > 1e-6 * hi; ++i) {
                const double mid = 0.5 * (lo + hi);
                (coveredAtScale(S, open, faces, boxes, mid, G) >= opt.samples ? hi : lo) = mid;
            }
            scale = hi;
            packing = packSquare(boxes, scale, G);
            W = packing.width, H = packing.height;
        }
        st.texelsPerObjectUnit = scale;
        for (auto& tr : S.tris)
            for (int k = 0; k < 3; ++k)
                tr.uv[k] = tr.uv[k] * scale + glm::dvec2(packing.origin[size_t(tr.chart)] + G);
    }
    if (W < 1 || H < 1 || int64_t(W) * H > (int64_t(1) << 28))
        throw InputError(str("atlas of ", W, " x ", H, " texels is out of range"));
    const auto open = outlineEdges(S);
    const int charts = chartCount(S);

    // Rasterize: the first triangle to cover a texel centre owns it.
    SurfaceLayout L;
    L.kind = opt.kind;
    L.rate = 0;
    L.muWidth = L.rhoWidth = W;
    L.muHeight = L.rhoHeight = H;
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
    std::vector<int> chartOfTexel(texels, -1);
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

    // The unfolded mesh: one vertex per (original vertex, chart, atlas position).
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

    // Cut edges: smooth seams, creases, borders.
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

    // Gutter texels within G of a chart (8-neighbour steps), owned by the chart they grew from.
    std::vector<int> ring(texels, -1), owner(texels, -1);
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
    // Seam-aware sources: each gutter texel continues its chart's nearest outline edge across the
    // cut, into the chart on the other side, where it takes the bilinear mix of the covered
    // texels around that point.
    struct OutlineEdge {
        uint32_t t;
        int k;
    };
    const double cellSize = 4.0;
    const int gx = W / int(cellSize) + 1, gy = H / int(cellSize) + 1;
    std::unordered_map<int64_t, std::vector<OutlineEdge>> edgeGrid;
    for (uint32_t t = 0; t < S.tris.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            if (!open[t][k]) continue;
            const glm::dvec2 a = S.tris[t].uv[k], b = S.tris[t].uv[(k + 1) % 3];
            const glm::dvec2 lo = glm::min(a, b), hi = glm::max(a, b);
            for (int cy = std::max(0, int(lo.y / cellSize)); cy <= std::min(gy - 1, int(hi.y / cellSize)); ++cy)
                for (int cx = std::max(0, int(lo.x / cellSize)); cx <= std::min(gx - 1, int(hi.x / cellSize)); ++cx)
                    edgeGrid[int64_t(cy) * gx + cx].push_back({t, k});
        }
    const int reach = int(std::ceil((G + 2) / cellSize));
    for (size_t x = 0; x < texels; ++x) {
        if (ring[x] <= 0) continue;
        ++st.gutterTexels;
        const glm::dvec2 p(double(x % W) + 0.5, double(x / W) + 0.5);
        const int cx = int(p.x / cellSize), cy = int(p.y / cellSize);
        double best = INFINITY;
        OutlineEdge nearest{UINT32_MAX, 0};
        for (int yy = std::max(0, cy - reach); yy <= std::min(gy - 1, cy + reach); ++yy)
            for (int xx = std::max(0, cx - reach); xx <= std::min(gx - 1, cx + reach); ++xx) {
                auto it = edgeGrid.find(int64_t(yy) * gx + xx);
                if (it == edgeGrid.end()) continue;
                for (const OutlineEdge& e : it->second) {
                    if (S.tris[e.t].chart != owner[x]) continue;
                    const glm::dvec2 a = S.tris[e.t].uv[e.k], b = S.tris[e.t].uv[(e.k + 1) % 3];
                    const double len2 = glm::dot(b - a, b - a);
                    const double s = len2 > 0 ? std::clamp(glm::dot(p - a, b - a) / len2, 0.0, 1.0) : 0.0;
                    const double d = glm::length(p - (a + s * (b - a)));
                    if (d < best) best = d, nearest = e;
                }
            }
        if (nearest.t == UINT32_MAX) continue;
        uint32_t u;
        int uk;
        if (!S.twin(nearest.t, nearest.k, &u, &uk) || !S.smoothAcross(scene, nearest.t, nearest.k, u, uk))
            continue;
        // The similarity across the edge: p = a0 + alpha (a1 - a0) + beta |a1 - a0| outA, with outA
        // pointing away from t's third corner; s = b0 + alpha (b1 - b0) + beta |b1 - b0| inB, with
        // inB pointing to u's third corner. b0 is the same surface point as a0.
        const Surface::Tri& ta = S.tris[nearest.t];
        const Surface::Tri& tb = S.tris[u];
        const glm::dvec2 a0 = ta.uv[nearest.k], a1 = ta.uv[(nearest.k + 1) % 3], a2 = ta.uv[(nearest.k + 2) % 3];
        const glm::dvec2 b0 = tb.uv[(uk + 1) % 3], b1 = tb.uv[uk], b2 = tb.uv[(uk + 2) % 3];
        const glm::dvec2 ea = a1 - a0, eb = b1 - b0;
        const double la = glm::length(ea), lb = glm::length(eb);
        if (!(la > 0) || !(lb > 0)) continue;
        glm::dvec2 outA(-ea.y / la, ea.x / la);
        if (glm::dot(outA, a2 - a0) > 0) outA = -outA;
        glm::dvec2 inB(-eb.y / lb, eb.x / lb);
        if (glm::dot(inB, b2 - b0) < 0) inB = -inB;
        const double alpha = glm::dot(p - a0, ea) / (la * la);
        const double beta = glm::dot(p - a0, outA) / la;
        if (beta <= 0) continue;  // an uncovered texel inside its own chart: plain dilation
        const glm::dvec2 s = b0 + alpha * eb + beta * lb * inB;
        // Bilinear weights of the texel centres around s, over the covered texels of u's chart.
        SeamSource src;
        src.texel = uint32_t(x);
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
            if (chartOfTexel[q] != tb.chart) continue;
            src.sample[used] = L.rho[q].a;
            src.weight[used] = float(w);
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
                    if (chartOfTexel[q] != tb.chart || d >= bestD) continue;
                    bestD = d;
                    src.sample[0] = L.rho[q].a;
                    used = 1;
                }
            if (used == 0) continue;
            src.weight[0] = 1.0f;
            for (int j = 1; j < 4; ++j) src.sample[j] = 0, src.weight[j] = 0.0f;
        } else {
            for (int j = 0; j < used; ++j) src.weight[j] = float(src.weight[j] / total);
        }
        A.seam.push_back(src);
    }
    st.seamSources = A.seam.size();

    // Statistics: density spread and conformal distortion over the atlas.
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
    if (opt.kind == LayoutKind::Uv && st.densitySpread > 4.0)
        st.warnings.push_back(str(scene.parts[0].meshPath, ": texel density varies ",
                                  std::round(st.densitySpread * 10) / 10,
                                  "x over the UV atlas (1st to 99th percentile, by area): samples are "
                                  "spread unevenly over the surface"));
    st.charts = charts;
    st.coveredTexels = N;
    st.atlasTexels = texels;
    return L;
}

}  // namespace shrefract
