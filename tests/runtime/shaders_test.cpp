// The GLSL files of shaders/ as the library embeds them (runtime/src/shaders.h).
#include "shaders.h"

#include "common/limits.h"
#include "shadergen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace shrefract {
namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Every file in shaders/ is embedded; files without includes verbatim, the others with every
// #include line replaced by the included file's text (the slow path: read them from disk here).
TEST(ShaderFiles, EmbeddedAreTheFilesOnDiskWithIncludesResolved) {
    std::vector<std::string> onDisk;
    for (const auto& e : fs::directory_iterator(SHREFRACT_SHADER_DIR)) onDisk.push_back(e.path().filename());
    std::sort(onDisk.begin(), onDisk.end());
    EXPECT_EQ(shaders::names(), onDisk);
    for (const std::string& name : onDisk) {
        const std::string raw = readFile(fs::path(SHREFRACT_SHADER_DIR) / name);
        const std::string& embedded = shaders::source(name);
        EXPECT_EQ(embedded.find("#include"), std::string::npos) << name;
        if (raw.find("#include") == std::string::npos) {
            EXPECT_EQ(embedded, raw) << name;
            continue;
        }
        // Each line of the raw file is in the embedded text, except the #include lines, whose
        // files' lines are there instead.
        std::istringstream lines(raw);
        std::string line;
        while (std::getline(lines, line)) {
            if (line.rfind("#include \"", 0) == 0) {
                const std::string inc = line.substr(10, line.size() - 11);
                std::istringstream incLines(readFile(fs::path(SHREFRACT_SHADER_DIR) / inc));
                std::string l2;
                while (std::getline(incLines, l2))
                    if (l2.find("#include") == std::string::npos)
                        EXPECT_NE(embedded.find(l2), std::string::npos) << name << " lacks " << inc << ": " << l2;
            } else {
                EXPECT_NE(embedded.find(line), std::string::npos) << name << ": " << line;
            }
        }
    }
    EXPECT_THROW(shaders::source("nope.frag"), std::invalid_argument);
}

// glslangValidator compiles every stage file as the GPU gets it (includes resolved). The
// decompression template compiles through the generator (ShaderGen.GeneratedGlslCompiles); the
// error model's fold is compiled here with the pass runtime/src/error_fold.cpp generates for it
// at the largest error order.
TEST(ShaderFiles, EveryStageCompiles) {
    if (std::string(SHREFRACT_GLSLANG).empty() || !fs::exists(SHREFRACT_GLSLANG))
        GTEST_SKIP() << "glslangValidator not found (Debian: glslang-tools)";
    const fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "shader_files";
    fs::create_directories(dir);
    int checked = 0;
    for (const std::string& name : shaders::names()) {
        if (!endsWith(name, ".vert") && !endsWith(name, ".frag")) continue;
        if (name == "decompress.frag") continue;
        const fs::path f = dir / name;
        std::string text = shaders::source(name);
        if (name == "error_fold.frag")
            text = shaders::fill(text, "#pragma shrefract_generated",
                                 generateDecompression(limits::kMaxErrorOrder, shaderPreset(ShaderPreset::Modern),
                                                       ShForm::Polynomial).passes[0].generated);
        std::ofstream(f, std::ios::binary) << text;
        const std::string cmd = std::string(SHREFRACT_GLSLANG) + " " + f.string() + " > " +
                                f.string() + ".log 2>&1";
        EXPECT_EQ(std::system(cmd.c_str()), 0) << name << "\n" << readFile(f.string() + ".log");
        ++checked;
    }
    EXPECT_GE(checked, 10);
}

TEST(ShaderFiles, TemplatesFillTheirMarkerLine) {
    const std::string t = "#version 330 core\nA\n  #pragma mark here\nB\n";
    EXPECT_EQ(shaders::fill(t, "#pragma mark", "X\nY"), "#version 330 core\nA\nX\nY\nB\n");
    EXPECT_THROW(shaders::fill(t, "#pragma other", "X"), std::invalid_argument);
    EXPECT_EQ(shaders::withVersion(t, "450", "#define F"), "#version 450\n#define F\nA\n  #pragma mark here\nB\n");
    EXPECT_THROW(shaders::withVersion("void main() {}\n", "450"), std::invalid_argument);
}

}  // namespace
}  // namespace shrefract
