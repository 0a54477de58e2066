// Image metrics, the evaluation EXR layout and the reference camera, against known answers.
#include <gtest/gtest.h>

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
