// glTF input (common/gltf_scene.h): the mapping of docs/bake.md "glTF input", checked against
// closed forms (bounds under known transforms, κ from a known attenuation) and against the same
// scene read from its OFF files; and every kind of bad file, built here, refused with a message
// that names the file and the problem.
#include "common/gltf_scene.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/scene.h"
#include "support/input_error.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path testDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "gltf" / info->name();
    fs::create_directories(dir);
    return dir;
}

// The cube [-0.5, 0.5]^3, wound counter-clockwise seen from outside.
const std::vector<float> kCubePositions = {-0.5f, -0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, -0.5f,
                                           -0.5f, 0.5f,  -0.5f, -0.5f, -0.5f, 0.5f, 0.5f, -0.5f, 0.5f,
                                           0.5f,  0.5f,  0.5f,  -0.5f, 0.5f,  0.5f};
const std::vector<uint16_t> kCubeIndices = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                            2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 3, 0, 4, 3, 4, 7};

// A glTF document under construction: meshes of one TRIANGLES primitive each, their data in one
// buffer, written as .gltf + .bin, .gltf with a data URI, or .glb.
struct Doc {
    json j = {{"asset", {{"version", "2.0"}, {"generator", "shrefract tests"}}}};
    std::string bin;

    int add(const char* key, json item) {
        j[key].push_back(std::move(item));
        return int(j[key].size()) - 1;
    }
    int view(const void* data, size_t size) {
        while (bin.size() % 4) bin.push_back('\0');
        const size_t offset = bin.size();
        bin.append(static_cast<const char*>(data), size);
        return add("bufferViews", {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}});
    }
    int vec3(const std::vector<float>& v) {
        return add("accessors", {{"bufferView", view(v.data(), v.size() * 4)},
                                 {"componentType", 5126},
                                 {"count", v.size() / 3},
                                 {"type", "VEC3"}});
    }
    int indices(const std::vector<uint16_t>& i) {
        return add("accessors", {{"bufferView", view(i.data(), i.size() * 2)},
                                 {"componentType", 5123},
                                 {"count", i.size()},
                                 {"type", "SCALAR"}});
    }
    // A transmissive material; `extensions` are merged into its extensions object.
    int glass(const std::string& name, json extensions = json::object()) {
        extensions["KHR_materials_transmission"] = {{"transmissionFactor", 1.0}};
        return add("materials", {{"name", name}, {"extensions", extensions}});
    }
    int opaque(const std::string& name) {
        return add("materials", {{"name", name}, {"pbrMetallicRoughness", {{"metallicFactor", 1.0}}}});
    }
    int mesh(int material, const std::vector<float>& positions = kCubePositions,
             const std::vector<uint16_t>& idx = kCubeIndices) {
        json prim = {{"attributes", {{"POSITION", vec3(positions)}}}, {"material", material}};
        if (!idx.empty()) prim["indices"] = indices(idx);
        return add("meshes", {{"primitives", json::array({prim})}});
    }
    int node(const std::string& name, int mesh, json extra = json::object()) {
        extra["name"] = name;
        if (mesh >= 0) extra["mesh"] = mesh;
        return add("nodes", extra);
    }
    void scene(std::vector<int> roots) {
        j["scene"] = 0;
        j["scenes"] = json::array({{{"nodes", roots}}});
    }
    void finishBuffer(const std::string& uri) {
        while (bin.size() % 4) bin.push_back('\0');
        j["buffers"] = json::array({{{"byteLength", bin.size()}}});
        if (!uri.empty()) j["buffers"][0]["uri"] = uri;
    }
    std::string writeGltf(const std::string& name = "scene.gltf", const std::string& binName = "scene.bin") {
        finishBuffer(binName);
        const fs::path dir = testDir();
        std::ofstream(dir / binName, std::ios::binary) << bin;
        std::ofstream(dir / name) << j.dump(1);
        return (dir / name).string();
    }
    std::string writeDataUri() {
        static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        finishBuffer("");
        std::string enc;
        for (size_t i = 0; i < bin.size(); i += 3) {
            uint32_t n = uint32_t(uint8_t(bin[i])) << 16;
            if (i + 1 < bin.size()) n |= uint32_t(uint8_t(bin[i + 1])) << 8;
            if (i + 2 < bin.size()) n |= uint8_t(bin[i + 2]);
            enc += b64[(n >> 18) & 63];
            enc += b64[(n >> 12) & 63];
            enc += i + 1 < bin.size() ? b64[(n >> 6) & 63] : '=';
            enc += i + 2 < bin.size() ? b64[n & 63] : '=';
        }
        j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + enc;
        const fs::path p = testDir() / "embedded.gltf";
        std::ofstream(p) << j.dump();
        return p.string();
    }
    std::string writeGlb(const std::string& name = "scene.glb") {
        finishBuffer("");
        std::string text = j.dump();
        while (text.size() % 4) text.push_back(' ');
        auto u32 = [](uint32_t x) { return std::string(reinterpret_cast<const char*>(&x), 4); };
        std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
        out += u32(uint32_t(text.size())) + "JSON" + text;
        out += u32(uint32_t(bin.size())) + std::string("BIN\0", 4) + bin;
        const fs::path p = testDir() / name;
        std::ofstream(p, std::ios::binary) << out;
        return p.string();
    }
};

