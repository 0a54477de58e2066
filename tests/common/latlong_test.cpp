// Environment images: what loadLatLong refuses, naming the file (the runtime's
// Environment::loadLatLong and the reference renderer both go through it).
#include "common/latlong.h"

#include <ImfRgbaFile.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/bakefile.h"
#include "common/error.h"
#include "support/files.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

fs::path scratch() { return test::scratchFolder("latlong"); }

// A width x height RGBA half EXR of a grey sky, with `poison` at pixel (1, 1) if not zero.
fs::path writeEnv(const fs::path& p, int width, int height, float poison = 0.0f) {
    std::vector<Imf::Rgba> pixels(size_t(width) * height, Imf::Rgba(0.5f, 0.5f, 0.5f, 1.0f));
    if (poison != 0.0f) pixels[size_t(width) + 1].g = poison;
    Imf::RgbaOutputFile out(p.c_str(), width, height, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels.data(), 1, size_t(width));
    out.writePixels(height);
    return p;
}

void expectRefused(const fs::path& p, const std::string& what) {
    try {
        loadLatLong(p.string());
        FAIL() << p << " was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(p.string() + ": "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
}

TEST(LatLong, TwoToOneImagesLoad) {
    const fs::path dir = scratch();
    for (auto [w, h] : {std::pair{64, 32}, {65, 32}, {63, 32}, {2, 1}}) {
        const LatLongImage img = loadLatLong(writeEnv(dir / "ok.exr", w, h).string());
        EXPECT_EQ(img.width, w);
        EXPECT_EQ(img.height, h);
        EXPECT_EQ(img.rgb[0], 0.5f);
    }
}

// Any aspect ratio was taken without a word (101 x 37, 16384 x 8); NaN and inf pixels spread into
// every output pixel that filtered them; a bake given as --env rendered black.
TEST(LatLong, RefusesWhatIsNoPanorama) {
    const fs::path dir = scratch();
    expectRefused(writeEnv(dir / "odd.exr", 101, 37), "101 x 37: a lat-long image is twice as wide");
    expectRefused(writeEnv(dir / "strip.exr", 16384, 8), "16384 x 8");
    expectRefused(writeEnv(dir / "nan.exr", 64, 32, NAN),
                  "1 values are not finite (NaN or inf), the first at pixel (1, 1)");
    expectRefused(writeEnv(dir / "inf.exr", 64, 32, INFINITY), "not finite");
    expectRefused(dir / "missing.exr", "file not found");
    std::ofstream(dir / "text.exr") << "not an image";
    expectRefused(dir / "text.exr", "not an OpenEXR file");
    ASSERT_EQ(::mkfifo((dir / "fifo.exr").c_str(), 0644), 0);
    expectRefused(dir / "fifo.exr", "not a regular file");
    EXPECT_EQ(latLongProblem(64, 32, std::vector<float>(64 * 32 * 3, 1.0f)), "");
    EXPECT_NE(latLongProblem(64, 32, std::vector<float>(5, 1.0f)), "");
}

TEST(LatLong, RefusesABakeFile) {
    const fs::path dir = scratch();
    BakeData d;
    d.order = 0;
    d.layout.muWidth = d.layout.muHeight = 1;
    d.layout.rhoWidth = d.layout.rhoHeight = 1;
    d.layout.rho.resize(1);
    writeBake((dir / "a.shrefract.exr").string(), d);
    expectRefused(dir / "a.shrefract.exr", "is a shrefract bake, not an environment image");
}

}  // namespace
}  // namespace shrefract
