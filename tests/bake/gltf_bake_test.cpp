// glTF input end to end: the mug with water as glTF (data/scenes/mug_water.gltf, written by
// scripts/make-mug from the same OFF text) bakes to the same weights, bit for bit, as its JSON
// scene (data/scenes/mug_water.json); and what a Blender-style file leaves out is said.
#include <gtest/gtest.h>

#include <cstring>
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
    const std::string out = tmp("glass_on_table.shrefract.exr");
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