// One glass cube under one node, the common start of most cases.
Doc glassCube(json glassExtensions = json::object(), json nodeExtra = json::object()) {
    Doc d;
    d.scene({d.node("cube", d.mesh(d.glass("Glass", glassExtensions)), nodeExtra)});
    return d;
}

void expectError(const std::string& path, std::initializer_list<std::string> fragments) {
    test::expectRefused([](const std::string& p) { loadScene(p); }, path, fragments);
}

// Two readers (OpenMesh on the OFF files, tinygltf on the binary buffer) of one scene, written by
// scripts/make-mug and scripts/make-teapot from the same OFF text.
class GltfMatchesJson : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(GltfMatchesJson, BitForBit) {
    const std::string dir = std::string(SHREFRACT_DATA_DIR) + "/scenes/";
    const Scene off = loadScene(dir + GetParam().first);
    const Scene gltf = loadScene(dir + GetParam().second);
    ASSERT_EQ(gltf.parts.size(), off.parts.size());
    for (size_t i = 0; i < off.parts.size(); ++i) {
        const Part &a = off.parts[i], &b = gltf.parts[i];
        EXPECT_EQ(b.name, a.name);
        EXPECT_EQ(b.medium.ior, a.medium.ior);
        EXPECT_EQ(b.medium.priority, a.medium.priority) << a.name;
        EXPECT_EQ(b.medium.absorption, a.medium.absorption);
        ASSERT_EQ(b.mesh.positions.size(), a.mesh.positions.size());
        EXPECT_EQ(0, std::memcmp(b.mesh.positions.data(), a.mesh.positions.data(),
                                 a.mesh.positions.size() * sizeof(glm::vec3)));
        EXPECT_EQ(b.mesh.triangles, a.mesh.triangles);
        EXPECT_EQ(0, std::memcmp(b.mesh.normals.data(), a.mesh.normals.data(),
                                 a.mesh.normals.size() * sizeof(glm::vec3)));
    }
    EXPECT_TRUE(gltf.notes.empty());
}

INSTANTIATE_TEST_SUITE_P(Scenes, GltfMatchesJson,
                         ::testing::Values(std::make_pair("mug_water.json", "mug_water.gltf"),
                                           std::make_pair("teapot.json", "teapot.glb")),
                         [](const auto& info) { return info.index == 0 ? "Mug" : "Teapot"; });

TEST(Gltf, BlenderTumblerUnderATransformedEmpty) {
    // Rig: scale 1.5, a turn about +y, then (0.2, 0.75, -0.1); Tumbler: up 0.002; Water: none.
    // The tumbler's y [0, 0.09] lands on 0.75 + 1.5 * ([0, 0.09] + 0.002); its outer radius 0.035
    // becomes 0.0525 about the vertical axis through (0.2, -0.1), whatever the turn.
    const Scene s = loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/blender_tumbler.glb");
    ASSERT_EQ(s.parts.size(), 2u);
    const Part &glass = s.parts[0], &water = s.parts[1];
    EXPECT_EQ(glass.name, "Tumbler");
    EXPECT_EQ(water.name, "Water");
    EXPECT_NEAR(glass.mesh.boundsMin().y, 0.753, 1e-6);
    EXPECT_NEAR(glass.mesh.boundsMax().y, 0.888, 1e-6);
    float radius = 0.0f;
    for (const glm::vec3& p : glass.mesh.positions)
        radius = std::max(radius, glm::length(glm::vec2(p.x - 0.2f, p.z + 0.1f)));
    EXPECT_NEAR(radius, 0.0525, 1e-6);
    EXPECT_EQ(glass.medium.ior, 1.45);
    EXPECT_EQ(water.medium.ior, 1.333);
    EXPECT_EQ(glass.medium.priority, 1);
    EXPECT_EQ(water.medium.priority, 2);  // its bounds lie inside the glass's
    // attenuationDistance 1, attenuationColor exp(-(0.4, 0.12, 0.05)).
    EXPECT_NEAR(water.medium.absorption.x, 0.4, 1e-12);
    EXPECT_NEAR(water.medium.absorption.y, 0.12, 1e-12);
    EXPECT_NEAR(water.medium.absorption.z, 0.05, 1e-12);
    EXPECT_TRUE(glass.report.warnings.empty());
    EXPECT_TRUE(s.notes.empty());
}

