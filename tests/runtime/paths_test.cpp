// The runtime's interpolation paths, weight formats and spread shading (docs/runtime.md), on both
// headless backends: the direct path against the paper's rho path, vertex against texture-space
// decompression, 8-bit weights against the CPU decompressor, and the spread lookup against its
// CPU twin (common/prefilter.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "bake_data.h"
#include "common/error.h"
#include "common/latlong.h"
#include "common/prefilter.h"
#include "common/sh.h"
#include "support/frame_mask.h"
#include "support/headless.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "test_bake.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

std::vector<float> sky(int w, int h) {
    std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
            p[0] = 0.2f + 2.0f * float(x) / w;
            p[1] = 0.2f + 1.0f * float(h - y) / h;
            p[2] = ((x / 8 + y / 8) % 2) ? 1.0f : 0.1f;
        }
    return rgb;
}

class Paths : public test::HeadlessTest {
protected:
    std::unique_ptr<Refractor> make(const Bake& bake, const std::string& path,
                                    const std::string& decompression = "auto",
                                    const std::string& shading = "sharp") {
        RefractorOptions o;
        o.path = parseName<RefractorPath>(path);
        o.decompression = parseName<DecompressionSite>(decompression);
        o.shading = parseName<Shading>(shading);
        o.loader = context_->loader();
        return Refractor::create(bake, o);
    }
};

// Largest angle (degrees) between two frames' exit directions over the pixels both cover, and
// how many pixels one covers and the other not.
struct Compared {
    double maxDeg = 0, meanDeg = 0;
    size_t both = 0, mismatch = 0;
};
Compared compareDirections(const RenderedFrame& a, const RenderedFrame& b) {
    Compared c;
    double sum = 0;
    for (size_t i = 0; i < a.directions.size(); i += 4) {
        const bool ca = a.directions[i + 3] > 0.5f, cb = b.directions[i + 3] > 0.5f;
        if (ca != cb) ++c.mismatch;
        if (!ca || !cb) continue;
        const glm::vec3 da(a.directions[i], a.directions[i + 1], a.directions[i + 2]);
        const glm::vec3 db(b.directions[i], b.directions[i + 1], b.directions[i + 2]);
        const double deg = std::acos(std::clamp(double(glm::dot(da, db)), -1.0, 1.0)) * 180.0 / M_PI;
        c.maxDeg = std::max(c.maxDeg, deg);
        sum += deg;
        ++c.both;
    }
    c.meanDeg = c.both ? sum / c.both : 0;
    return c;
}

// The refined mesh interpolated by the rasterizer and rho interpolated by bilinear filtering with
// correction texels (paper §5.3.1) are the same barycentric interpolation at rate 1, where every
// triangle is one corrected cell: the same exit direction per pixel, up to float rounding and the
// texture unit's sub-texel weights (8 bits in llvmpipe). Measured on both backends, order 4,
// 96 x 96, two views (about 2000 and 3200 pixels): direct vs rho max 0.028 deg, mean 0.0003 deg;
// vertex vs texture decompression max 0.028 deg (the same float math in two shader stages; the
// random weights make some D short, where rounding turns the direction most). Limits 0.1 deg
// max, 0.002 deg mean, no coverage difference beyond 1%. At rate 3 the paths
// differ by design: rho is bilinear inside the cells that lie wholly in a triangle (the paper
// keeps plain bilinear filtering there), the direct path piecewise linear on their two halves.
TEST_P(Paths, DirectAndRhoGiveTheSameExitDirections) {
    Environment env = Environment::fromLatLong(64, 32, sky(64, 32));
    for (int rate : {1, 3}) {
        Bake bake = makeBake(test::randomBake(4, rate));
        for (const Camera& cam : {Camera::orbit(30, 20, 3.5f), Camera::orbit(200, -35, 2.8f)}) {
            auto rho = make(bake, "rho"), vertex = make(bake, "direct", "vertex"),
                 texture = make(bake, "direct", "texture");
            EXPECT_EQ(rho->path(), RefractorPath::Rho);
            EXPECT_EQ(vertex->decompression(), DecompressionSite::Vertex);
            EXPECT_EQ(texture->decompression(), DecompressionSite::Texture);
            const RenderedFrame fr = renderFrame(*rho, env, cam, 96, 96);
            const RenderedFrame fv = renderFrame(*vertex, env, cam, 96, 96);
            const RenderedFrame ft = renderFrame(*texture, env, cam, 96, 96);
            const Compared vr = compareDirections(fv, fr), tr = compareDirections(ft, fr),
                           vt = compareDirections(fv, ft);
            std::printf("[%s] rate %d: direct/vertex vs rho max %.4f mean %.5f deg over %zu px, mismatch "
                        "%zu; direct/texture vs rho max %.4f; vertex vs texture max %.2g deg\n",
                        nameOf(GetParam()), rate, vr.maxDeg, vr.meanDeg, vr.both, vr.mismatch, tr.maxDeg,
                        vt.maxDeg);
            EXPECT_GT(vr.both, 1000u);
            EXPECT_LT(vt.maxDeg, 0.1);
            EXPECT_LE(vr.mismatch, vr.both / 100);  // silhouette rasterization only
            if (rate != 1) continue;
            EXPECT_LT(vr.maxDeg, 0.1);
            EXPECT_LT(vr.meanDeg, 0.002);
            EXPECT_LT(tr.maxDeg, 0.1);
        }
    }
}

