// Addressing in the surface layouts (declared in common/bakefile.h). The layouts themselves are
// built by the bake (bake/joining_layout.cpp, bake/chart_layout.cpp); these are the lookups
// everyone shares.
#include <algorithm>

#include "common/bakefile.h"
#include "common/error.h"

namespace shrefract {

glm::ivec2 SurfaceLayout::muTexel(int i) const {
    if (!isChartLayout()) return {i % muWidth, i / muWidth};
    const uint32_t t = atlas.sampleTexel[static_cast<size_t>(i)];
    return {static_cast<int>(t % static_cast<uint32_t>(muWidth)),
            static_cast<int>(t / static_cast<uint32_t>(muWidth))};
}

glm::ivec2 SurfaceLayout::rhoTexel(int t, int i, int j) const {
    int b = t / 2;
    int bx = (b % blocksPerRow) * blockWidth;
    int by = (b / blocksPerRow) * blockHeight;
    if (t % 2 == 0) return {bx + i, by + j};
    // The partner is rotated 180 degrees so its hypotenuse faces ours across the block.
    return {bx + blockWidth - 1 - i, by + blockHeight - 1 - j};
}

uint32_t SurfaceLayout::sampleAt(int t, int i, int j) const {
    glm::ivec2 p = rhoTexel(t, i, j);
    const RhoTexel& tx = rho[static_cast<size_t>(p.y) * rhoWidth + p.x];
    SHREFRACT_CHECK_EQ(tx.kind, static_cast<uint32_t>(RhoTexel::Sample));
    return tx.a;
}

std::vector<DrawCorner> drawCorners(const SurfaceLayout& L) {
    std::vector<DrawCorner> corners;
    corners.reserve(static_cast<size_t>(L.triangleCount) * 3);
    if (L.isChartLayout()) {
        const ChartAtlas& A = L.atlas;
        for (const glm::uvec3& t : A.triangles)
            for (int k = 0; k < 3; ++k)
                corners.push_back({A.vertexPosition[t[k]], A.vertexNormal[t[k]], A.vertexUV[t[k]], t[k]});
        return corners;
    }
    const int r = L.rate;
    for (int t = 0; t < L.triangleCount; ++t) {
        const glm::ivec2 grid[3] = {{0, 0}, {r, 0}, {0, r}};
        for (glm::ivec2 c : grid) {
            const uint32_t s = L.sampleAt(t, c.x, c.y);
            const glm::ivec2 texel = L.rhoTexel(t, c.x, c.y);
            const glm::vec2 uv((texel.x + 0.5f) / L.rhoWidth, (texel.y + 0.5f) / L.rhoHeight);
            corners.push_back({L.position[s], L.normal[s], uv, s});
        }
    }
    return corners;
}

void drawPoints(const SurfaceLayout& L, std::vector<glm::vec3>* positions,
                std::vector<glm::vec3>* normals) {
    *positions = L.isChartLayout() ? L.atlas.vertexPosition : L.position;
    *normals = L.isChartLayout() ? L.atlas.vertexNormal : L.normal;
}

std::vector<uint32_t> refinedTriangles(const SurfaceLayout& L) {
    const int r = L.rate;
    std::vector<uint32_t> indices;
    indices.reserve(static_cast<size_t>(L.triangleCount) * r * r * 3);
    for (int t = 0; t < L.triangleCount; ++t)
        for (int j = 0; j < r; ++j)
            for (int i = 0; i + j < r; ++i) {
                indices.insert(indices.end(), {L.sampleAt(t, i, j), L.sampleAt(t, i + 1, j),
                                               L.sampleAt(t, i, j + 1)});
                if (i + j + 1 < r)
                    indices.insert(indices.end(), {L.sampleAt(t, i + 1, j), L.sampleAt(t, i + 1, j + 1),
                                                   L.sampleAt(t, i, j + 1)});
            }
    return indices;
}

float samplesDiagonal(const SurfaceLayout& L) {
    if (L.position.empty()) return 1e-6f;
    glm::vec3 lo(L.position[0]), hi(L.position[0]);
    for (const glm::vec3& p : L.position) lo = glm::min(lo, p), hi = glm::max(hi, p);
    return std::max(glm::length(hi - lo), 1e-6f);
}

}  // namespace shrefract
