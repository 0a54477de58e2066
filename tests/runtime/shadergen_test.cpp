#include "shadergen.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "common/sh.h"

namespace shrefract {
namespace {

std::string readFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

std::string concatenated(const DecompressionShaders& s) {
    std::string all = "// ---- decompress.vert\n" + s.vertex;
    for (size_t i = 0; i < s.passes.size(); ++i)
        all += "// ---- decompress_pass" + std::to_string(i + 1) + ".frag\n" + s.passes[i].fragment;
    return all;
}

TEST(ShaderGen, EveryFunctionOnceAndWithinLimits) {
    for (ShForm form : {ShForm::Polynomial, ShForm::Recurrence})
    for (const char* preset : {"2006", "modern"}) {
        for (int L = 0; L <= 10; ++L) {
            ShaderLimits limits = shaderPreset(parseName<ShaderPreset>(preset));
            DecompressionShaders s = generateDecompression(L, limits, form);
            EXPECT_EQ(s.form, form);
            std::multiset<int> seen;
            for (size_t p = 0; p < s.passes.size(); ++p) {
                const DecompressionPass& pass = s.passes[p];
                for (int k : pass.functions) seen.insert(k);
                EXPECT_LE(static_cast<int>(pass.samplers.size()), limits.maxTextureUnits);
                if (limits.maxAluInstructions > 0)
                    EXPECT_LE(pass.aluCost, limits.maxAluInstructions) << s.summary();
                // Every function is labelled.
                for (int k : pass.functions) {
                    ShLM f = shEvenFunctions(L)[k];
                    std::string label = "// y_" + std::to_string(f.l) + "^" + std::to_string(f.m) + "\n";
                    EXPECT_NE(pass.fragment.find(label), std::string::npos) << label;
                }
            }
            ASSERT_EQ(static_cast<int>(seen.size()), shEvenCount(L));
            for (int k = 0; k < shEvenCount(L); ++k) EXPECT_EQ(seen.count(k), 1u) << k;
            if (std::string(preset) == "modern") EXPECT_EQ(s.passes.size(), 1u);
            std::printf("%s\n", s.summary().c_str());
        }
    }
}

TEST(ShaderGen, TooSmallLimitsAreRefused) {
    ShaderLimits tiny = shaderPreset(ShaderPreset::Paper2006);
    tiny.maxAluInstructions = 3;
    EXPECT_THROW(generateDecompression(4, tiny), std::invalid_argument);
    EXPECT_THROW(parseName<ShaderPreset>("2042"), std::invalid_argument);
    // The grid basis needs all its layers in one array: the 2006 preset has a texture each.
    EXPECT_THROW(generateGridDecompression(8, 16, shaderPreset(ShaderPreset::Paper2006)), std::invalid_argument);
}

// The grid basis's one pass compiles as GLSL 3.30 core and 4.50, float and 8-bit weights.
TEST(ShaderGen, GridBasisGlslCompiles) {
    if (std::string(SHREFRACT_GLSLANG).empty() || !std::filesystem::exists(SHREFRACT_GLSLANG))
        GTEST_SKIP() << "glslangValidator not found (Debian: glslang-tools)";
    namespace fs = std::filesystem;
    for (const char* version : {"330 core", "450"})
        for (bool unorm : {false, true}) {
            ShaderLimits limits = shaderPreset(ShaderPreset::Modern);
            limits.version = version;
            limits.unormWeights = unorm;
            const DecompressionShaders s = generateGridDecompression(16, 32, limits);
            ASSERT_EQ(s.passes.size(), 1u);
            EXPECT_EQ(s.summary(), "grid 16x32, limits modern: 1 pass");
            const fs::path sub = fs::path(SHREFRACT_TEST_TMP) / "glsl" /
                                 ("grid_" + std::string(version).substr(0, 3) + (unorm ? "_u8" : "_f32"));
            dumpShaders(s, sub.string());
            for (const char* name : {"decompress.vert", "decompress_pass1.frag"}) {
                const std::string f = (sub / name).string();
                const std::string cmd = std::string(SHREFRACT_GLSLANG) + " " + f + " > " + f + ".log 2>&1";
                EXPECT_EQ(std::system(cmd.c_str()), 0) << f << "\n" << readFile(f + ".log");
            }
        }
}

// Compiles every generated pass with glslangValidator as GLSL 3.30 core and 4.50.
TEST(ShaderGen, GeneratedGlslCompiles) {
    if (std::string(SHREFRACT_GLSLANG).empty() || !std::filesystem::exists(SHREFRACT_GLSLANG))
        GTEST_SKIP() << "glslangValidator not found (Debian: glslang-tools)";
    namespace fs = std::filesystem;
    fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "glsl";
    for (ShForm form : {ShForm::Polynomial, ShForm::Recurrence})
    for (const char* version : {"330 core", "450"})
        for (const char* preset : {"2006", "modern"})
            for (int L : {0, 2, 5, 8}) {
                ShaderLimits limits = shaderPreset(parseName<ShaderPreset>(preset));
                limits.version = version;
                DecompressionShaders s = generateDecompression(L, limits, form);
                fs::path sub = dir / (std::string(preset) + "_" + std::to_string(L) + "_" +
                                      std::string(version).substr(0, 3) + "_" + nameOf(form));
                dumpShaders(s, sub.string());
                std::vector<std::string> files = {(sub / "decompress.vert").string()};
                for (size_t i = 0; i < s.passes.size(); ++i)
                    files.push_back((sub / ("decompress_pass" + std::to_string(i + 1) + ".frag")).string());
                for (const std::string& f : files) {
                    std::string cmd = std::string(SHREFRACT_GLSLANG) + " " + f + " > " + f + ".log 2>&1";
                    EXPECT_EQ(std::system(cmd.c_str()), 0) << f << "\n" << readFile(f + ".log");
                }
            }
}

// The generated code for a small case, against a committed file. Regenerate with
// SHREFRACT_UPDATE_SNAPSHOTS=1 after an intended change, and read the diff.
TEST(ShaderGen, SnapshotOrder2) {
    for (const char* preset : {"2006", "modern"}) {
        std::string text = concatenated(generateDecompression(2, shaderPreset(parseName<ShaderPreset>(preset))));
        std::string path = std::string(SHREFRACT_SNAPSHOT_DIR) + "/decompress_order2_" + preset + ".glsl";
        const char* update = std::getenv("SHREFRACT_UPDATE_SNAPSHOTS");
        if (update && std::string(update) == "1") {
            std::ofstream(path, std::ios::binary) << text;
            continue;
        }
        ASSERT_TRUE(std::filesystem::exists(path)) << path << " missing: run with SHREFRACT_UPDATE_SNAPSHOTS=1";
        EXPECT_EQ(readFile(path), text) << "generated GLSL changed; if intended, update " << path;
    }
}

}  // namespace
}  // namespace shrefract