TEST(Gltf, BlenderGlassOnATableLeavesTheTableOut) {
    const Scene s =
        loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/blender_glass_on_table.gltf");
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_EQ(s.parts[0].name, "Sphere");
    // The unit icosphere scaled by 0.05 about (0.1, 0.8, 0.05).
    for (const glm::vec3& p : s.parts[0].mesh.positions)
        EXPECT_NEAR(glm::length(p - glm::vec3(0.1f, 0.8f, 0.05f)), 0.05, 1e-6);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_NE(s.notes[0].find("left out node 'Table'"), std::string::npos) << s.notes[0];
}

TEST(Gltf, ExternalDataUriAndGlbBuffersReadTheSame) {
    Doc d = glassCube();
    Doc e = d, g = d;
    const Scene a = loadScene(d.writeGltf()), b = loadScene(e.writeDataUri()), c = loadScene(g.writeGlb());
    ASSERT_EQ(a.parts.size(), 1u);
    for (const Scene* s : {&b, &c}) {
        ASSERT_EQ(s->parts.size(), 1u);
        EXPECT_EQ(s->parts[0].mesh.positions, a.parts[0].mesh.positions);
        EXPECT_EQ(s->parts[0].mesh.triangles, a.parts[0].mesh.triangles);
    }
    // And the file's numbers, unchanged: the cube's corners.
    EXPECT_EQ(a.parts[0].mesh.boundsMin(), glm::vec3(-0.5f));
    EXPECT_EQ(a.parts[0].mesh.boundsMax(), glm::vec3(0.5f));
    EXPECT_EQ(a.parts[0].mesh.triangles.size(), 12u);
}

TEST(Gltf, NodeTransformsThroughTheHierarchy) {
    // Parent: scale 2, then translate (10, 0, 0). Child: scale y by 3, then translate (0, 1, 0).
    // The cube's y range [-0.5, 0.5] becomes [-1.5, 1.5] + 1 = [-0.5, 2.5] in the parent, then
    // [-1, 5]; x [-0.5, 0.5] -> [9, 11]; z -> [-1, 1].
    Doc d;
    const int child = d.node("cube", d.mesh(d.glass("Glass")),
                             {{"translation", {0, 1, 0}}, {"scale", {1, 3, 1}}});
    const int parent = d.node("empty", -1,
                              {{"children", {child}}, {"translation", {10, 0, 0}}, {"scale", {2, 2, 2}}});
    d.scene({parent});
    const Scene s = loadScene(d.writeGltf());
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_EQ(s.parts[0].mesh.boundsMin(), glm::vec3(9, -1, -1));
    EXPECT_EQ(s.parts[0].mesh.boundsMax(), glm::vec3(11, 5, 1));
}

TEST(Gltf, MatrixAndRotation) {
    // A column-major matrix translating by (0, 0, -3) above a node turned 90 degrees about z
    // (quaternion (0, 0, sin 45, cos 45)) and stretched along x by 4: the cube's x extent 4
    // becomes its y extent; the turn maps (x, y) to (-y, x).
    Doc d;
    const double h = std::sqrt(0.5);
    const int child = d.node("cube", d.mesh(d.glass("Glass")),
                             {{"rotation", {0, 0, h, h}}, {"scale", {4, 1, 1}}});
    const int parent = d.node("root", -1,
                              {{"children", {child}},
                               {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3, 1}}});
    d.scene({parent});
    const Scene s = loadScene(d.writeGltf());
    ASSERT_EQ(s.parts.size(), 1u);
    const glm::vec3 lo = s.parts[0].mesh.boundsMin(), hi = s.parts[0].mesh.boundsMax();
    const glm::vec3 wantLo(-0.5f, -2.0f, -3.5f), wantHi(0.5f, 2.0f, -2.5f);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(lo[k], wantLo[k], 1e-6) << k;
        EXPECT_NEAR(hi[k], wantHi[k], 1e-6) << k;
    }
}

