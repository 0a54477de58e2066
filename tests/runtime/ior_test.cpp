// Variable index of refraction at shading time (Refractor::setIor, setIorBracket; paper §5.4,
// runtime/src/ior.h). Held to what the interpolation must reproduce exactly at its ends: at the
// bake's own index the plain shading, at index 1 the straight path (the primary ray itself),
// at either bake's index of a bracket that bake's plain shading; each channel independently.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "support/headless.h"
#include "bake_data.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "test_bake.h"

namespace shrefract {
namespace {

constexpr int kSize = 48;

// A lat-long environment that varies in every direction, so a wrong exit shows in the colour.
Environment gradientEnvironment() {
    const int w = 64, h = 32;
    std::vector<float> rgb(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &rgb[(size_t(y) * w + x) * 3];
            p[0] = 0.2f + float(x) / w, p[1] = 0.2f + float(y) / h, p[2] = 0.5f + 0.5f * std::sin(0.3f * x + 0.2f * y);
        }
    return Environment::fromLatLong(w, h, rgb);
}

// Both interpolation paths: rho (the paper's refraction map) and direct (D per vertex).
class IorTest : public test::EglTest<kSize, ::testing::TestWithParam<const char*>> {
protected:
    std::unique_ptr<Refractor> refractor(const BakeData& d) {
        RefractorOptions o;
        o.loader = context_->loader();
        o.path = parseName<RefractorPath>(GetParam());
        auto r = Refractor::create(makeBake(d), o);
        EXPECT_EQ(nameOf(r->path()), std::string(GetParam()));
        return r;
    }
    RenderedFrame render(Refractor& r) {
        if (!env_) env_ = std::make_unique<Environment>(gradientEnvironment());  // this context's
        return renderFrame(r, *env_, camera_, kSize, kSize);
    }
    Camera camera_ = Camera::orbit(35, 25, 3.0f);
    std::unique_ptr<Environment> env_;
    void TearDown() override { env_.reset(); }
};

// max |a - b| over the covered pixels, channel c of the colour (c = 3: the direction buffer).
float maxDifference(const RenderedFrame& a, const RenderedFrame& b, int c, size_t* covered = nullptr) {
    float worst = 0;
    size_t n = 0;
    for (size_t i = 0; i < size_t(kSize) * kSize; ++i) {
        if (a.directions[4 * i + 3] < 0.5f) continue;
        ++n;
        if (c < 3) {
            worst = std::max(worst, std::abs(a.color[4 * i + c] - b.color[4 * i + c]));
        } else {
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(a.directions[4 * i + k] - b.directions[4 * i + k]));
        }
    }
    if (covered) *covered = n;
    return worst;
}

TEST_P(IorTest, AtTheBakesOwnIndexItIsThePlainShading) {
    BakeData d = test::randomBake(4, 3);
    auto r = refractor(d);
    RenderedFrame plain = render(*r);
    r->setIor(glm::vec3(1.5f));  // the manifest's media[0].ior
    RenderedFrame same = render(*r);
    size_t covered = 0;
    for (int c = 0; c < 4; ++c) EXPECT_LT(maxDifference(plain, same, c, &covered), 1e-5f) << c;
    EXPECT_GT(covered, 200u);
    r->resetIor();
    EXPECT_EQ(maxDifference(plain, render(*r), 0), 0.0f);
}

// Index 1 bends nothing: every exit is the primary ray through the pixel centre.
TEST_P(IorTest, AtIndexOneTheExitIsTheStraightPath) {
    BakeData d = test::randomBake(4, 3);
    auto r = refractor(d);
    r->setIor(glm::vec3(1.0f));
    RenderedFrame f = render(*r);
    const glm::mat4 view = viewMatrix(camera_), proj = projectionMatrix(camera_, kSize, kSize);
    float worst = 0;
    size_t covered = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const size_t i = size_t(y) * kSize + x;
            if (f.directions[4 * i + 3] < 0.5f) continue;
            ++covered;
            // Row 0 is the top; GL's window y runs up.
            glm::vec3 far = glm::unProject(glm::vec3(x + 0.5f, kSize - y - 0.5f, 1.0f), view, proj,
                                           glm::vec4(0, 0, kSize, kSize));
            glm::vec3 ray = glm::normalize(far - camera_.eye);
            glm::vec3 exit(f.directions[4 * i], f.directions[4 * i + 1], f.directions[4 * i + 2]);
            worst = std::max(worst, glm::length(exit - ray));
        }
    std::printf("  index 1: max |exit - primary ray| = %.3g over %zu pixels\n", worst, covered);
    EXPECT_GT(covered, 200u);
    // The fragment's interpolated position against the exact pixel centre: measured 1.6e-6
    // (llvmpipe); a wrong weight (e.g. t = 0.1) is off by 1e-2 and more.
    EXPECT_LT(worst, 1e-4f);
}

