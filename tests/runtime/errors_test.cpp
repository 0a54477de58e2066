// Bad input gets a clear error and leaves no output file.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "bake_data.h"
#include "common/bakefile.h"
#include "common/error.h"
#include "test_bake.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
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
    EXPECT_THROW(parseName<Backend>("vulkan"), std::invalid_argument);
}

TEST(RuntimeErrors, RefractorNeedsACurrentContext) {
    Bake bake = makeBake(test::randomBake(1, 1));
    RefractorOptions o;
    o.loader = createHeadlessContext(Backend::Egl)->loader();  // context gone again at once
    EXPECT_THROW(Refractor::create(bake, o), std::runtime_error);
}

}  // namespace
}  // namespace shrefract
