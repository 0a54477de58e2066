// Image metrics, the evaluation EXR layout and the reference camera, against known answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "eval/image_eval.h"
#include "eval/reference.h"
#include "common/evalbuffer.h"
#include "common/latlong.h"
#include "common/scene.h"
#include "common/tonemap.h"

using namespace shrefract;

namespace {

EvalBuffer randomBuffer(int w, int h, unsigned seed) {
    EvalBuffer b;
    b.width = w, b.height = h;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int i = 0; i < w * h; ++i) {
        b.color.emplace_back(u(rng) + 1, u(rng) + 1, u(rng) + 1, i % 3 ? 1.0f : 0.0f);
        b.direction.push_back(i % 3 ? glm::normalize(glm::vec3(u(rng), u(rng), u(rng))) : glm::vec3(0));
    }
    return b;
}

// The grey level whose tone-mapped value is `v` (toneMapAces is increasing on grey): bisection.
float greyFor(float v) {
    float lo = 0.0f, hi = 16.0f;
    for (int k = 0; k < 60; ++k) {
        const float mid = 0.5f * (lo + hi);
        (toneMapAces(glm::vec3(mid)).x < v ? lo : hi) = mid;
    }
    return 0.5f * (lo + hi);
}

// The buffer's colours blurred with the 3 x 3 binomial kernel (clamp to edge).
EvalBuffer blurred(const EvalBuffer& b) {
    EvalBuffer out = b;
    const float k[3] = {0.25f, 0.5f, 0.25f};
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x) {
            glm::vec3 s(0);
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = std::clamp(x + dx, 0, b.width - 1), yy = std::clamp(y + dy, 0, b.height - 1);
                    s += k[dx + 1] * k[dy + 1] * glm::vec3(b.color[size_t(yy) * b.width + xx]);
                }
            glm::vec4& c = out.color[size_t(y) * b.width + x];
            c = glm::vec4(s, c.a);
        }
    return out;
}

}  // namespace

TEST(ImageEval, EvalBufferRoundTripsThroughExr) {
    std::filesystem::create_directories(SHREFRACT_TEST_TMP);
    const std::string path = std::string(SHREFRACT_TEST_TMP) + "/roundtrip.exr";
    EvalBuffer a = randomBuffer(17, 9, 3);
    writeEvalBuffer(path, a);
    EvalBuffer b = readEvalBuffer(path);
    ASSERT_EQ(b.width, 17);
    ASSERT_EQ(b.height, 9);
    for (size_t i = 0; i < a.pixelCount(); ++i) {
        EXPECT_EQ(a.color[i], b.color[i]) << i;
        EXPECT_EQ(a.direction[i], b.direction[i]) << i;
    }
}

