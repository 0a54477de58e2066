// The isolated-surface pipeline (paper §5.2, Figure 6; runtime/src/chart_pipeline.cpp) on chart
// layouts the bake makes, on both headless backends: decompression of the covered texels
// against the CPU decompressor, the gutters and the refraction map against the CPU twin
// (common/decompress.h), the gutters' width against a brute-force distance, and the seam jump.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "bake_data.h"
#include "bake/chart_layout.h"
#include "common/error.h"
#include "common/sh.h"
#include "gl.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "support/headless.h"
#include "test_bake.h"

namespace shrefract {
namespace {

// Chart layouts of the data objects, built once (CGAL takes a fraction of a second each).
const SurfaceLayout& chartLayout(const std::string& file, LayoutKind kind, size_t samples, int gutter) {
    static std::map<std::string, SurfaceLayout> cache;
    const std::string key = file + nameOf(kind) + std::to_string(samples) + "g" + std::to_string(gutter);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    ChartOptions opt;
    opt.kind = kind;
    opt.samples = samples;
    opt.gutter = gutter;
    const Scene scene = loadScene(std::string(SHREFRACT_DATA_DIR) + "/" + file, Medium{});
    return cache.emplace(key, buildChartLayout(scene, opt)).first->second;
}

class ChartGl : public test::HeadlessTest {
protected:
    std::unique_ptr<Refractor> refractor(const Bake& bake, int gutter = -1, bool seamAware = true,
                                         bool smoothing = false) {
        RefractorOptions o;
        o.loader = context_->loader();
        o.gutter = gutter;
        o.seamAware = seamAware;
        o.smoothing = smoothing;
        return Refractor::create(bake, o);
    }
};

std::vector<glm::vec4> asVec4(const std::vector<float>& v) {
    std::vector<glm::vec4> out(v.size() / 4);
    for (size_t i = 0; i < out.size(); ++i) out[i] = {v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]};
    return out;
}

// D at every covered texel, decompressed at the local view direction the unfolded mesh
// interpolates there, against the CPU at the sample's stored position and normal.
TEST_P(ChartGl, DecompressionEqualsCpuAtEveryCoveredTexel) {
    for (LayoutKind kind : {LayoutKind::Uv, LayoutKind::Isolated}) {
        const BakeData data = test::randomBake(chartLayout("scenes/vase.obj", kind, 3000, 2), 4);
        auto r = refractor(makeBake(data));
        for (glm::vec3 eye : {glm::vec3(0.3f, 0.8f, 3.0f), glm::vec3(-2.5f, -1.0f, 0.4f)}) {
            const float worst = test::worstAgainstCpu(*r, data, eye);
            std::printf("[%s] %s: max |GL - CPU| = %.3g over %d texels\n", nameOf(GetParam()),
                        nameOf(kind), worst, data.layout.sampleCount());
            // Measured 1e-5..4e-5: the view vector interpolated from the vertices in float, where
            // the CPU takes the sample's stored point; a wrong texel would be off by O(1).
            EXPECT_LT(worst, 5e-4f) << nameOf(kind);
        }
    }
}

// The refraction map is the CPU twin's, for every gutter width, with and without seam sources and
// smoothing, fed with the GL D.
TEST_P(ChartGl, RefractionMapEqualsTheCpuTwin) {
    const BakeData data = test::randomBake(chartLayout("scenes/vase.obj", LayoutKind::Isolated, 3000, 2), 2);
    const Bake bake = makeBake(data);
    const glm::vec3 eye(1.0f, 1.5f, 2.5f);
    for (int gutter : {0, 1, 2})
        for (bool seam : {false, true})
            for (bool smooth : {false, true}) {
                auto r = refractor(bake, gutter, seam, smooth);
                r->setSmoothing(false);
                r->update(FrameView::fromEye(eye));
                const std::vector<glm::vec4> D = asVec4(r->readDirectionalMap());
                r->setSmoothing(smooth);
                r->update(FrameView::fromEye(eye));
                ChartMapOptions o;
                o.dilation = gutter, o.seamAware = seam, o.smoothing = smooth;
                const std::vector<glm::vec4> cpu = chartRefractionMap(data.layout, D.data(), o);
                const std::vector<glm::vec4> gl = asVec4(r->readRefractionMap());
                ASSERT_EQ(gl.size(), cpu.size());
                float worst = 0;
                for (size_t t = 0; t < gl.size(); ++t)
                    for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(gl[t][c] - cpu[t][c]));
                EXPECT_LT(worst, 1e-5f) << "gutter " << gutter << " seam " << seam << " smooth " << smooth;
            }
}