TEST(Gltf, MirroringTransformKeepsTheWindingOutward) {
    // scale -1 in x mirrors the cube: glTF then reverses the winding, so the triangles must be
    // turned back rather than found inward (the loader's warning) and flipped.
    const Scene s = loadScene(glassCube({}, {{"scale", {-1, 1, 1}}}).writeGltf());
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_TRUE(s.parts[0].report.warnings.empty())
        << s.parts[0].report.warnings.front();
    // Outward: the normal at corner (0.5, 0.5, 0.5) (vertex 6 mirrored to x = -0.5) points out.
    const Mesh& m = s.parts[0].mesh;
    for (size_t v = 0; v < m.positions.size(); ++v)
        EXPECT_GT(glm::dot(m.normals[v], m.positions[v]), 0.0f) << v;
}

TEST(Gltf, IorDefaultsToOnePointFive) {
    const Scene bare = loadScene(glassCube().writeGltf());
    ASSERT_EQ(bare.parts.size(), 1u);
    EXPECT_EQ(bare.parts[0].medium.ior, 1.5);
    Doc d = glassCube({{"KHR_materials_ior", {{"ior", 1.33}}}});
    EXPECT_EQ(loadScene(d.writeGlb()).parts[0].medium.ior, 1.33);
}

TEST(Gltf, VolumeAttenuationIsKappa) {
    // exp(-kappa * 2) = (0.5, 0.25, 1): kappa = (ln 2 / 2, ln 4 / 2, 0) per unit.
    Doc d = glassCube({{"KHR_materials_volume",
                        {{"attenuationDistance", 2.0}, {"attenuationColor", {0.5, 0.25, 1.0}}}}});
    const Scene s = loadScene(d.writeGltf());
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_NEAR(s.parts[0].medium.absorption.x, 0.34657359027997264, 1e-15);
    EXPECT_NEAR(s.parts[0].medium.absorption.y, 0.69314718055994531, 1e-15);
    EXPECT_EQ(s.parts[0].medium.absorption.z, 0.0);
    EXPECT_FALSE(std::signbit(s.parts[0].medium.absorption.z));
    // No distance: infinite, nothing absorbed whatever the colour.
    Doc e = glassCube({{"KHR_materials_volume", {{"attenuationColor", {0.5, 0.5, 0.5}}}}});
    EXPECT_EQ(loadScene(e.writeGltf()).parts[0].medium.absorption, glm::dvec3(0.0));
}

TEST(Gltf, NonGlassPrimitivesAreLeftOutWithANote) {
    Doc d;
    const int table = d.node("Table", d.mesh(d.opaque("Steel")));
    const int glass = d.node("Sphere", d.mesh(d.glass("Glass"), kCubePositions, kCubeIndices),
                             {{"translation", {0, 2, 0}}});
    // An extension present but transmissionFactor absent (default 0) is opaque too.
    const int frosted = d.node("Frosted", d.mesh(d.add("materials", {{"name", "Zero"},
        {"extensions", {{"KHR_materials_transmission", json::object()}}}})));
    d.scene({table, glass, frosted});
    const Scene s = loadScene(d.writeGltf());
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_EQ(s.parts[0].name, "Sphere");
    EXPECT_EQ(s.parts[0].mesh.boundsMin(), glm::vec3(-0.5f, 1.5f, -0.5f));
    ASSERT_EQ(s.notes.size(), 2u);
    EXPECT_NE(s.notes[0].find("'Table'"), std::string::npos) << s.notes[0];
    EXPECT_NE(s.notes[0].find("dielectrics only"), std::string::npos) << s.notes[0];
    EXPECT_NE(s.notes[1].find("'Frosted'"), std::string::npos) << s.notes[1];
}

