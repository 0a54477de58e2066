// The GL pipeline against the CPU decompressor (common/decompress.h), on both headless
// backends: EGL surfaceless and OSMesa (Mesa llvmpipe; no GPU needed).
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "bake_data.h"
#include "common/error.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "support/headless.h"
#include "test_bake.h"

namespace shrefract {
namespace {

class GlTest : public test::HeadlessTest {
protected:
    std::unique_ptr<Refractor> refractor(const Bake& bake, const std::string& preset = "modern") {
        RefractorOptions o;
        o.preset = parseName<ShaderPreset>(preset);
        o.loader = context_->loader();
        return Refractor::create(bake, o);
    }
};

TEST_P(GlTest, DecompressionEqualsCpuAtEveryMuSample) {
    for (int order : {2, 4, 8}) {
        BakeData data = test::randomBake(order, 3);
        Bake bake = makeBake(data);
        for (const char* preset : {"modern", "2006"}) {
            auto r = refractor(bake, preset);
            for (glm::vec3 eye : {glm::vec3(0.3f, 0.8f, 3.0f), glm::vec3(-2.5f, -1.0f, 0.4f)}) {
                float err = test::worstAgainstCpu(*r, data, eye, order);
                std::printf("[%s] order %d preset %s passes %d: max |GL - CPU| = %.3g\n",
                            nameOf(GetParam()), order, preset, r->passCount(), err);
                EXPECT_LT(err, 1e-4f) << preset << " order " << order;
            }
            // Progressive decompression: a lower order on the fly.
            r->setOrder(1);
            EXPECT_EQ(r->order(), 1);
            EXPECT_LT(test::worstAgainstCpu(*r, data, glm::vec3(1, 2, 2), 1), 1e-4f);
            // -1 means every band, as RefractorOptions::order = -1 does; above the stored order
            // clamps to it; below -1 is refused.
            r->setOrder(-1);
            EXPECT_EQ(r->order(), order);
            EXPECT_EQ(refractor(bake, preset)->order(), order);
            r->setOrder(order + 3);
            EXPECT_EQ(r->order(), order);
            EXPECT_THROW(r->setOrder(-2), std::invalid_argument);
        }
    }
}

// Texel-space position of barycentric (u, v) on triangle t (texel centres at integer + 0.5).
glm::vec2 rhoPoint(const SurfaceLayout& L, int t, float u, float v) {
    glm::vec2 o = glm::vec2(L.rhoTexel(t, 0, 0));
    glm::vec2 di = glm::vec2(L.rhoTexel(t, 1, 0)) - o, dj = glm::vec2(L.rhoTexel(t, 0, 1)) - o;
    return o + u * L.rate * di + v * L.rate * dj + 0.5f;
}

// What GL_LINEAR returns at texel-space point p, in exact arithmetic.
glm::vec4 bilinear(const std::vector<float>& img, int w, int h, glm::vec2 p) {
    glm::vec2 x = p - 0.5f;
    glm::ivec2 x0 = glm::ivec2(glm::floor(x));
    glm::vec2 f = x - glm::vec2(x0);
    auto at = [&](int i, int j) {
        i = std::clamp(i, 0, w - 1);
        j = std::clamp(j, 0, h - 1);
        const float* q = &img[(static_cast<size_t>(j) * w + i) * 4];
        return glm::vec4(q[0], q[1], q[2], q[3]);
    };
    glm::vec4 r(0.0f);
    if ((1 - f.x) * (1 - f.y) > 0) r += (1 - f.x) * (1 - f.y) * at(x0.x, x0.y);
    if (f.x * (1 - f.y) > 0) r += f.x * (1 - f.y) * at(x0.x + 1, x0.y);
    if ((1 - f.x) * f.y > 0) r += (1 - f.x) * f.y * at(x0.x, x0.y + 1);
    if (f.x * f.y > 0) r += f.x * f.y * at(x0.x + 1, x0.y + 1);
    return r;
}

struct SeamErrors {
    float seam = 0;     // max difference across shared edges
    float vsCpu = 0;    // max difference to interpolateRho with the GL D_mu
};

SeamErrors seamErrors(Refractor& r, const SurfaceLayout& L) {
    std::vector<float> rho = r.readRefractionMap();
    std::vector<float> dmu = r.readDirectionalMap();
    std::vector<glm::vec4> D(L.sampleCount());
    for (size_t i = 0; i < D.size(); ++i)
        D[i] = {dmu[4 * i], dmu[4 * i + 1], dmu[4 * i + 2], dmu[4 * i + 3]};
    const glm::vec2 cornerUV[3] = {{0, 0}, {1, 0}, {0, 1}};
    // Edges by their corner samples: (a, b) -> (triangle, corner index of a, of b).
    std::map<std::pair<uint32_t, uint32_t>, std::vector<std::array<int, 3>>> edges;
    const int rr = L.rate;
    for (int t = 0; t < L.triangleCount; ++t) {
        uint32_t c[3] = {L.sampleAt(t, 0, 0), L.sampleAt(t, rr, 0), L.sampleAt(t, 0, rr)};
        for (int e = 0; e < 3; ++e) {
            int a = e, b = (e + 1) % 3;
            if (c[a] > c[b]) std::swap(a, b);
            edges[{c[a], c[b]}].push_back({t, a, b});
        }
    }
    SeamErrors out;
    int shared = 0;
    for (const auto& [key, list] : edges) {
        if (list.size() != 2) continue;
        ++shared;
        for (float s = 0.0f; s <= 1.0f; s += 1.0f / 64) {
            glm::vec4 v[2];
            for (int side = 0; side < 2; ++side) {
                auto [t, a, b] = list[side];
                glm::vec2 uv = (1 - s) * cornerUV[a] + s * cornerUV[b];
                v[side] = bilinear(rho, L.rhoWidth, L.rhoHeight, rhoPoint(L, t, uv.x, uv.y));
                glm::vec4 cpu = interpolateRho(L, D.data(), t, uv.x, uv.y);
                for (int c = 0; c < 4; ++c) out.vsCpu = std::max(out.vsCpu, std::abs(v[side][c] - cpu[c]));
            }
            for (int c = 0; c < 4; ++c) out.seam = std::max(out.seam, std::abs(v[0][c] - v[1][c]));
        }
    }
    EXPECT_GT(shared, 0);
    return out;
}

TEST_P(GlTest, RhoIsSeamlessWithCorrectionOnly) {
    for (int rate : {1, 2, 4}) {
        BakeData data = test::randomBake(3, rate);
        Bake bake = makeBake(data);
        auto r = refractor(bake);
        r->update(FrameView::fromEye({0.5f, 1.0f, 2.5f}));
        SeamErrors on = seamErrors(*r, data.layout);
        r->setCorrection(false);
        r->update(FrameView::fromEye({0.5f, 1.0f, 2.5f}));
        SeamErrors off = seamErrors(*r, data.layout);
        std::printf("[%s] rate %d: seam error with correction %.3g, without %.3g; "
                    "vs interpolateRho %.3g\n",
                    nameOf(GetParam()), rate, on.seam, off.seam, on.vsCpu);
        EXPECT_LT(on.seam, 1e-5f);
        EXPECT_LT(on.vsCpu, 1e-5f);
        EXPECT_GT(off.seam, 1e-2f);
    }
}

TEST_P(GlTest, SmoothingAveragesNeighbours) {
    BakeData data = test::randomBake(2, 2);
    Bake bake = makeBake(data);
    auto r = refractor(bake);
    glm::vec3 eye(1, 1, 2);
    r->update(FrameView::fromEye(eye));
    std::vector<float> raw = r->readDirectionalMap();
    r->setSmoothing(true);
    r->update(FrameView::fromEye(eye));
    std::vector<float> smooth = r->readDirectionalMap();
    const SurfaceLayout& L = data.layout;
    float worst = 0;
    for (int i = 0; i < L.sampleCount(); ++i) {
        for (int c = 0; c < 4; ++c) {
            double s = 0;
            for (uint32_t j = 0; j < L.neighbourCount[i]; ++j) {
                uint32_t e = L.neighbourOffset[i] + j;
                s += L.neighbourWeight[e] * raw[4 * L.neighbourIndex[e] + c];
            }
            worst = std::max(worst, float(std::abs(s - smooth[4 * i + c])));
        }
    }
    EXPECT_LT(worst, 1e-4f);
}

std::vector<float> testSky(int w, int h) {
    std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
            p[0] = 0.2f + 2.0f * float(x) / w;          // varies with azimuth
            p[1] = 0.2f + 1.0f * float(h - y) / h;      // brighter up
            p[2] = ((x / 8 + y / 8) % 2) ? 1.0f : 0.1f;  // checker
        }
    return rgb;
}

TEST_P(GlTest, RenderIsDeterministicCoversTheObjectAndFinite) {
    BakeData data = test::randomBake(4, 3);
    Bake bake = makeBake(data);
    Environment env = Environment::fromLatLong(64, 32, testSky(64, 32));
    auto r = refractor(bake);
    Camera cam = Camera::orbit(30, 20, 3.5f);
    RenderedFrame a = renderFrame(*r, env, cam, 96, 96);
    RenderedFrame b = renderFrame(*r, env, cam, 96, 96);
    EXPECT_EQ(a.color, b.color);
    EXPECT_EQ(a.directions, b.directions);
    size_t covered = 0, nonFinite = 0;
    for (size_t i = 0; i < a.color.size(); ++i) nonFinite += !std::isfinite(a.color[i]);
    for (size_t i = 0; i < a.directions.size(); ++i) nonFinite += !std::isfinite(a.directions[i]);
    for (size_t i = 3; i < a.directions.size(); i += 4) covered += a.directions[i] > 0.5f;
    double coverage = double(covered) / (96 * 96);
    std::printf("[%s] coverage %.3f; GPU ms view %.3f decompress %.3f unpack %.3f shade %.3f\n",
                nameOf(GetParam()), coverage, a.timings.view, a.timings.decompress,
                a.timings.unpack, a.timings.shade);
    EXPECT_EQ(nonFinite, 0u);
    EXPECT_GT(coverage, 0.15);
    EXPECT_LT(coverage, 0.9);
    // Covered pixels carry unit directions.
    for (size_t i = 0; i < a.directions.size(); i += 4)
        if (a.directions[i + 3] > 0.5f)
            ASSERT_NEAR(glm::length(glm::vec3(a.directions[i], a.directions[i + 1], a.directions[i + 2])),
                        1.0f, 1e-3f);
}

INSTANTIATE_TEST_SUITE_P(Backends, GlTest, ::testing::Values(Backend::Egl, Backend::OSMesa),
                         [](const auto& info) { return std::string(nameOf(info.param)); });

}  // namespace
}  // namespace shrefract

namespace shrefract {
namespace {

// f16 and u8 bakes go to the GPU as RGBA16F: half the weight memory, and the decompression
// stays within half precision of the CPU's float sum (random weights in [-1, 1] at order 8:
// each weight rounds by at most 2^-11 relative, 45 terms with |y| up to ~1.3: bound 0.05;
// measured 5.7e-4 on both backends).
TEST_P(GlTest, HalfPrecisionBakesUseHalfTheWeightMemory) {
    BakeData data = test::randomBake(8, 2);
    const std::vector<float> weights = data.weights;
    Bake full = makeBake(data);
    data.precision = Precision::F16;
    Bake half = makeBake(data);
    auto r32 = refractor(full), r16 = refractor(half);
    EXPECT_EQ(r16->memory().weights * 2, r32->memory().weights);
    const glm::vec3 eye(0.3f, 0.8f, 3.0f);
    float err = test::worstAgainstCpu(*r16, data, eye, 8);
    std::printf("[%s] RGBA16F weights: max |GL - CPU| = %.3g\n", nameOf(GetParam()), err);
    EXPECT_LT(err, 0.05f);
    EXPECT_GT(err, 1e-6f);  // it really is half precision, not float
}

}  // namespace
}  // namespace shrefract