TEST(ImageEval, IdenticalImagesHaveZeroErrorAndSsimOne) {
    EvalBuffer a = randomBuffer(32, 24, 5);
    nlohmann::json r = compareImages(a, a);
    EXPECT_NEAR(r["angleDeg"]["max"].get<double>(), 0.0, 0.05);  // acos near 1 is ill-conditioned
    EXPECT_EQ(r["coverage"]["mismatch"].get<size_t>(), 0u);
    EXPECT_NEAR(r["ssim"].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(r["psnr"].get<double>(), 99.0);
}

// The flicker measure: 0 for equal frames; one pixel of n changed from black to c reads
// (tm(c).r + tm(c).g + tm(c).b) / 3n, tm the display transform (toneMapAces(0) = 0).
TEST(ImageEval, FlickerMeasureIsTheMeanToneMappedDifference) {
    const size_t n = 40;
    std::vector<float> a(n * 4, 0.0f), b = a;
    EXPECT_EQ(meanAbsToneMappedDifference(a, b), 0.0);
    const glm::vec3 c(0.7f, 2.0f, 0.05f);
    b[4 * 7 + 0] = c.r, b[4 * 7 + 1] = c.g, b[4 * 7 + 2] = c.b;
    const glm::vec3 t = toneMapAces(c, 2.0f);
    EXPECT_NEAR(meanAbsToneMappedDifference(a, b, 2.0f), (t.r + t.g + t.b) / (3.0 * n), 1e-7);
    EXPECT_EQ(meanAbsToneMappedDifference(a, b), meanAbsToneMappedDifference(b, a));
    EXPECT_THROW(meanAbsToneMappedDifference(a, std::vector<float>(8)), std::invalid_argument);
}

TEST(ImageEval, KnownAngleAndCoverageMismatch) {
    EvalBuffer a = randomBuffer(16, 16, 1), b = a;
    for (size_t i = 0; i < a.pixelCount(); ++i)
        if (a.covered(i)) a.direction[i] = {0, 0, 1}, b.direction[i] = {0, std::sin(0.1f), std::cos(0.1f)};
    b.color[1].a = 0.0f;  // covered in a only
    nlohmann::json r = compareImages(a, b);
    EXPECT_NEAR(r["angleDeg"]["median"].get<double>(), 0.1 * 180 / M_PI, 1e-3);
    EXPECT_EQ(r["coverage"]["refOnly"].get<size_t>(), 1u);
    EXPECT_EQ(r["coverage"]["testOnly"].get<size_t>(), 0u);
}

TEST(ImageEval, SsimDropsWithNoiseAndIsSymmetric) {
    const int w = 40, h = 30;
    std::vector<float> a(w * h), b(w * h);
    std::mt19937 rng(9);
    std::normal_distribution<float> n(0.0f, 0.2f);
    for (int i = 0; i < w * h; ++i) a[i] = 0.5f + 0.3f * std::sin(i * 0.1f), b[i] = a[i] + n(rng);
    double s = ssim(a, b, w, h);
    EXPECT_LT(s, 0.9);
    EXPECT_GT(s, 0.0);
    EXPECT_NEAR(s, ssim(b, a, w, h), 1e-12);
}

TEST(ImageEval, IdenticalImagesHaveObjectMetricsOfNoError) {
    EvalBuffer a = randomBuffer(32, 24, 5);
    nlohmann::json r = compareImages(a, a);
    EXPECT_EQ(r["objectPsnr"].get<double>(), 99.0);
    EXPECT_NEAR(r["objectSsim"].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(r["detailRatio"].get<double>(), 1.0);
    EXPECT_EQ(r["objectFlip"].get<double>(), 0.0);
    EXPECT_EQ(r["flip"].get<double>(), 0.0);
}

// The object is the left half; the test differs from the reference only at x >= 30, farther from
// it than any window reaches (SSIM 5, detail blur 6, FLIP's CSF 10 and feature detectors 9 pixels):
// every object metric reads no error, the whole-frame ones do.
TEST(ImageEval, ObjectMetricsSeeOnlyTheObject) {
    EvalBuffer ref = randomBuffer(40, 40, 8), test = ref;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x) {
            const size_t i = size_t(y) * 40 + x;
            ref.color[i].a = test.color[i].a = x < 20 ? 1.0f : 0.0f;
            if (x >= 30) test.color[i] = glm::vec4(glm::vec3(2.0f) - glm::vec3(ref.color[i]), 0.0f);
        }
    nlohmann::json r = compareImages(ref, test);
    EXPECT_EQ(r["objectPsnr"].get<double>(), 99.0);
    EXPECT_NEAR(r["objectSsim"].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(r["detailRatio"].get<double>(), 1.0);
    EXPECT_EQ(r["objectFlip"].get<double>(), 0.0);
    EXPECT_LT(r["psnr"].get<double>(), 30.0);
    EXPECT_LT(r["ssim"].get<double>(), 0.9);
    EXPECT_GT(r["flip"].get<double>(), 0.05);
}

// A 4 x 3 image, the reference covering pixels 1, 5, 6 and 10 (the test others): objectPsnr is
// the PSNR of the tone-mapped RGB over those four alone.
TEST(ImageEval, ObjectPsnrIsThePsnrOverTheReferenceCoverage) {
    EvalBuffer ref = randomBuffer(4, 3, 11), test = randomBuffer(4, 3, 12);
    const std::vector<size_t> mask = {1, 5, 6, 10};
    for (size_t i = 0; i < ref.pixelCount(); ++i) {
        ref.color[i].a = std::count(mask.begin(), mask.end(), i) ? 1.0f : 0.0f;
        test.color[i].a = 1.0f - ref.color[i].a;
    }
    double se = 0;
    for (size_t i : mask) {
        const glm::vec3 d = toneMapAces(glm::vec3(ref.color[i])) - toneMapAces(glm::vec3(test.color[i]));
        se += glm::dot(d, d);
    }
    const double expected = 10.0 * std::log10(1.0 / (se / (3.0 * mask.size())));
    nlohmann::json r = compareImages(ref, test);
    EXPECT_NEAR(r["objectPsnr"].get<double>(), expected, 1e-6);
    EXPECT_NE(r["objectPsnr"].get<double>(), r["psnr"].get<double>());
    EXPECT_TRUE(r["objectSsim"].is_null());  // smaller than one SSIM window
    // No object pixel: the object metrics are undefined.
    for (glm::vec4& c : ref.color) c.a = 0.0f;
    r = compareImages(ref, test);
    for (const char* key : {"objectPsnr", "objectSsim", "detailRatio", "objectFlip"})
        EXPECT_TRUE(r[key].is_null()) << key;
}

TEST(ImageEval, DetailRatioFallsWithBlur) {
    EvalBuffer a = randomBuffer(40, 32, 7);
    EXPECT_EQ(compareImages(a, a)["detailRatio"].get<double>(), 1.0);
    const double blurredRatio = compareImages(a, blurred(a))["detailRatio"].get<double>();
    EXPECT_LT(blurredRatio, 0.9);
    EXPECT_GT(compareImages(blurred(a), a)["detailRatio"].get<double>(), 1.1);  // noisier than the reference
}

// A one-pixel checkerboard of tone-mapped luminance m +- d, and the same blurred by the kernel
// [1/8, 3/4, 1/8] along x and y, which scales the alternating pattern by (3/4 - 2/8)^2 = 1/4:
// m +- d/4. On an alternating pattern the sigma-2 blur is a fixed factor r, so |L - G2 * L| is
// d |1 - r| against d/4 |1 - r|: the detail ratio is 1/4 exactly, on object pixels at least the
// blur's radius (6) from the border.
TEST(ImageEval, DetailRatioOfABlurredCheckerboardIsAQuarter) {
    const int w = 32, h = 24;
    const float m = 0.5f, d = 0.2f;
    EvalBuffer ref, test;
    ref.width = test.width = w, ref.height = test.height = h;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float s = (x + y) % 2 ? 1.0f : -1.0f;
            const bool inside = x >= 6 && y >= 6 && x < w - 6 && y < h - 6;
            ref.color.emplace_back(glm::vec3(greyFor(m + s * d)), inside ? 1.0f : 0.0f);
            test.color.emplace_back(glm::vec3(greyFor(m + s * d / 4)), 1.0f);
            ref.direction.emplace_back(0, 0, 1), test.direction.emplace_back(0, 0, 1);
        }
    EXPECT_NEAR(compareImages(ref, test)["detailRatio"].get<double>(), 0.25, 1e-3);
}

TEST(ImageEval, FlipHeatMapColoursEveryPixelAndAddsALegend) {
    EvalBuffer a = randomBuffer(24, 16, 2);
    Image8 same = flipHeatMap(a, a);
    ASSERT_EQ(same.width, 24);
    ASSERT_EQ(same.height, 16 + 24);
    const glm::u8vec3 zero = errorColor(0.0f, 1.0f);
    for (int i = 0; i < 24 * 16; ++i)
        ASSERT_EQ(glm::u8vec3(same.rgb[3 * i], same.rgb[3 * i + 1], same.rgb[3 * i + 2]), zero) << i;
    Image8 diff = flipHeatMap(a, blurred(a));
    EXPECT_NE(std::vector<uint8_t>(diff.rgb.begin(), diff.rgb.begin() + 24 * 16 * 3),
              std::vector<uint8_t>(same.rgb.begin(), same.rgb.begin() + 24 * 16 * 3));
}

// The reference camera is glm's: the ray through a pixel centre projects back onto it.
// Dispersion's composition: channel c from buffer c, coverage and directions from green.
TEST(Reference, ComposeChannelsTakesEachChannelFromItsBuffer) {
    const EvalBuffer r = randomBuffer(7, 5, 1), g = randomBuffer(7, 5, 2), b = randomBuffer(7, 5, 3);
    const EvalBuffer c = composeChannels(r, g, b);
    ASSERT_EQ(c.pixelCount(), g.pixelCount());
    for (size_t i = 0; i < c.pixelCount(); ++i) {
        EXPECT_EQ(c.color[i], glm::vec4(r.color[i].r, g.color[i].g, b.color[i].b, g.color[i].a));
        EXPECT_EQ(c.direction[i], g.direction[i]);
    }
    EXPECT_THROW(composeChannels(r, g, randomBuffer(5, 7, 3)), std::invalid_argument);
}

TEST(Reference, PrimaryRayHitsThePixelCentreUnderTheGlProjection) {
    ReferenceView v;
    v.eye = {1.0f, 0.7f, 2.5f}, v.target = {0.1f, -0.2f, 0.0f}, v.fovDegrees = 40.0f;
    v.width = 64, v.height = 48;
    const glm::mat4 vp = glm::perspective(glm::radians(v.fovDegrees), 64.0f / 48.0f, 0.01f, 1000.0f) *
                         glm::lookAt(v.eye, v.target, v.up);
    for (glm::ivec2 px : {glm::ivec2(0, 0), glm::ivec2(63, 47), glm::ivec2(10, 30), glm::ivec2(32, 24)}) {
        glm::vec4 c = vp * glm::vec4(v.eye + 2.0f * primaryRay(v, px.x, px.y), 1.0f);
        // GL window coordinates: y up; the renderers store row 0 at the top.
        float wx = (c.x / c.w * 0.5f + 0.5f) * v.width, wy = (c.y / c.w * 0.5f + 0.5f) * v.height;
        EXPECT_NEAR(wx, px.x + 0.5f, 1e-3f);
        EXPECT_NEAR(v.height - wy, px.y + 0.5f, 1e-3f);
    }
}

// Stratified sampling: with spp = n^2 every one of the n x n cells of the pixel gets exactly one
// sample, inside it; the pattern is deterministic and differs between pixels.
TEST(Reference, PixelSamplesCoverEveryStratumOnce) {
    for (int spp : {4, 16, 64}) {
        const int n = int(std::lround(std::sqrt(spp)));
        std::vector<int> hits(spp, 0);
        for (int s = 0; s < spp; ++s) {
            const glm::vec2 o = pixelSample(7, 3, s, spp);
            ASSERT_TRUE(o.x >= 0.0f && o.x < 1.0f && o.y >= 0.0f && o.y < 1.0f) << o.x << " " << o.y;
            ++hits[int(o.y * n) * n + int(o.x * n)];
            EXPECT_EQ(o, pixelSample(7, 3, s, spp));
        }
        for (int c = 0; c < spp; ++c) EXPECT_EQ(hits[c], 1) << "spp " << spp << " cell " << c;
        EXPECT_NE(pixelSample(7, 3, 0, spp), pixelSample(8, 3, 0, spp));
    }
}

// More samples per pixel converge to the pixel integral: against a 256-spp render of the glass
// icosphere, the colour error falls at every step 1 -> 4 -> 16 -> 64 spp, while the direction
// buffer and coverage stay those of the pixel centre (the 1-spp truth the angular error uses).
TEST(Reference, SupersamplingConvergesAndKeepsTheCentreDirections) {
    const Scene scene = loadScene(std::string(SHREFRACT_DATA_DIR) + "/scenes/icosphere.off");
    const Tracer tracer(scene);
    const ReferenceEnvironment env(loadLatLong(std::string(SHREFRACT_DATA_DIR) + "/envmaps/city.exr"));
    ReferenceView v;
    v.eye = {1.2f, 0.8f, 2.6f}, v.width = 40, v.height = 32;
    auto render = [&](int spp) {
        v.spp = spp;
        return renderReference(tracer, env, v);
    };
    const EvalBuffer truth = render(256), one = render(1);
    double last = 1e30;
    for (int spp : {1, 4, 16, 64}) {
        const EvalBuffer b = render(spp);
        double err = 0;
        for (size_t i = 0; i < b.pixelCount(); ++i) {
            err += glm::length(glm::vec3(b.color[i]) - glm::vec3(truth.color[i]));
            EXPECT_EQ(b.direction[i], one.direction[i]) << "pixel " << i;
            EXPECT_EQ(b.color[i].a, one.color[i].a) << "pixel " << i;
        }
        std::printf("[ measured ] spp %2d: mean |colour - 256 spp| = %.4f\n", spp, err / b.pixelCount());
        EXPECT_LT(err, last) << "spp " << spp;
        last = err;
    }
}

TEST(LatLong, BilinearLookupMatchesTexelCentres) {
    // 4 x 2 image, texel (x, y) = x + 10 y: at a texel centre the lookup returns that texel.
    LatLongImage img;
    img.width = 4, img.height = 2;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 3; ++c) img.rgb.push_back(float(x + 10 * y));
    // Texel (1, 0): u = 1.5 / 4, v = 0.5 / 2 -> phi = 2 pi (u - 0.5), theta = pi v.
    float phi = 2.0f * float(M_PI) * (1.5f / 4 - 0.5f), theta = float(M_PI) * 0.25f;
    glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
    EXPECT_NEAR(sampleLatLong(img, d).x, 1.0f, 1e-4f);
}