TEST(Gltf, PriorityFromContainmentOrExtras) {
    std::vector<float> small(kCubePositions);
    for (float& x : small) x *= 0.5f;
    std::vector<float> shifted(kCubePositions);
    for (size_t i = 0; i < shifted.size(); i += 3) shifted[i] += 0.75f;  // overlaps the outer cube
    Doc d;
    const int water = d.glass("Water", {{"KHR_materials_ior", {{"ior", 1.33}}}});
    d.scene({d.node("inner", d.mesh(water, small)), d.node("outer", d.mesh(d.glass("Glass"))),
             d.node("side", d.mesh(water, shifted))});
    const Scene s = loadScene(d.writeGltf());
    ASSERT_EQ(s.parts.size(), 3u);
    EXPECT_EQ(s.parts[0].medium.priority, 2);  // inside the outer cube's bounds
    EXPECT_EQ(s.parts[1].medium.priority, 1);
    EXPECT_EQ(s.parts[2].medium.priority, 1);  // overlapping, not inside: ambiguous, said so
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_NE(s.notes[0].find("'outer' and 'side'"), std::string::npos) << s.notes[0];
    EXPECT_NE(s.notes[0].find(kGltfPriorityKey), std::string::npos) << s.notes[0];

    // extras settle it: on the node, or on the material (the node's wins).
    Doc e;
    const int tagged = e.glass("Water", {{"KHR_materials_ior", {{"ior", 1.33}}}});
    e.j["materials"][tagged]["extras"] = {{kGltfPriorityKey, 7}};
    e.scene({e.node("outer", e.mesh(e.glass("Glass"))), e.node("side", e.mesh(tagged, shifted)),
             e.node("inner", e.mesh(tagged, small), {{"extras", {{kGltfPriorityKey, 3}}}})});
    const Scene t = loadScene(e.writeGltf());
    ASSERT_EQ(t.parts.size(), 3u);
    EXPECT_EQ(t.parts[0].medium.priority, 1);
    EXPECT_EQ(t.parts[1].medium.priority, 7);
    EXPECT_EQ(t.parts[2].medium.priority, 3);
    EXPECT_TRUE(t.notes.empty());
}

// ---- bad input ----

TEST(GltfRejects, MissingBuffer) {
    Doc d = glassCube();
    const std::string path = d.writeGltf("scene.gltf", "gone.bin");
    fs::remove(testDir() / "gone.bin");
    expectError(path, {"gone.bin"});
}

TEST(GltfRejects, BufferThatIsNotARegularFile) {
    // A FIFO would block the read (tinygltf's own existence check opens it), a device such as
    // /dev/zero read forever: only regular files are buffers.
    Doc d = glassCube();
    fs::remove(testDir() / "fifo.bin");  // a FIFO left by an earlier run would block the write
    const std::string path = d.writeGltf("scene.gltf", "fifo.bin");
    fs::remove(testDir() / "fifo.bin");
    ASSERT_EQ(::mkfifo((testDir() / "fifo.bin").c_str(), 0600), 0);
    expectError(path, {"fifo.bin", "not found"});
}

TEST(GltfRejects, TruncatedExternalBuffer) {
    Doc d = glassCube();
    const std::string path = d.writeGltf();
    fs::resize_file(testDir() / "scene.bin", d.bin.size() - 8);
    expectError(path, {"scene.bin", "size"});
}

TEST(GltfRejects, BufferViewPastTheBuffer) {
    Doc d = glassCube();
    d.j["bufferViews"][0]["byteLength"] = 4096;
    expectError(d.writeGlb(), {"bufferView 0", "reaches past the end of buffer 0", "truncated"});
}

TEST(GltfRejects, AccessorPastItsView) {
    Doc d = glassCube();
    d.j["accessors"][0]["count"] = 9;  // 9 vertices in a view of 8
    expectError(d.writeGltf(), {"POSITION", "9 elements", "reach past the end of bufferView 0"});
}

TEST(GltfRejects, AttributeCountsDisagree) {
    Doc d = glassCube();
    d.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] =
        d.vec3(std::vector<float>(kCubePositions.begin(), kCubePositions.begin() + 15));
    expectError(d.writeGltf(), {"NORMAL has 5 elements but POSITION has 8"});
}