// frameWallMs draws the frames it times into a target of its own: the frames an app renders
// before and after it are bit-identical, it returns a time (a positive, finite median), and it
// refuses to time no frame at all.
TEST_P(Paths, FrameTimingLeavesTheFramesAsTheyWere) {
    Environment env = Environment::fromLatLong(64, 32, sky(64, 32));
    Bake bake = makeBake(test::randomBake(4, 1));
    const Camera cam = Camera::orbit(30, 20, 3.5f);
    auto r = make(bake, "direct");
    const RenderedFrame before = renderFrame(*r, env, cam, 96, 96);
    const double ms = frameWallMs(*r, env, Camera::orbit(120, -20, 3.0f), 64, 64, 3);
    EXPECT_GT(ms, 0.0);
    EXPECT_TRUE(std::isfinite(ms));
    const RenderedFrame after = renderFrame(*r, env, cam, 96, 96);
    EXPECT_EQ(before.directions, after.directions);
    EXPECT_EQ(before.color, after.color);
    EXPECT_THROW(frameWallMs(*r, env, cam, 64, 64, 0), std::invalid_argument);
}

// 8-bit bakes upload their codes as RGBA8 UNORM (4 bytes a texel a coefficient, against 16 for
// float32) and the shader applies the per-coefficient scale and offset: D matches the CPU sum of
// the dequantized weights to float rounding (measured 2.4e-7; limit 1e-4), both ways
// of decompressing.
TEST_P(Paths, EightBitWeightsStayEightBitOnTheGpu) {
    const fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "paths";
    fs::create_directories(dir);
    BakeData data = test::randomBake(8, 2);
    data.precision = Precision::U8;
    writeBake((dir / ("u8_" + std::string(nameOf(GetParam())) + ".shrefract.exr")).string(), data);
    const BakeData read = readBake((dir / ("u8_" + std::string(nameOf(GetParam())) + ".shrefract.exr")).string());
    Bake bake = makeBake(read);
    const glm::vec3 eye(0.3f, 0.8f, 3.0f);
    for (const char* dec : {"vertex", "texture"}) {
        auto r = make(bake, "direct", dec);
        const float worst = test::worstAgainstCpu(*r, read, eye);
        std::printf("[%s] u8 as RGBA8, %s decompression: max |GL - CPU| = %.3g\n", nameOf(GetParam()), dec, worst);
        EXPECT_LT(worst, 1e-4f) << dec;
        const size_t texels = size_t(read.layout.muWidth) * read.layout.muHeight;
        EXPECT_EQ(r->memory().weights, size_t(shEvenCount(8)) * texels * 4);
    }
}

