// Meshes built in code for analytic tracer and layout tests: exact geometry, known normals.
#pragma once

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "common/scene.h"

namespace shrefract::test {

// A polyhedron with flat faces, unwelded (every face keeps its own vertices and normal). Each
// face is a convex polygon listed counter-clockwise seen from outside; `inward` flips them
// (the cavity of a shell).
inline Mesh flatPolyhedron(const std::vector<std::vector<glm::vec3>>& faces, bool inward = false) {
    Mesh m;
    for (const auto& f : faces) {
        glm::vec3 n = glm::normalize(glm::cross(f[1] - f[0], f[2] - f[0]));
        uint32_t base = static_cast<uint32_t>(m.positions.size());
        for (glm::vec3 p : f) {
            m.positions.push_back(p);
            m.normals.push_back(inward ? -n : n);
        }
        for (uint32_t k = 1; k + 1 < f.size(); ++k) {
            if (inward)
                m.triangles.push_back({base, base + k + 1, base + k});
            else
                m.triangles.push_back({base, base + k, base + k + 1});
        }
    }
    return m;
}

inline Mesh flatBox(glm::vec3 l, glm::vec3 h, bool inward = false) {
    return flatPolyhedron({{{l.x, l.y, h.z}, {h.x, l.y, h.z}, {h.x, h.y, h.z}, {l.x, h.y, h.z}},   // +z
                           {{l.x, h.y, l.z}, {h.x, h.y, l.z}, {h.x, l.y, l.z}, {l.x, l.y, l.z}},   // -z
                           {{h.x, l.y, l.z}, {h.x, h.y, l.z}, {h.x, h.y, h.z}, {h.x, l.y, h.z}},   // +x
                           {{l.x, l.y, h.z}, {l.x, h.y, h.z}, {l.x, h.y, l.z}, {l.x, l.y, l.z}},   // -x
                           {{l.x, h.y, h.z}, {h.x, h.y, h.z}, {h.x, h.y, l.z}, {l.x, h.y, l.z}},   // +y
                           {{l.x, l.y, l.z}, {h.x, l.y, l.z}, {h.x, l.y, h.z}, {l.x, l.y, h.z}}},  // -y
                          inward);
}

// Appends b's geometry to a (one mesh, two shells).
inline void append(Mesh& a, const Mesh& b) {
    uint32_t base = static_cast<uint32_t>(a.positions.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
    for (glm::uvec3 t : b.triangles) a.triangles.push_back(t + glm::uvec3(base));
}

// An icosphere of radius `radius` (welded, closed), `levels` subdivisions of the icosahedron,
// with exact sphere normals: 20 * 4^levels triangles.
inline Mesh icosphere(int levels, float radius = 1.0f) {
    Mesh m;
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& p : v) p = glm::normalize(p);
    std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[key] = static_cast<uint32_t>(v.size() - 1);
        };
        std::vector<glm::uvec3> g;
        for (auto tri : f) {
            uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
            g.push_back({tri[0], a, c});
            g.push_back({tri[1], b, a});
            g.push_back({tri[2], c, b});
            g.push_back({a, b, c});
        }
        f = g;
    }
    for (auto p : v) {
        m.positions.push_back(p * radius);
        m.normals.push_back(p);
    }
    m.triangles = f;
    return m;
}

inline Scene sceneOf(Mesh mesh, double ior = 1.5, int priority = 0) {
    Scene s;
    Part p;
    p.name = "glass";
    p.mesh = std::move(mesh);
    p.medium.ior = ior;
    p.medium.priority = priority;
    s.parts.push_back(std::move(p));
    return s;
}

}  // namespace shrefract::test
