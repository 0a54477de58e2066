// glTF input end to end: the mug with water as glTF (data/scenes/mug_water.gltf, written by
// scripts/make-mug from the same OFF text) bakes to the same weights, bit for bit, as its JSON
// scene (data/scenes/mug_water.json); and what a Blender-style file leaves out is said.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <glm/glm.hpp>

#include <cstring>
#include <filesystem>
#include <string>

#include "common/bakefile.h"
#include "support/cli_run.h"

namespace {

using shrefract::test::run;
using shrefract::test::tmp;

const std::string kBake = SHREFRACT_BAKE_EXE;
const std::string kScenes = std::string(SHREFRACT_DATA_DIR) + "/scenes/";
// Small enough for a second each (6298 samples, 32 directions, 6 coefficients), large enough that
// every part and both media are sampled.
const std::string kSmall = " --rate 1 --grid 4x8 --order 2 -q --cache ''";

TEST(GltfBake, MugWithWaterBakesTheJsonScenesWeightsBitForBit) {
    const std::string fromJson = tmp("mug_water_json.shrefract.exr");
    const std::string fromGltf = tmp("mug_water_gltf.shrefract.exr");
    ASSERT_EQ(run(kBake + " " + kScenes + "mug_water.json -o " + fromJson + kSmall).code, 0);
    const auto r = run(kBake + " " + kScenes + "mug_water.gltf -o " + fromGltf + kSmall);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("left out"), std::string::npos) << r.out;
    const shrefract::BakeData a = shrefract::readBake(fromJson), b = shrefract::readBake(fromGltf);
    ASSERT_EQ(a.weights.size(), b.weights.size());
    ASSERT_GT(a.weights.size(), 0u);
    // Bit for bit (== would take -0 for +0).
    EXPECT_EQ(0, std::memcmp(a.weights.data(), b.weights.data(), a.weights.size() * sizeof(float)))
        << "the weights differ";
    ASSERT_EQ(a.errors.size(), b.errors.size());
    EXPECT_EQ(0, std::memcmp(a.errors.data(), b.errors.data(), a.errors.size() * sizeof(float)))
        << "the error models differ";
    // The manifests differ only in where the parts came from.
    EXPECT_NE(b.manifest["input"].get<std::string>().find("mug_water.gltf"), std::string::npos);
    ASSERT_EQ(b.manifest["media"].size(), 2u);
    EXPECT_NE(b.manifest["media"][1]["mesh"].get<std::string>().find("mug_water.gltf#water"),
              std::string::npos);
    for (int i = 0; i < 2; ++i) {
        for (const char* key : {"name", "ior", "absorption", "priority", "meshChecksum", "triangles"})
            EXPECT_EQ(a.manifest["media"][i][key], b.manifest["media"][i][key]) << i << " " << key;
    }
}

TEST(GltfBake, SaysWhatItLeavesOutAndThatIorIsTheMaterials) {
    // Not roundTrip's "glass_on_table": ctest runs the two cases at once.
    const std::string out = tmp("glass_on_table_notes.shrefract.exr");
    const auto r = run(kBake + " " + kScenes + "blender_glass_on_table.gltf -o " + out + kSmall +
                       " --ior 1.7");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("note: " + kScenes + "blender_glass_on_table.gltf: left out node 'Table'"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("note: --ior is for a bare mesh"), std::string::npos) << r.out;
    const shrefract::BakeData b = shrefract::readBake(out);
    ASSERT_EQ(b.manifest["media"].size(), 1u);
    EXPECT_EQ(b.manifest["media"][0]["name"], "Sphere");
    EXPECT_EQ(b.manifest["media"][0]["ior"], 1.5);  // the material's, not --ior's
}

}  // namespace