// The grid basis on the GPU (shaders/grid_eval.glsl) against the CPU decompressor
// (DirectionGrid::interpolate): every sample's D for views that put local directions in every
// branch of the interpolation (the pole cap from straight above, the last ring and the mirrored
// lower hemisphere from the side), f32 and u8, vertex and texture decompression and the rho path.
// Measured on both backends: max |GL - CPU| 1.3e-5 (f32 and u8: GL's float atan); limit 1e-4, as
// the SH test's. Planted: the phi weights swapped (s for 1 - s) gives 1.55; the lower hemisphere
// not mirrored (atan(rxy, w.z)) 1.35.
TEST_P(Paths, GridBasisMatchesTheCpuInterpolation) {
    const fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "paths";
    fs::create_directories(dir);
    for (Precision p : {Precision::F32, Precision::U8}) {
        BakeData data = test::randomGridBake(DirectionGrid{8, 16}, 2);
        data.precision = p;
        const std::string path =
            (dir / str("grid_", nameOf(p), "_", nameOf(GetParam()), ".shrefract.exr")).string();
        writeBake(path, data);
        const BakeData read = readBake(path);
        ASSERT_EQ(read.basis, Basis::Grid);
        Bake bake = makeBake(read);
        for (const glm::vec3 eye : {glm::vec3(0.3f, 0.8f, 3.0f), glm::vec3(0.0f, 0.0f, 3.0f),
                                    glm::vec3(3.0f, 0.1f, 0.2f), glm::vec3(-1.2f, -2.5f, -1.0f)}) {
            for (const auto& [pathName, dec] : {std::pair{"direct", "vertex"}, std::pair{"direct", "texture"},
                                                 std::pair{"rho", "auto"}}) {
                auto r = make(bake, pathName, dec);
                const float worst = test::worstAgainstCpu(*r, read, eye);
                std::printf("[%s] grid 8x16 %s, %s %s, eye (%g, %g, %g): max |GL - CPU| = %.3g\n",
                            nameOf(GetParam()), nameOf(p), pathName, dec, eye.x, eye.y, eye.z, worst);
                EXPECT_LT(worst, 1e-4f) << nameOf(p) << " " << pathName << " " << dec;
            }
        }
        const size_t texels = size_t(read.layout.muWidth) * read.layout.muHeight;
        const size_t texelBytes = p == Precision::U8 ? 4 : 16;
        // u8: the weights and the K x 2 RGBA32F dequantization texture.
        EXPECT_EQ(make(bake, "rho")->memory().weights,
                  128 * texels * texelBytes + (p == Precision::U8 ? 128 * 2 * 16 : 0));
    }
}

// What memory() reports, part by part: weights at 16, 8 or 4 bytes a texel a coefficient; the
// direct path with vertex decompression has no rho and no render targets, only an index buffer
// of every triangle's subdivision; rho appears when an app asks for refractionMap().
TEST_P(Paths, MemoryIsReportedPerPart) {
    BakeData data = test::randomBake(4, 3);
    const SurfaceLayout& L = data.layout;
    const size_t texels = size_t(L.muWidth) * L.muHeight, K = size_t(shEvenCount(4));
    auto vertex = make(makeBake(data), "direct", "vertex");
    const GpuMemory& m = vertex->memory();
    EXPECT_EQ(m.weights, K * texels * 16);
    EXPECT_EQ(m.samples, texels * 24);
    EXPECT_EQ(m.rho, 0u);
    EXPECT_EQ(m.targets, 0u);
    EXPECT_EQ(m.mesh, size_t(L.triangleCount) * L.rate * L.rate * 3 * 4);  // r^2 sub-triangles each
    RefractorOptions half;
    half.halfWeights = true;
    half.loader = context_->loader();
    EXPECT_EQ(Refractor::create(makeBake(data), half)->memory().weights, K * texels * 8);
    auto rho = make(makeBake(data), "rho");
    EXPECT_EQ(rho->memory().rho, size_t(L.rhoWidth) * L.rhoHeight * 16);
    EXPECT_EQ(rho->memory().mesh, size_t(L.triangleCount) * 3 * 8 * 4);
    // The direct path builds rho on request, and it is the rho path's map.
    const glm::vec3 eye(0.3f, 0.8f, 3.0f);
    vertex->update(FrameView::fromEye(eye));
    rho->update(FrameView::fromEye(eye));
    const std::vector<float> a = vertex->readRefractionMap(), b = rho->readRefractionMap();
    EXPECT_EQ(vertex->memory().rho, rho->memory().rho);
    ASSERT_EQ(a.size(), b.size());
    float worst = 0;
    for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    EXPECT_LT(worst, 1e-6f);
}

// "auto" decompresses in the vertex shader up to order 1 and in texture space above (the measured
// crossover on llvmpipe, docs/runtime.md); "vertex" asked for holds at any order.
TEST_P(Paths, AutoDecompressionFollowsTheOrder) {
    const Bake high = makeBake(test::randomBake(4, 2));
    EXPECT_EQ(make(high, "direct")->decompression(), DecompressionSite::Texture);
    EXPECT_EQ(make(high, "direct", "vertex")->decompression(), DecompressionSite::Vertex);
    auto r = make(high, "direct");
    r->setOrder(1);
    EXPECT_EQ(r->decompression(), DecompressionSite::Vertex);
}

