#include "common/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.h"
#include "support/input_error.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

std::string dataPath(const std::string& rel) { return std::string(SHREFRACT_DATA_DIR) + "/" + rel; }

// A folder of its own for the running test, holding a copy of the unit cube as box.off.
fs::path testDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "scene" / info->name();
    fs::create_directories(dir);
    fs::copy_file(dataPath("scenes/cube.off"), dir / "box.off",
                  fs::copy_options::overwrite_existing);
    return dir;
}

std::string writeScene(const std::string& json) {
    fs::path path = testDir() / "scene.json";
    std::ofstream(path) << json;
    return path.string();
}

// A scene with one part whose body is `partBody` (the text inside the part's braces).
std::string onePart(const std::string& partBody) {
    return writeScene(R"({"parts": [{"name": "glass", "mesh": "box.off")" + partBody + "}]}");
}

// Expects loadScene to fail with a message that starts with the scene file and contains every
// fragment.
void expectSceneError(const std::string& path, std::initializer_list<std::string> fragments) {
    test::expectRefused([](const std::string& p) { loadScene(p); }, path, fragments);
}

TEST(Scene, GlassWithLiquidHasTwoPartsAndPriorities) {
    Scene s = loadScene(dataPath("scenes/glass_liquid.json"));
    ASSERT_EQ(s.parts.size(), 2u);
    const Part& glass = s.parts[0];
    const Part& liquid = s.parts[1];
    EXPECT_EQ(glass.name, "glass");
    EXPECT_EQ(glass.medium.name, "glass");
    EXPECT_EQ(glass.medium.ior, 1.5);
    EXPECT_EQ(glass.medium.priority, 1);
    EXPECT_EQ(glass.medium.absorption, glm::dvec3(0.0, 0.05, 0.1));
    EXPECT_EQ(liquid.name, "liquid");
    EXPECT_EQ(liquid.medium.ior, 1.33);
    EXPECT_EQ(liquid.medium.priority, 2);
    EXPECT_EQ(glass.mesh.triangles.size(), 12u);
    EXPECT_EQ(liquid.mesh.triangles.size(), 12u);
    // The liquid's bottom lies in the glass's bottom plane; elsewhere it is inside.
    EXPECT_EQ(liquid.mesh.boundsMin().z, glass.mesh.boundsMin().z);
    EXPECT_LT(liquid.mesh.boundsMax().z, glass.mesh.boundsMax().z);
    EXPECT_EQ(fs::path(liquid.meshPath).filename(), "liquid_box.off");
    EXPECT_TRUE(fs::exists(liquid.meshPath));
}

TEST(Scene, BeadInShellAndDiamond) {
    Scene shell = loadScene(dataPath("scenes/bead_in_shell.json"));
    ASSERT_EQ(shell.parts.size(), 2u);
    EXPECT_EQ(shell.parts[0].mesh.triangles.size(), 640u);
    EXPECT_EQ(shell.parts[0].report.borderEdges, 0u);
    EXPECT_TRUE(shell.parts[0].report.warnings.empty());  // the inner sphere is not "flipped"
    EXPECT_EQ(shell.parts[1].mesh.triangles.size(), 320u);
    EXPECT_NEAR(shell.parts[1].mesh.boundsMax().x, 0.4f, 1e-6f);

    Scene diamond = loadScene(dataPath("scenes/diamond.json"));
    ASSERT_EQ(diamond.parts.size(), 1u);
    EXPECT_EQ(diamond.parts[0].medium.ior, 2.42);
    EXPECT_EQ(diamond.parts[0].mesh.triangles.size(), 1280u);
}

TEST(Scene, MeshPathsAreRelativeToTheSceneFile) {
    fs::path dir = testDir();
    fs::create_directories(dir / "sub");
    fs::copy_file(dataPath("scenes/cube.off"), dir / "sub" / "inner.off",
                  fs::copy_options::overwrite_existing);
    std::string absolute = fs::absolute(dataPath("scenes/slab.off")).string();
    fs::path path = dir / "scene.json";
    std::ofstream(path) << R"({"parts": [{"mesh": "sub/inner.off", "priority": 2},
                                         {"mesh": ")"
                        << absolute << R"("}]})";
    // Load through a path with a different working directory in mind: only the scene's own
    // folder may anchor the relative mesh path.
    Scene s = loadScene(path.string());
    ASSERT_EQ(s.parts.size(), 2u);
    EXPECT_EQ(fs::path(s.parts[0].meshPath), (dir / "sub" / "inner.off").lexically_normal());
    EXPECT_EQ(s.parts[0].name, "inner");  // default name: the mesh's stem
    EXPECT_EQ(s.parts[0].medium.priority, 2);
    EXPECT_EQ(s.parts[1].name, "slab");
    EXPECT_EQ(s.parts[1].mesh.boundsMax(), glm::vec3(2.0f, 2.0f, 0.5f));
}

TEST(Scene, ScaleAndTranslateApplyToPositions) {
    Scene s = loadScene(onePart(R"(, "scale": 2, "translate": [1, 0, -3])"));
    EXPECT_EQ(s.parts[0].mesh.boundsMin(), glm::vec3(0.0f, -1.0f, -4.0f));
    EXPECT_EQ(s.parts[0].mesh.boundsMax(), glm::vec3(2.0f, 1.0f, -2.0f));
}