// Gutters are filled to the set width: every texel within `width` 8-neighbour steps of a covered
// texel (brute force: the Chebyshev distance to the nearest one) holds a direction, every texel
// farther out holds none.
TEST_P(ChartGl, GuttersAreFilledToTheSetWidth) {
    const BakeData data = test::randomBake(chartLayout("scenes/vase.obj", LayoutKind::Isolated, 3000, 3), 2);
    const SurfaceLayout& L = data.layout;
    std::vector<int> distance(size_t(L.muWidth) * L.muHeight, 1 << 20);
    for (int i = 0; i < L.sampleCount(); ++i) {
        const glm::ivec2 p = L.muTexel(i);
        for (int y = std::max(0, p.y - 4); y <= std::min(L.muHeight - 1, p.y + 4); ++y)
            for (int x = std::max(0, p.x - 4); x <= std::min(L.muWidth - 1, p.x + 4); ++x) {
                int& d = distance[size_t(y) * L.muWidth + x];
                d = std::min(d, std::max(std::abs(x - p.x), std::abs(y - p.y)));
            }
    }
    auto r = refractor(makeBake(data));
    EXPECT_EQ(r->gutter(), 3);  // the bake's
    for (int width : {0, 1, 3}) {
        r->setGutter(width);
        r->update(FrameView::fromEye(glm::vec3(0, 1, 3)));
        const std::vector<glm::vec4> map = asVec4(r->readRefractionMap());
        size_t wrong = 0, ring = 0;
        for (size_t t = 0; t < map.size(); ++t) {
            const bool filled = glm::length(glm::vec3(map[t])) > 0;
            wrong += filled != (distance[t] <= width);
            ring += distance[t] == width;
        }
        EXPECT_EQ(wrong, 0u) << "width " << width;
        EXPECT_GT(ring, 0u);
    }
}

// The seam jump shrinks from no gutter to gutter to seam-aware filling: a refraction field that
// is smooth over the surface (band 0 only: D = (P + c, |P|) whatever the view), looked up on the
// two sides of every smooth seam of the vase's isolated charts. No gutter: an atlas packed without
// gutters, nothing filled; gutter: 2 rings of dilation; seam-aware: the same with the sources.
TEST_P(ChartGl, SeamJumpShrinksFromNoGutterToGutterToSeamAware) {
    auto smoothField = [](const SurfaceLayout& L) {
        BakeData d = test::randomBake(L, 0);
        const float y00 = 0.282094792f;
        for (int i = 0; i < L.sampleCount(); ++i) {
            const glm::vec3 p = L.position[i];
            const glm::vec4 D(p + glm::vec3(0.3f, -0.2f, 0.5f), glm::length(p));
            for (int c = 0; c < 4; ++c) d.weights[size_t(i) * 4 + c] = D[c] / y00;
        }
        return d;
    };
    auto quantile = [](std::vector<double> v, double q) {
        std::nth_element(v.begin(), v.begin() + size_t(q * (v.size() - 1)), v.end());
        return v[size_t(q * (v.size() - 1))];
    };
    const BakeData tight = smoothField(chartLayout("scenes/vase.obj", LayoutKind::Isolated, 8000, 0));
    const BakeData spaced = smoothField(chartLayout("scenes/vase.obj", LayoutKind::Isolated, 8000, 2));
    auto jump = [&](const BakeData& d, int gutter, bool seam, double q) {
        auto r = refractor(makeBake(d), gutter, seam);
        r->update(FrameView::fromEye(glm::vec3(0, 1, 3)));
        return quantile(seamJumps(d.layout, asVec4(r->readRefractionMap())), q);
    };
    const double none = jump(tight, 0, false, 0.5), gutter = jump(spaced, 2, false, 0.5),
                 seamAware = jump(spaced, 2, true, 0.5);
    std::printf("[%s] seam jump, degrees, median (p95): no gutter %.3f (%.3f), gutter %.3f (%.3f), "
                "seam-aware %.3f (%.3f)\n",
                nameOf(GetParam()), none, jump(tight, 0, false, 0.95), gutter,
                jump(spaced, 2, false, 0.95), seamAware, jump(spaced, 2, true, 0.95));
    // Measured: 1.062 (3.45), 1.010 (2.79), 0.156 (1.14). The medians of no gutter and gutter are
    // close: the shading normalizes, so the zeros of unfilled texels do not turn a direction; what
    // no gutter adds is the neighbouring charts' texels, in the tail.
    EXPECT_GT(none, gutter);
    EXPECT_GT(gutter, seamAware);
    EXPECT_LT(seamAware, gutter / 5);
}