// Smoothing needs D_mu in texture space: turned on, the vertex-decompressing direct path switches
// to texture-space decompression and the smoothed D reaches the pixels.
TEST_P(Paths, SmoothingSwitchesVertexDecompressionToTextureSpace) {
    Bake bake = makeBake(test::randomBake(1, 2));
    Environment env = Environment::fromLatLong(64, 32, sky(64, 32));
    auto r = make(bake, "direct");
    const Camera cam = Camera::orbit(30, 20, 3.5f);
    EXPECT_EQ(r->decompression(), DecompressionSite::Vertex);
    const RenderedFrame plain = renderFrame(*r, env, cam, 96, 96);
    r->setSmoothing(true);
    EXPECT_EQ(r->decompression(), DecompressionSite::Texture);
    EXPECT_FALSE(r->timingsEnabled());  // off unless asked for: they stall every stage
    r->setTimings(true);
    const RenderedFrame smooth = renderFrame(*r, env, cam, 96, 96);
    EXPECT_GT(r->timings().smooth, 0.0);
    EXPECT_GT(compareDirections(plain, smooth).maxDeg, 1.0);  // smoothing changed the directions
    auto fixed = make(bake, "direct", "vertex");
    EXPECT_THROW(fixed->setSmoothing(true), std::invalid_argument);
}

// Spread shading against its CPU twin. A bake whose every sample maps every view direction to
// the same exit direction e scaled by R (only band 0: w_0 = R e / y_0^0), at IOR 1 (no front
// reflection away from the silhouette) and footprint 0 (the exit direction is constant over the
// screen): every pixel shows the prefiltered environment along e at the level for
// spreadSigma(R). Measured against sampleCubeLod on the CPU: within 2e-3 relative (GL's
// trilinear weights); measured at most 3.7e-4 relative; limit 3e-3.
TEST_P(Paths, SpreadLookupMatchesItsCpuTwin) {
    const int w = 64, h = 32;
    const std::vector<float> rgb = sky(w, h);
    Environment env = Environment::fromLatLong(w, h, rgb);
    const PrefilteredCube cube = prefilterCube(cubeFromLatLong(LatLongImage{w, h, rgb}, env.faceSize()));
    ASSERT_EQ(int(cube.levels.size()), env.levels());
    const glm::vec3 e = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
    const float y00 = 0.282094792f;
    for (float R : {1.0f, 0.97f, 0.8f, 0.4f}) {
        BakeData data = test::randomBake(2, 1);
        data.manifest["media"][0]["ior"] = 1.0;
        data.manifest["media"][0]["absorption"] = {0.0, 0.0, 0.0};
        std::fill(data.weights.begin(), data.weights.end(), 0.0f);
        const size_t n = data.layout.position.size();
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) data.weights[i * 4 + c] = R * e[c] / y00;
        RefractorOptions o;
        o.loader = context_->loader();
        o.shading = Shading::Spread;
        o.footprintScale = 0.0f;
        auto r = Refractor::create(makeBake(data), o);
        const RenderedFrame f = renderFrame(*r, env, Camera::orbit(30, 20, 3.5f), 48, 48);
        const float sigma = spreadSigma(R, o.spreadScale);  // the default width factor
        const glm::vec3 expect = sampleCubeLod(cube, e, lodForSigma(sigma, env.faceSize(), env.levels()));
        double worst = 0;
        size_t covered = 0;
        for (size_t i = 0; i < f.color.size(); i += 4) {
            if (!test::coveredAround(f, int(i / 4 % 48), int(i / 4 / 48))) continue;  // 2 px from the edge
            ++covered;
            for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(f.color[i + c] - expect[c]) / expect[c]));
        }
        std::printf("[%s] R %.2f: lod %.2f, max relative |GL - CPU| %.2g over %zu px\n", nameOf(GetParam()), R,
                    lodForSigma(sigma, env.faceSize(), env.levels()), worst, covered);
        EXPECT_GT(covered, 100u);
        EXPECT_LT(worst, 3e-3) << "R " << R;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, Paths, ::testing::Values(Backend::Egl, Backend::OSMesa),
                         [](const auto& info) { return std::string(nameOf(info.param)); });

}  // namespace
}  // namespace shrefract
