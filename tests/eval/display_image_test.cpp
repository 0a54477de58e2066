// shrefract-eval image --test-png: a display image (a browser's frame) against a reference
// evaluation buffer, checked against answers computed here: PSNR by hand over the object mask,
// FLIP of flat images in closed form, and the bytes of a PNG read back as written.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "eval/image_eval.h"
#include "common/error.h"
#include "common/evalbuffer.h"
#include "common/tonemap.h"

using namespace shrefract;

namespace {

std::string tmpPath(const std::string& name) {
    std::filesystem::create_directories(SHREFRACT_TEST_TMP);
    return std::string(SHREFRACT_TEST_TMP) + "/" + name;
}

EvalBuffer flatBuffer(int w, int h, glm::vec3 colour, bool covered) {
    EvalBuffer b;
    b.width = w, b.height = h;
    b.color.assign(size_t(w) * h, glm::vec4(colour, covered ? 1.0f : 0.0f));
    b.direction.assign(size_t(w) * h, glm::vec3(0, 0, covered ? 1.0f : 0.0f));
    return b;
}

Image8 flatImage(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
    Image8 img;
    img.resize(w, h);
    for (size_t i = 0; i < img.rgb.size(); i += 3) img.rgb[i] = r, img.rgb[i + 1] = g, img.rgb[i + 2] = b;
    return img;
}

// CIE L* of an sRGB-encoded grey (Y of a grey is its linear value; white has Y = 1).
double lightness(double g) {
    const double y = g <= 0.04045 ? g / 12.92 : std::pow((g + 0.055) / 1.055, 2.4);
    const double d = 6.0 / 29;
    return 116 * (y > d * d * d ? std::cbrt(y) : y / (3 * d * d) + 4.0 / 29) - 16;
}

// The FLIP of two flat grey images: the CSF filters keep a constant, the feature terms are 0, and
// between greys (a* = b* = 0) HyAB is |delta L*|; then ^0.7, over the green-blue distance, and
// the compression (0.4 of the range onto [0, 0.95]). The green-blue distance from D65 XYZ rows.
double flatGreyFlip(double g1, double g2) {
    const double white[3] = {0.9505041, 1.0, 1.0889300};
    auto lab = [&](double x, double y, double z) {
        const double d = 6.0 / 29;
        auto f = [&](double t) { return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29; };
        const double fx = f(x / white[0]), fy = f(y / white[1]), fz = f(z / white[2]);
        const double L = 116 * fy - 16;
        return glm::dvec3(L, L / 100 * 500 * (fx - fy), L / 100 * 200 * (fy - fz));
    };
    const glm::dvec3 green = lab(0.3575761, 0.7151522, 0.1191920), blue = lab(0.1804375, 0.0721750, 0.9503041);
    const double cMax = std::pow(std::abs(green.x - blue.x) + std::hypot(green.y - blue.y, green.z - blue.z), 0.7);
    const double e = std::pow(std::abs(lightness(g1) - lightness(g2)), 0.7);
    return e < 0.4 * cMax ? 0.95 * e / (0.4 * cMax) : 0.95 + 0.05 * (e - 0.4 * cMax) / (0.6 * cMax);
}

}  // namespace

TEST(DisplayImage, PngReadsBackTheBytesWritten) {
    Image8 img;
    img.resize(7, 5);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = static_cast<uint8_t>((i * 37 + 11) % 256);
    const std::string path = tmpPath("bytes.png");
    writePng8(path, img);
    const Image8 back = readPng8(path);
    ASSERT_EQ(back.width, 7);
    ASSERT_EQ(back.height, 5);
    EXPECT_EQ(back.rgb, img.rgb);
}

TEST(DisplayImage, ObjectPsnrIsTheQuantizationErrorOverTheMaskByHand) {
    // A smooth HDR image, a disc covered; the PNG is its tone map rounded to 8 bits, with the
    // background outside the disc replaced by black (which the object metrics must ignore).
    const int w = 48, h = 40;
    EvalBuffer ref;
    ref.width = w, ref.height = h;
    Image8 png;
    png.resize(w, h);
    double se = 0;
    size_t n = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec3 c(0.05f + 0.08f * x, 0.3f + 0.05f * y, 2.0f * std::abs(std::sin(0.2f * (x + y))));
            const bool covered = std::hypot(x - 24.0, y - 20.0) < 12;
            ref.color.emplace_back(c, covered ? 1.0f : 0.0f);
            ref.direction.emplace_back(0, 0, covered ? 1 : 0);
            const glm::vec3 t = toneMapAces(c);
            uint8_t* p = png.at(x, y);
            for (int k = 0; k < 3; ++k) {
                p[k] = covered ? static_cast<uint8_t>(std::lround(t[k] * 255.0)) : 0;
                if (covered) se += std::pow(double(t[k]) - p[k] / 255.0, 2), ++n;
            }
        }
    const std::string path = tmpPath("quantized.png");
    writePng8(path, png);
    const nlohmann::json r = compareDisplayImage(ref, readPng8(path));
    const double byHand = 10 * std::log10(1.0 / (se / n));
    std::printf("[ measured ] object PSNR %.4f dB, by hand %.4f dB\n", r["objectPsnr"].get<double>(), byHand);
    EXPECT_NEAR(r["objectPsnr"].get<double>(), byHand, 1e-3);
    EXPECT_GT(r["objectPsnr"].get<double>(), 55.0);  // 8-bit rounding: at most half a code
    EXPECT_EQ(r["coverage"]["ref"].get<size_t>(), n / 3);
    EXPECT_LT(r["psnr"].get<double>(), 30.0);  // the black background counts frame-wide
    EXPECT_FALSE(r.contains("angleDeg"));
}

TEST(DisplayImage, FlatGreenAgainstBlueIsFlipOne) {
    // A very bright green tone-maps to exactly (0, 1, 0): against a blue PNG, FLIP's maximum.
    const nlohmann::json r = compareDisplayImage(flatBuffer(32, 24, {0, 1e4f, 0}, true), flatImage(32, 24, 0, 0, 255));
    EXPECT_NEAR(r["objectFlip"].get<double>(), 1.0, 1e-6);
    EXPECT_NEAR(r["psnr"].get<double>(), 10 * std::log10(1.5), 1e-5);
}

TEST(DisplayImage, FlatGreysMatchTheClosedFormFlip) {
    for (float level : {0.05f, 0.3f, 1.0f, 4.0f})
        for (int code : {0, 40, 128, 200, 255}) {
            const double g = toneMapAces(glm::vec3(level)).x;
            const nlohmann::json r =
                compareDisplayImage(flatBuffer(32, 24, glm::vec3(level), true), flatImage(32, 24, code, code, code));
            const double expected = flatGreyFlip(g, code / 255.0);
            EXPECT_NEAR(r["objectFlip"].get<double>(), expected, 1e-4) << level << " vs " << code;
            EXPECT_NEAR(r["flip"].get<double>(), expected, 1e-4) << level << " vs " << code;
        }
}

TEST(DisplayImage, RefusesOtherSizesAndFilesThatAreNoPng) {
    EXPECT_THROW(compareDisplayImage(flatBuffer(8, 8, glm::vec3(1), true), flatImage(8, 9, 1, 2, 3)), InputError);
    const std::string path = tmpPath("not.png");
    std::ofstream(path) << "not a png";
    EXPECT_THROW(readPng8(path), InputError);
    EXPECT_THROW(readPng8(tmpPath("missing.png")), InputError);
}
