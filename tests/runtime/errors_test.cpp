// Bad input gets a clear error and leaves no output file.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "shrefract/context.h"
#include "shrefract/runtime.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

fs::path tmpDir() {
    fs::path d = fs::path(SHREFRACT_TEST_TMP) / "errors";
    fs::create_directories(d);
    return d;
}

TEST(RuntimeErrors, MissingBakeNamesTheFile) {
    try {
        loadBake("/nonexistent/dir/x.shrefract.exr");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.shrefract.exr"), std::string::npos);
    }
}

TEST(RuntimeErrors, CorruptBakeIsInputError) {
    fs::path p = tmpDir() / "corrupt.shrefract.exr";
    std::ofstream(p) << "not an exr";
    EXPECT_THROW(loadBake(p.string()), InputError);
}

TEST(RuntimeErrors, MissingEnvironmentIsInputError) {
    std::unique_ptr<HeadlessContext> ctx;
    try {
        ctx = createHeadlessContext(Backend::Egl);
    } catch (const ContextError& e) {
        GTEST_SKIP() << e.what();
    }
    EXPECT_THROW(Environment::loadLatLong((tmpDir() / "missing.exr").string()), InputError);
}

TEST(RuntimeErrors, UnknownBackendIsRefused) {
    EXPECT_THROW(parseBackend("vulkan"), std::invalid_argument);
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
    };
    for (const Case& c : cases) {
        EXPECT_NE(run(c.args + " --out " + out.string(), log), 0) << c.args;
        std::string msg = slurp(log);
        EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
        EXPECT_FALSE(fs::exists(out)) << c.args;
    }
}

}  // namespace
}  // namespace shrefract