TEST(GltfRejects, IndexOutOfRange) {
    std::vector<uint16_t> idx(kCubeIndices);
    idx[7] = 8;
    Doc d;
    d.scene({d.node("cube", d.mesh(d.glass("Glass"), kCubePositions, idx))});
    expectError(d.writeGltf(), {"node 'cube' primitive 0", "index 8 (element 7", "out of range",
                                "8 vertices"});
}

TEST(GltfRejects, IndicesNotWholeTriangles) {
    std::vector<uint16_t> idx(kCubeIndices.begin(), kCubeIndices.end() - 1);
    Doc d;
    d.scene({d.node("cube", d.mesh(d.glass("Glass"), kCubePositions, idx))});
    expectError(d.writeGltf(), {"35 indices", "multiple of 3"});
}

TEST(GltfRejects, NonTriangleMode) {
    Doc d = glassCube();
    d.j["meshes"][0]["primitives"][0]["mode"] = 1;  // LINES
    expectError(d.writeGltf(), {"node 'cube' primitive 0", "mode 1 is not supported", "TRIANGLES"});
}

TEST(GltfRejects, DracoCompression) {
    Doc d = glassCube();
    d.j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    d.j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    d.j["meshes"][0]["primitives"][0]["extensions"] = {
        {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
    expectError(d.writeGltf(), {"KHR_draco_mesh_compression", "not supported"});
}

TEST(GltfRejects, MeshoptCompression) {
    Doc d = glassCube();
    d.j["bufferViews"][0]["extensions"] = {
        {"EXT_meshopt_compression",
         {{"buffer", 0}, {"byteLength", 96}, {"byteStride", 12}, {"count", 8}, {"mode", "ATTRIBUTES"}}}};
    expectError(d.writeGlb(), {"bufferView 0 uses EXT_meshopt_compression", "not supported"});
}

TEST(GltfRejects, TransmissiveMaterialWithoutGlassTriangles) {
    Doc d;
    d.glass("Unused glass");
    d.scene({d.node("table", d.mesh(d.opaque("Steel")))});
    expectError(d.writeGltf(), {"transmissive materials ('Unused glass')", "no glass triangles"});
}

TEST(GltfRejects, NoGlassAtAll) {
    Doc d;
    d.scene({d.node("table", d.mesh(d.opaque("Steel")))});
    expectError(d.writeGlb(), {"no glass", "KHR_materials_transmission"});
}

TEST(GltfRejects, NodeWithTwoParents) {
    Doc d;
    const int cube = d.node("cube", d.mesh(d.glass("Glass")));
    d.scene({d.node("a", -1, {{"children", {cube}}}), d.node("b", -1, {{"children", {cube}}})});
    expectError(d.writeGltf(), {"node 0 ('cube') has two parents"});
}

TEST(GltfRejects, NodeCycle) {
    Doc d;
    const int a = d.node("a", d.mesh(d.glass("Glass")), {{"children", {1}}});
    d.node("b", -1, {{"children", {a}}});
    d.scene({a});
    expectError(d.writeGltf(), {"scene 0 names node 0 ('a') as a root, but it is a child of node 1"});
}

TEST(GltfRejects, AbsurdMedium) {
    expectError(glassCube({{"KHR_materials_ior", {{"ior", 7.0}}}}).writeGltf(),
                {"material 'Glass'", "ior"});
    expectError(glassCube({{"KHR_materials_volume", {{"attenuationDistance", 1.0},
                                                     {"attenuationColor", {0.0, 1.0, 1.0}}}}})
                    .writeGltf(),
                {"material 'Glass'", "attenuationColor", "(0, 1]"});
}

TEST(GltfRejects, NonFinitePositionNamesTheNode) {
    std::vector<float> v(kCubePositions);
    v[4] = std::numeric_limits<float>::quiet_NaN();
    Doc d;
    d.scene({d.node("cube", d.mesh(d.glass("Glass"), v))});
    expectError(d.writeGltf(), {"node 'cube' primitive 0", "vertex 1 has non-finite coordinates"});
}

TEST(GltfRejects, NotGltf) {
    const fs::path p = testDir() / "junk.gltf";
    std::ofstream(p) << "{\"asset\": ";
    expectError(p.string(), {"could not read glTF"});
    const fs::path q = testDir() / "junk.glb";
    std::ofstream(q) << "glTF but not really";
    expectError(q.string(), {"could not read glTF"});
    expectError((testDir() / "absent.glb").string(), {"file not found"});
}

}  // namespace
}  // namespace shrefract
