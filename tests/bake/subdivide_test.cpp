// Uniform subdivision (the Lucy-class mesh): counts from the schemes' closed forms, a closed
// mesh stays closed, and bad input is refused by name.
#include "bake/subdivide.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "common/error.h"
#include "common/mesh.h"
#include "support/cli_run.h"
#include "support/files.h"

namespace shrefract {
namespace {

struct Case {
    Subdivision scheme;
    int steps;
    size_t vertices, triangles;
};

// Loop: every edge gets a vertex, every triangle becomes 4 (V' = V + E, T' = 4T, E' = 2E + 3T).
// sqrt(3): every triangle gets a vertex and becomes 3 (V' = V + T, T' = 3T). From the
// tetrahedron (V 4, E 6, T 4).
TEST(Subdivide, CountsFollowTheSchemesAndTheMeshStaysClosed) {
    const std::string in = test::tmp("subdivide_tetra.off");
    test::writeText(in, test::kTetraOff);
    for (const Case& c : {Case{Subdivision::Loop, 1, 10, 16}, Case{Subdivision::Loop, 2, 34, 64},
                          Case{Subdivision::Sqrt3, 1, 8, 12}, Case{Subdivision::Sqrt3, 2, 20, 36}}) {
        const std::string out = test::tmp("subdivide_out.off");
        const SubdivisionResult r = subdivideMeshFile(in, out, c.scheme, c.steps);
        EXPECT_EQ(r.vertices, c.vertices);
        EXPECT_EQ(r.triangles, c.triangles);
        MeshReport report;
        const Mesh m = loadMesh(out, &report);
        EXPECT_EQ(m.positions.size(), c.vertices);
        EXPECT_EQ(m.triangles.size(), c.triangles);
        EXPECT_EQ(report.borderEdges, 0u);
        EXPECT_EQ(report.nonManifoldEdges, 0u);
        EXPECT_EQ(report.degenerateTriangles, 0u);
        // Subdivision smooths towards the inside of a convex hull: every vertex stays in it.
        for (const glm::vec3& p : m.positions) {
            EXPECT_GE(std::min({p.x, p.y, p.z}), -1e-6f);
            EXPECT_LE(p.x + p.y + p.z, 1.0f + 1e-6f);
        }
    }
}

TEST(Subdivide, BadInputIsRefusedByNameAndWritesNothing) {
    const std::string out = test::tmp("subdivide_never.off");
    std::filesystem::remove(out);
    try {
        subdivideMeshFile(test::tmp("no_such_mesh.off"), out, Subdivision::Loop, 1);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no_such_mesh.off"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(out));
}

// The output goes through the staged write every tool uses: a symbolic link at the target is
// refused, not replaced by a rename (the file it points to keeps its bytes), and an extension
// OpenMesh cannot write is refused by name with nothing left behind.
TEST(Subdivide, TheOutputIsStagedAndALinkIsNeverReplaced) {
    const std::filesystem::path dir = test::scratchFolder("subdivide");
    const std::string in = (dir / "tetra.off").string();
    test::writeText(in, test::kTetraOff);
    const std::string precious = (dir / "precious.off").string();
    test::writeText(precious, "precious");
    const std::string link = (dir / "link.off").string();
    std::filesystem::create_symlink(precious, link);
    EXPECT_THROW(subdivideMeshFile(in, link, Subdivision::Loop, 1), InputError);
    EXPECT_TRUE(std::filesystem::is_symlink(link));
    EXPECT_EQ(test::readFile(precious), "precious");

    const std::string odd = (dir / "out.xyz").string();
    try {
        subdivideMeshFile(in, odd, Subdivision::Loop, 1);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("out.xyz"), std::string::npos) << e.what();
    }
    // Nothing but the three files this test planted.
    EXPECT_EQ(test::listing(dir), (std::set<std::string>{"link.off", "precious.off", "tetra.off"}));
}

}  // namespace
}  // namespace shrefract