TEST(Scene, DefaultsComeFromTheDefaultMedium) {
    Medium water;
    water.ior = 1.33;
    water.priority = 7;
    Scene s = loadScene(onePart(""), water);
    EXPECT_EQ(s.parts[0].medium.ior, 1.33);
    EXPECT_EQ(s.parts[0].medium.priority, 7);
    EXPECT_EQ(s.parts[0].medium.name, "glass");  // the part's name
}

TEST(Scene, BareMeshIsOnePartWithTheDefaultMedium) {
    Medium m;
    m.ior = 1.7;
    std::string path = dataPath("meshes/sphere.off");
    Scene s = loadScene(path, m);
    EXPECT_EQ(s.path, path);
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_EQ(s.parts[0].meshPath, path);
    EXPECT_EQ(s.parts[0].medium.ior, 1.7);
    EXPECT_EQ(s.parts[0].mesh.triangles.size(), 320u);
}

TEST(Scene, BareMeshWithAbsurdIorIsRejected) {
    Medium m;
    m.ior = 0.5;
    std::string path = dataPath("meshes/sphere.off");
    try {
        loadScene(path, m);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'ior' 0.5 is not in [1, 5]"), std::string::npos);
    }
}

TEST(Scene, JsonSyntaxErrorGivesLineAndColumn) {
    expectSceneError(writeScene("{\"parts\": [\n  {\"mesh\": \"box.off\",}\n]}"),
                     {"invalid JSON", "line 2, column"});
}

TEST(Scene, MissingOrEmptyParts) {
    expectSceneError(writeScene("{}"), {"missing 'parts'"});
    expectSceneError(writeScene(R"({"parts": []})"), {"'parts' is empty"});
    expectSceneError(writeScene(R"({"parts": {}})"), {"'parts' must be an array"});
    expectSceneError(writeScene(R"([1, 2])"), {"JSON object"});
    expectSceneError(writeScene(R"({"parts": [{"mesh": "box.off"}], "part": 1})"),
                     {"unknown key 'part'", "allowed: parts"});
}

TEST(Scene, MissingMesh) {
    expectSceneError(writeScene(R"({"parts": [{"name": "glass", "ior": 1.5}]})"),
                     {"parts[0] ('glass')", "missing 'mesh'"});
}

TEST(Scene, UnknownKeyListsTheAllowedOnes) {
    expectSceneError(onePart(R"(, "iro": 1.5)"),
                     {"parts[0] ('glass')", "unknown key 'iro'",
                      "allowed: name, mesh, ior, absorption, priority, scale, translate"});
}

TEST(Scene, IorOutOfRangeOrNotANumber) {
    expectSceneError(onePart(R"(, "ior": 0.9)"),
                     {"parts[0] ('glass')", "'ior' 0.9 is not in [1, 5]"});
    expectSceneError(onePart(R"(, "ior": 7)"), {"'ior' 7 is not in [1, 5]"});
    expectSceneError(onePart(R"(, "ior": 1e999)"), {"invalid JSON", "1e999"});
    expectSceneError(onePart(R"(, "ior": "1.5")"), {"'ior' must be a finite number"});
}

TEST(Scene, BadAbsorption) {
    expectSceneError(onePart(R"(, "absorption": [0, -0.1, 0])"),
                     {"parts[0] ('glass')", "'absorption' has -0.1"});
    expectSceneError(onePart(R"(, "absorption": [0, 0.1])"),
                     {"'absorption' must be 3 finite numbers"});
    expectSceneError(onePart(R"(, "absorption": [0, null, 0])"),
                     {"'absorption' must be 3 finite numbers, got [0,null,0]"});
    expectSceneError(onePart(R"(, "absorption": 0.1)"), {"'absorption' must be 3"});
}

TEST(Scene, PriorityMustBeAnInteger) {
    expectSceneError(onePart(R"(, "priority": 1.5)"),
                     {"parts[0] ('glass')", "'priority' must be an integer, got 1.5"});
    expectSceneError(onePart(R"(, "priority": "high")"), {"'priority' must be an integer"});
}

TEST(Scene, BadScaleOrTranslate) {
    expectSceneError(onePart(R"(, "scale": 0)"), {"'scale' must be a finite number > 0"});
    expectSceneError(onePart(R"(, "translate": [0, 0])"), {"'translate' must be 3"});
}

TEST(Scene, DuplicatePartNames) {
    expectSceneError(writeScene(R"({"parts": [{"mesh": "box.off"}, {"mesh": "box.off"}]})"),
                     {"parts[1]", "duplicate part name 'box'"});
}

TEST(Scene, MeshErrorNamesSceneAndMeshFile) {
    std::string path =
        writeScene(R"({"parts": [{"mesh": "box.off"}, {"name": "liquid", "mesh": "gone.off"}]})");
    std::string mesh = (fs::path(path).parent_path() / "gone.off").string();
    expectSceneError(path, {"parts[1] ('liquid')", mesh + ": file not found"});
}

TEST(Scene, MissingSceneFile) {
    expectSceneError((testDir() / "absent.json").string(), {"file not found"});
}

}  // namespace
}  // namespace shrefract
