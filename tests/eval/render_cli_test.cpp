// shrefract-render as a user meets it: bad input gets a clear error and leaves no output file;
// a good bake renders every output.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "common/bakefile.h"
#include "shrefract/render.h"
#include "test_bake.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

fs::path tmpDir() {
    fs::path d = fs::path(SHREFRACT_TEST_TMP) / "render_cli";
    fs::create_directories(d);
    return d;
}

int run(const std::string& args, const fs::path& log) {
    std::string cmd = std::string(SHREFRACT_RENDER_EXE) + " " + args + " > " + log.string() + " 2>&1";
    int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string slurp(const fs::path& p) {
    std::ifstream f(p);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(RenderCli, BadInputExitsNonZeroWithoutOutput) {
    fs::path d = tmpDir();
    fs::path out = d / "out.png", log = d / "log.txt";
    fs::remove(out);
    fs::path corrupt = d / "corrupt2.shrefract.exr";
    std::ofstream(corrupt) << "garbage";
    struct Case {
        std::string args, expect;
    } cases[] = {
        {(d / "missing.shrefract.exr").string() + " --env " + (d / "env.exr").string(), "missing.shrefract.exr"},
        {corrupt.string() + " --env " + (d / "env.exr").string(), "corrupt2.shrefract.exr"},
        {corrupt.string() + " --env x.exr --size 12by4", "--size"},
        {corrupt.string() + " --env x.exr --backend vulkan", "vulkan"},
        {corrupt.string() + " --env x.exr --camera orbit:1,2", "--camera"},
        // A grid per pixel: the ray tracer's, at one sample per pixel, at the bake's own index.
        {corrupt.string() + " --env x.exr --exits fit", "--exits fit: only --method raytrace"},
        {corrupt.string() + " --env x.exr --method raytrace --exits grid --spp 4", "--exits grid"},
        {corrupt.string() + " --env x.exr --method raytrace --exits split --ior 1.6", "--exits split"},
        {corrupt.string() + " --env x.exr --method raytrace --exits table", "table"},
    };
    for (const Case& c : cases) {
        EXPECT_NE(run(c.args + " --out " + out.string(), log), 0) << c.args;
        std::string msg = slurp(log);
        EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
        EXPECT_FALSE(fs::exists(out)) << c.args;
    }
}

// A 2x1 lat-long EXR, enough for an environment.
void writeTinyEnv(const fs::path& p) {
    std::vector<float> rgba = {1, 1, 1, 1, 0.5f, 0.5f, 0.5f, 1};
    writeExr(p.string(), 2, 1, rgba);
}

// End to end: a bake written with writeBake, rendered by the CLI; then the same bake with a
// missing environment fails without output.
TEST(RenderCli, RendersABakeAndRefusesAMissingEnvironment) {
    fs::path d = tmpDir();
    fs::path bakePath = d / "octa.shrefract.exr", env = d / "env.exr", log = d / "cli.txt";
    writeBake(bakePath.string(), test::randomBake(4, 2));
    writeTinyEnv(env);
    fs::path png = d / "octa.png", exr = d / "octa.exr", dirs = d / "dirs.exr";
    for (const fs::path& p : {png, exr, dirs}) fs::remove(p);
    std::string common = bakePath.string() + " --size 64x48 --camera orbit:20,10,3.5";
    ASSERT_EQ(run(common + " --env " + env.string() + " --out " + png.string() + " --out-exr " +
                      exr.string() + " --dirs " + dirs.string() + " --dump-shaders " +
                      (d / "shaders").string(),
                  log), 0)
        << slurp(log);
    std::printf("%s", slurp(log).c_str());
    for (const fs::path& p : {png, exr, dirs}) EXPECT_TRUE(fs::exists(p)) << p;
    EXPECT_TRUE(fs::exists(d / "shaders" / "decompress_pass1.frag"));
    fs::remove(png);
    EXPECT_NE(run(common + " --env " + (d / "nope.exr").string() + " --out " + png.string(), log), 0);
    EXPECT_NE(slurp(log).find("nope.exr"), std::string::npos) << slurp(log);
    EXPECT_FALSE(fs::exists(png));
}

}  // namespace
}  // namespace shrefract