// A chart bake renders: the object is covered and every shaded pixel is finite.
TEST_P(ChartGl, RenderCoversTheObject) {
    const BakeData data = test::randomBake(chartLayout("scenes/flat_cube.obj", LayoutKind::Isolated, 2000, 2), 2);
    auto r = refractor(makeBake(data));
    const Environment env = Environment::fromLatLong(2, 1, std::vector<float>(6, 0.5f));
    const RenderedFrame f = renderFrame(*r, env, Camera::orbit(30, 20, 3), 64, 64);
    size_t covered = 0;
    for (size_t i = 0; i < f.directions.size() / 4; ++i) {
        covered += f.directions[4 * i + 3] > 0;
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(f.color[4 * i + c]));
    }
    EXPECT_GT(covered, 64u * 64u / 10);
    EXPECT_EQ(makeBake(data).layout(), "isolated");
    // Chart bakes take their own path; the joining paths are refused for them.
    EXPECT_EQ(r->path(), RefractorPath::Charts);
    RefractorOptions direct;
    direct.loader = context_->loader();
    direct.path = RefractorPath::Direct;
    EXPECT_THROW(Refractor::create(makeBake(data), direct), std::invalid_argument);
}

// The error model on a chart layout shades the charts' footprint once per frame, as the
// decompression passes do: its pass must link with the unfolded mesh's vertex shader. With the
// full-screen triangle's, the mesh's draw call covered the whole atlas again and again (measured:
// 6 atlases a frame on the flat cube; on the bunny, 16 s a frame). Counted by an occlusion query
// over one update, with and without the model.
TEST_P(ChartGl, ErrorFoldShadesTheFootprintOnce) {
    BakeData data = test::randomBake(chartLayout("scenes/flat_cube.obj", LayoutKind::Isolated, 2000, 2), 2);
    const int n = data.layout.sampleCount();
    data.errorOrder = 0;
    data.errors.assign(size_t(n), std::log(0.05f + kErrorOffset) * std::sqrt(4.0f * float(M_PI)));
    const Bake bake = makeBake(data);
    auto fragments = [&](bool errorModel) {
        RefractorOptions o;
        o.loader = context_->loader();
        o.errorModel = errorModel;
        auto r = Refractor::create(bake, o);
        r->update(FrameView::fromEye({0.4f, 0.9f, 2.7f}));  // compiles and warms up
        GLuint query = 0;
        gl::glGenQueries(1, &query);
        gl::glBeginQuery(GL_SAMPLES_PASSED, query);
        r->update(FrameView::fromEye({-0.8f, 0.5f, 2.5f}));
        gl::glEndQuery(GL_SAMPLES_PASSED);
        GLuint64 count = 0;
        gl::glGetQueryObjectui64v(query, GL_QUERY_RESULT, &count);
        gl::glDeleteQueries(1, &query);
        return double(count);
    };
    const double plain = fragments(false), folded = fragments(true);
    const double atlas = double(data.layout.muWidth) * data.layout.muHeight;
    std::printf("[%s] update: %.0f fragments, %.0f with the error model; atlas %.0f texels, %d samples\n",
                nameOf(GetParam()), plain, folded, atlas, n);
    ASSERT_GT(plain, 0.0) << "the query counted nothing";
    // Measured: the fold adds 2166 fragments, one per sample (each covered texel is a sample),
    // against 19044 (6 atlases) with the full-screen vertex shader. Bounds: half the samples, and
    // one atlas (1.5x the footprint here).
    EXPECT_GT(folded - plain, 0.5 * n);
    EXPECT_LE(folded - plain, atlas);
}

INSTANTIATE_TEST_SUITE_P(Backends, ChartGl, ::testing::Values(Backend::Egl, Backend::OSMesa),
                         [](const auto& info) { return std::string(nameOf(info.param)); });

}  // namespace
}  // namespace shrefract
