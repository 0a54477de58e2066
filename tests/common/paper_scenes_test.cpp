// The paper's scenes in data/scenes (scripts/make-mug, scripts/make-teapot): closed and
// watertight as the project's own loader judges them, with the sizes and the fill line the
// scripts promise.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "common/scene.h"

namespace shrefract {
namespace {

std::string scenePath(const std::string& name) {
    return std::string(SHREFRACT_DATA_DIR) + "/scenes/" + name;
}

size_t triangles(const Scene& s) {
    size_t n = 0;
    for (const Part& p : s.parts) n += p.mesh.triangles.size();
    return n;
}

// Every part of every scene: no border, non-manifold or degenerate edges, no warning at all
// (the loader also warns on inconsistent winding and inward normals).
TEST(PaperScenes, EveryPartIsClosedAndWatertight) {
    for (const char* name : {"mug_empty.json", "mug_water.json", "mug_solid.json", "teapot.json",
                             "teapot_dense.json"}) {
        Scene s = loadScene(scenePath(name));
        ASSERT_FALSE(s.parts.empty()) << name;
        for (const Part& p : s.parts) {
            EXPECT_EQ(p.report.borderEdges, 0u) << name << " " << p.name;
            EXPECT_EQ(p.report.nonManifoldEdges, 0u) << name << " " << p.name;
            EXPECT_EQ(p.report.degenerateTriangles, 0u) << name << " " << p.name;
            EXPECT_TRUE(p.report.warnings.empty())
                << name << " " << p.name << ": " << p.report.warnings.front();
        }
    }
}

// The paper's Table 1: teapot 2256 triangles, mug 9184. Newell's 32 patches at n x n quads give
// 64 n^2 triangles less the 8 n degenerate ones at the lid's knob and the bottom's centre: 2256 at
// n = 6, the paper's count. 8 n more close the lid's seat (a ring of 4 n quads) and 8 n the four
// tube ends (2 n triangles each).
TEST(PaperScenes, SizesNearThePapersTable1) {
    auto teapot = [](size_t n) { return 64 * n * n - 8 * n + 8 * n + 8 * n; };
    EXPECT_EQ(64 * 6 * 6 - 8 * 6, 2256);
    EXPECT_EQ(triangles(loadScene(scenePath("teapot.json"))), teapot(6));
    EXPECT_EQ(triangles(loadScene(scenePath("teapot_dense.json"))), teapot(12));
    const size_t mug = triangles(loadScene(scenePath("mug_empty.json")));
    EXPECT_NEAR(double(mug), 9184.0, 0.05 * 9184.0);
}

// The water fills the mug to half its height (the plane y = 0), reaches 0.005 into the glass
// wall (inner radius 0.45, outer 0.5) and bottom (inner floor at y = -0.42), and wins there.
TEST(PaperScenes, WaterFillsHalfTheMugAndOverlapsTheGlass) {
    Scene s = loadScene(scenePath("mug_water.json"));
    ASSERT_EQ(s.parts.size(), 2u);
    const Part& glass = s.parts[0];
    const Part& water = s.parts[1];
    EXPECT_DOUBLE_EQ(glass.medium.ior, 1.5);
    EXPECT_DOUBLE_EQ(water.medium.ior, 1.33);
    EXPECT_GT(water.medium.priority, glass.medium.priority);
    EXPECT_FLOAT_EQ(glass.mesh.boundsMin().y, -0.5f);
    EXPECT_NEAR(glass.mesh.boundsMax().y, 0.5f, 1e-6f);
    EXPECT_NEAR(water.mesh.boundsMax().y, 0.0f, 1e-6f);       // the fill line
    EXPECT_NEAR(water.mesh.boundsMin().y, -0.425f, 1e-6f);    // 0.005 into the glass floor
    EXPECT_NEAR(water.mesh.boundsMax().x, 0.455f, 1e-6f);     // 0.005 into the glass wall
    // The water sits inside the glass's outer wall everywhere.
    for (glm::vec3 p : water.mesh.positions) {
        ASSERT_LT(std::hypot(p.x, p.z), 0.5f - 0.04f) << p.x << " " << p.z;
        ASSERT_GT(p.y, -0.5f + 0.07f);
    }
}

}  // namespace
}  // namespace shrefract