// Dispersion: each channel is shaded at its own index, independently of the others.
TEST_P(IorTest, EachChannelIsShadedAtItsOwnIndex) {
    BakeData d = test::randomBake(4, 3);
    auto r = refractor(d);
    r->setIor(glm::vec3(1.5f));
    RenderedFrame at15 = render(*r);
    r->setIor(glm::vec3(1.2f));
    RenderedFrame at12 = render(*r);
    r->setIor(glm::vec3(1.2f, 1.5f, 1.2f));
    RenderedFrame mixed = render(*r);
    EXPECT_LT(maxDifference(at12, mixed, 0), 1e-5f);
    EXPECT_LT(maxDifference(at15, mixed, 1), 1e-5f);
    EXPECT_LT(maxDifference(at12, mixed, 2), 1e-5f);
    EXPECT_LT(maxDifference(at15, mixed, 3), 1e-5f);  // the direction buffer is green's
    EXPECT_GT(maxDifference(at12, at15, 0), 1e-2f);  // the indices do differ in the image
}

// Two bakes: at either bake's index, that bake's own shading.
TEST_P(IorTest, BracketEndsAreTheTwoBakes) {
    BakeData a = test::randomBake(4, 3, 7), b = test::randomBake(4, 3, 11);
    b.manifest["media"][0]["ior"] = 1.7;
    auto ra = refractor(a), rb = refractor(b);
    RenderedFrame plainA = render(*ra), plainB = render(*rb);
    ra->setIorBracket(rb.get());
    ra->setIor(glm::vec3(1.5f));
    RenderedFrame atA = render(*ra);
    ra->setIor(glm::vec3(1.7f));
    RenderedFrame atB = render(*ra);
    for (int c = 0; c < 4; ++c) {
        EXPECT_LT(maxDifference(plainA, atA, c), 1e-5f) << c;
        EXPECT_LT(maxDifference(plainB, atB, c), 1e-5f) << c;
    }
    EXPECT_GT(maxDifference(plainA, plainB, 3), 0.1f);  // the two bakes differ
    ra->setIorBracket(nullptr);
}

TEST_P(IorTest, BracketMustShareTheLayoutAndDifferInIndex) {
    BakeData a = test::randomBake(4, 3, 7), other = test::randomBake(4, 2, 11), same = test::randomBake(4, 3, 11);
    other.manifest["media"][0]["ior"] = 1.7;
    auto ra = refractor(a), rOther = refractor(other), rSame = refractor(same);
    EXPECT_THROW(ra->setIorBracket(rOther.get()), std::invalid_argument);  // rate 2 vs 3
    EXPECT_THROW(ra->setIorBracket(rSame.get()), std::invalid_argument);   // both at 1.5
    EXPECT_THROW(ra->setIor(glm::vec3(0.9f, 1.5f, 1.5f)), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(Paths, IorTest, ::testing::Values("direct", "rho"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace shrefract
