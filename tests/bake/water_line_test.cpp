// The mug half filled with water (data/scenes/mug_water.json, scripts/make-mug), probed with the
// bake's own tracer: the water line is where the scene says. Paths that enter the mug's wall
// horizontally stay at their height (every wall normal is horizontal, so refraction keeps them
// in their horizontal plane): above the fill line (y = 0) they never meet the water, below it
// they all cross the water/glass interface.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bake/tracer.h"
#include "common/scene.h"

namespace shrefract {
namespace {

constexpr float kPi = 3.14159265358979f;

struct Probe {
    PathResult path;
    bool touchedWater = false;  // some ray of the path hit the water's mesh first
    float maxAbsDy = 0;         // how far the path's rays left the horizontal
};

// Enters the outer wall at height y and angle phi (about +y; the handle is at phi = 0), along the
// horizontal direction turned `turn` degrees from the inward normal.
Probe probe(const Tracer& tracer, float y, float phiDeg, float turnDeg) {
    const float phi = phiDeg * kPi / 180;
    const glm::vec3 out(std::cos(phi), 0, -std::sin(phi));  // the files' revolution: z = -r sin
    Probe r;
    SurfaceHit h;
    EXPECT_TRUE(tracer.hit(glm::vec3(0, y, 0) + 3.0f * out, -out, &h));
    const float turn = turnDeg * kPi / 180;
    const glm::vec3 side(std::sin(phi), 0, std::cos(phi));
    const glm::vec3 omega = std::cos(turn) * out + std::sin(turn) * side;  // toward the viewer
    std::vector<LoggedRay> log;
    r.path = tracer.trace(h.p, h.ns, omega, h.part, &log);
    for (const LoggedRay& ray : log) {
        r.maxAbsDy = std::max(r.maxAbsDy, std::abs(ray.dir.y));
        SurfaceHit next;
        if (tracer.hit(ray.org, ray.dir, &next) && next.part == 1) r.touchedWater = true;
    }
    return r;
}

TEST(WaterLine, PathsAboveTheFillLineNeverMeetTheWaterAndPathsBelowAllDo) {
    Scene scene = loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/mug_water.json");
    Tracer tracer(scene);
    // Heights from just above the glass floor (inner floor at y = -0.42) to below the lip (0.475).
    const float heights[] = {-0.35f, -0.25f, -0.15f, -0.05f, -0.01f, 0.01f, 0.05f, 0.15f, 0.25f, 0.4f};
    int above = 0, below = 0;
    // phi = 90 and 270 degrees: through the axis the path leaves at the opposite side, away
    // from the handle (phi = 0). Turns within 30 degrees: no total internal reflection at the
    // glass/water boundary (critical angle asin(1.33 / 1.5) = 62 degrees).
    for (float phi : {90.0f, 270.0f})
        for (float y : heights)
            for (float turn : {-30.0f, -12.0f, 0.0f, 7.0f, 21.0f, 30.0f}) {
                Probe p = probe(tracer, y, phi, turn);
                EXPECT_LT(p.maxAbsDy, 1e-4f) << "y " << y << " phi " << phi << " turn " << turn;
                EXPECT_EQ(p.touchedWater, y < 0.0f)
                    << "y " << y << " phi " << phi << " turn " << turn;
                EXPECT_EQ(p.path.flags & (kPathLeaked | kPathCapped), 0u);
                (y < 0.0f ? below : above) += 1;
            }
    EXPECT_EQ(above, below);
}

// Straight through the axis, nothing bends (the vertex columns at phi = 90 and 270 degrees have
// radial normals and lie on the circle): the length inside non-air media is then known in closed
// form. Above the fill line: two glass walls, 2 x 0.05. Below: glass, water and glass from wall to
// wall, the mug's outer diameter 1.0 (where the water overlaps the glass the water wins; either
// way it is not air).
TEST(WaterLine, LengthThroughTheAxisIsTwoWallsAboveAndTheDiameterBelow) {
    Scene scene = loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/mug_water.json");
    Tracer tracer(scene);
    for (float phi : {90.0f, 270.0f})
        for (float y : {-0.3f, -0.1f, -0.02f, 0.02f, 0.1f, 0.3f}) {
            Probe p = probe(tracer, y, phi, 0.0f);
            // Offsets of 1e-5 x the scene's extent (1.8e-5 here) at up to 4 interfaces.
            EXPECT_NEAR(p.path.length, y < 0 ? 1.0f : 0.1f, 1e-4f) << "y " << y << " phi " << phi;
            const float phiR = phi * kPi / 180;
            EXPECT_NEAR(glm::dot(p.path.exit, glm::vec3(-std::cos(phiR), 0, std::sin(phiR))), 1.0f,
                        1e-5f);
        }
    // The empty mug: two walls at every height.
    Scene empty = loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/mug_empty.json");
    Tracer emptyTracer(empty);
    for (float y : {-0.3f, 0.3f})
        EXPECT_NEAR(probe(emptyTracer, y, 90.0f, 0.0f).path.length, 0.1f, 1e-4f) << "y " << y;
}

}  // namespace
}  // namespace shrefract