namespace gltf_round_trip {

using Model = tinygltf::Model;

Model parseFile(const std::string& path) {
    Model m;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool glb = path.size() > 4 && path.substr(path.size() - 4) == ".glb";
    const bool ok = glb ? loader.LoadBinaryFromFile(&m, &err, &warn, path)
                        : loader.LoadASCIIFromFile(&m, &err, &warn, path);
    EXPECT_TRUE(ok) << path << ": " << err;
    return m;
}

// Accessor a's elements as floats (tightly packed float accessors only: what both files hold).
std::vector<float> floats(const Model& m, int a) {
    const tinygltf::Accessor& acc = m.accessors.at(size_t(a));
    const tinygltf::BufferView& v = m.bufferViews.at(size_t(acc.bufferView));
    EXPECT_EQ(acc.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
    const int n = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    std::vector<float> out(acc.count * size_t(n));
    std::memcpy(out.data(), m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset + acc.byteOffset,
                out.size() * sizeof(float));
    return out;
}

glm::dmat4 matrixOf(const std::vector<double>& m) {
    glm::dmat4 r(1.0);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) r[c][k] = m[size_t(c * 4 + k)];
    return r;
}

// Bakes SCENE small, writes it back with shrefract-export --into, and checks the file against the
// input (parsed on its own) and the bake: every node, material and non-glass primitive as it was;
// each glass primitive's vertices, taken to the bake's space by bakeFromLocal, are the samples they
// name; and every sample is drawn exactly once.
void roundTrip(const std::string& scene, const std::string& stem) {
    const std::string bake = tmp(stem + ".shrefract.exr"), out = tmp(stem + "_baked.glb");
    ASSERT_EQ(run(kBake + " " + kScenes + scene + " -o " + bake + kSmall).code, 0);
    const auto r = run(std::string(SHREFRACT_EXPORT_EXE) + " " + bake + " --into " + kScenes + scene + " -o " + out);
    ASSERT_EQ(r.code, 0) << r.out;
    const Model in = parseFile(kScenes + scene), got = parseFile(out);
    const shrefract::BakeData d = shrefract::readBake(bake);
    ASSERT_EQ(got.nodes.size(), in.nodes.size());
    for (size_t n = 0; n < in.nodes.size(); ++n) {
        EXPECT_EQ(got.nodes[n].name, in.nodes[n].name);
        EXPECT_EQ(got.nodes[n].children, in.nodes[n].children);
        EXPECT_EQ(got.nodes[n].translation, in.nodes[n].translation);
        EXPECT_EQ(got.nodes[n].rotation, in.nodes[n].rotation);
        EXPECT_EQ(got.nodes[n].scale, in.nodes[n].scale);
        EXPECT_EQ(got.nodes[n].matrix, in.nodes[n].matrix);
    }
    ASSERT_EQ(got.materials.size(), in.materials.size());
    for (size_t i = 0; i < in.materials.size(); ++i) {
        const tinygltf::Material &a = got.materials[i], &b = in.materials[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.pbrMetallicRoughness.baseColorFactor, b.pbrMetallicRoughness.baseColorFactor);
        EXPECT_EQ(a.pbrMetallicRoughness.metallicFactor, b.pbrMetallicRoughness.metallicFactor);
        EXPECT_EQ(a.pbrMetallicRoughness.roughnessFactor, b.pbrMetallicRoughness.roughnessFactor);
        ASSERT_EQ(a.extensions.size(), b.extensions.size()) << a.name;
        for (const auto& [name, value] : b.extensions) {
            ASSERT_TRUE(a.extensions.count(name)) << name;
            // Numbers as numbers: a writer may print 1.0 as 1.
            for (const std::string& key : value.Keys())
                if (value.Get(key).IsNumber())
                    EXPECT_EQ(a.extensions.at(name).Get(key).GetNumberAsDouble(),
                              value.Get(key).GetNumberAsDouble()) << name << "." << key;
        }
    }
    const size_t N = d.layout.position.size();
    std::vector<int> drawn(N, 0);
    int glass = 0, other = 0;
    for (size_t n = 0; n < got.nodes.size(); ++n) {
        if (got.nodes[n].mesh < 0) continue;
        const auto& gm = got.meshes.at(size_t(got.nodes[n].mesh)).primitives;
        const auto& im = in.meshes.at(size_t(in.nodes[n].mesh)).primitives;
        ASSERT_EQ(gm.size(), im.size());
        for (size_t k = 0; k < gm.size(); ++k) {
            EXPECT_EQ(gm[k].material, im[k].material);
            auto ext = gm[k].extensions.find("SHREFRACT_sh_refraction");
            if (ext == gm[k].extensions.end()) {
                // Not glass: the same positions, bit for bit.
                ++other;
                EXPECT_EQ(floats(got, gm[k].attributes.at("POSITION")), floats(in, im[k].attributes.at("POSITION")));
                continue;
            }
            ++glass;
            glm::dmat4 bakeFromLocal(1.0);
            if (ext->second.Has("bakeFromLocal")) {
                std::vector<double> m;
                const tinygltf::Value& v = ext->second.Get("bakeFromLocal");
                for (size_t i = 0; i < v.ArrayLen(); ++i) m.push_back(v.Get(int(i)).GetNumberAsDouble());
                ASSERT_EQ(m.size(), 16u);
                bakeFromLocal = matrixOf(m);
            }
            const std::vector<float> p = floats(got, gm[k].attributes.at("POSITION"));
            const std::vector<float> s = floats(got, gm[k].attributes.at("_SHREFRACT_SAMPLE"));
            ASSERT_EQ(p.size(), s.size() * 3);
            double worst = 0;
            for (size_t v = 0; v < s.size(); ++v) {
                const size_t i = size_t(s[v]);
                ASSERT_LT(i, N);
                ++drawn[i];
                const glm::dvec3 back = glm::dvec3(bakeFromLocal * glm::dvec4(p[v * 3], p[v * 3 + 1], p[v * 3 + 2], 1.0));
                worst = std::max(worst, glm::length(back - glm::dvec3(d.layout.position[i])));
            }
            // float32 positions through a matrix and back: a few ulps of coordinates near 1.
            EXPECT_LT(worst, 1e-5);
        }
    }
    EXPECT_GT(glass, 0);
    for (size_t i = 0; i < N; ++i) ASSERT_EQ(drawn[i], 1) << "sample " << i;
    if (stem == "glass_on_table") {
        EXPECT_EQ(other, 1);  // the table
    }
}

TEST(GltfRoundTrip, NodesAndTransformsStayAndGlassCarriesTheBake) { roundTrip("blender_tumbler.glb", "tumbler"); }
TEST(GltfRoundTrip, OtherObjectsStayAsTheyWere) { roundTrip("blender_glass_on_table.gltf", "glass_on_table"); }

TEST(GltfRoundTrip, RefusesABakeOfAnotherScene) {
    const std::string bake = tmp("mug_for_other.shrefract.exr"), out = tmp("mismatch.glb");
    ASSERT_EQ(run(kBake + " " + kScenes + "mug_water.gltf -o " + bake + kSmall).code, 0);
    const auto r = run(std::string(SHREFRACT_EXPORT_EXE) + " " + bake + " --into " + kScenes +
                       "blender_tumbler.glb -o " + out);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("blender_tumbler.glb"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("re-bake"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace gltf_round_trip
