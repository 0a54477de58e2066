// Chart bakes end to end (paper §5.2, Figure 7; eval/seams.h): the vase baked joining, isolated
// and in its own UVs at about the same sample count, rendered by the runtime and by the Embree
// reference; the per-pixel error of the chart layouts against joining's, the seam pixel pairs,
// and the query tool's chart lookup against the GL refraction map.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>

#include "support/headless.h"
#include "runtime/src/bake_data.h"
#include "bake/bake.h"
#include "common/decompress.h"
#include "common/latlong.h"
#include "common/scene.h"
#include "eval/directions.h"
#include "eval/image_eval.h"
#include "eval/reference.h"
#include "eval/seams.h"
#include "shrefract/context.h"
#include "shrefract/render.h"

using namespace shrefract;

namespace {

constexpr int kSize = 160;

struct Baked {
    Scene scene;
    BakeData data;
    std::unique_ptr<Tracer> tracer;
};

// Order 4, 16 x 32 directions, about 2500 samples: a couple of seconds each on 2 cores.
const Baked& baked(LayoutKind kind, int gutter = 2) {
    static std::map<std::pair<LayoutKind, int>, std::unique_ptr<Baked>> cache;
    auto& slot = cache[{kind, gutter}];
    if (!slot) {
        slot = std::make_unique<Baked>();
        const std::string path = std::string(SHREFRACT_DATA_DIR) + "/scenes/vase.obj";
        slot->scene = loadScene(path);
        BakeOptions o;
        o.order = 4;
        o.grid = DirectionGrid{16, 32};
        o.layout = kind;
        o.rate = kind == LayoutKind::Joining ? 2 : 0;  // 2400 triangles at rate 2: 4898 samples
        o.samples = 4898;
        o.charts.gutter = gutter;
        slot->data = bake(slot->scene, o, path).data;
        slot->tracer = std::make_unique<Tracer>(slot->scene, traceOptionsOfBake(slot->data));
    }
    return *slot;
}

ReferenceView viewOf(const Camera& c) {
    ReferenceView v;
    v.eye = c.eye, v.target = c.target, v.up = c.up, v.fovDegrees = c.fovDegrees;
    v.width = v.height = kSize;
    return v;
}

class ChartsEndToEnd : public test::EglTest<kSize> {
protected:
    void SetUp() override {
        test::EglTest<kSize>::SetUp();
        if (IsSkipped()) return;
        const std::string envPath = std::string(SHREFRACT_DATA_DIR) + "/envmaps/courtyard.exr";
        latLong_ = std::make_unique<ReferenceEnvironment>(loadLatLong(envPath));
        env_ = std::make_unique<Environment>(Environment::fromLatLong(
            latLong_->latLong.width, latLong_->latLong.height, latLong_->latLong.rgb));
    }
    RenderedFrame renderSh(const Baked& b, const Camera& c, int gutter = -1, bool seam = true) {
        RefractorOptions o;
        o.loader = context_->loader();
        o.gutter = gutter;
        o.seamAware = seam;
        auto refractor = Refractor::create(makeBake(b.data), o);
        return renderFrame(*refractor, *env_, c, kSize, kSize);
    }
    EvalBuffer evalOf(const RenderedFrame& f) { return makeEvalBuffer(kSize, kSize, f.color, f.directions); }
    std::unique_ptr<ReferenceEnvironment> latLong_;
    std::unique_ptr<Environment> env_;
};

double median(const nlohmann::json& r) { return r["angleDeg"]["median"].get<double>(); }

}  // namespace

// At (about) equal sample counts the chart layouts come as close to the reference as joining.
// Measured (160 x 160, two views): joining median 7.53 / 4.19 deg, isolated 7.50 / 4.19, uv
// 7.13 / 4.30. Threshold: within 10 % of joining's, the goal.
TEST_F(ChartsEndToEnd, ChartLayoutsMatchTheReferenceAsWellAsJoining) {
    for (glm::vec3 view : {glm::vec3(30, 20, 2.2), glm::vec3(200, -15, 2.0)}) {
        const Camera c = Camera::orbit(view.x, view.y, view.z);
        const EvalBuffer ref = renderReference(*baked(LayoutKind::Joining).tracer, *latLong_, viewOf(c));
        const double joining = median(compareImages(ref, evalOf(renderSh(baked(LayoutKind::Joining), c))));
        for (LayoutKind kind : {LayoutKind::Isolated, LayoutKind::Uv}) {
            const Baked& b = baked(kind);
            EXPECT_GE(b.data.layout.sampleCount(), 4898);
            const double m = median(compareImages(ref, evalOf(renderSh(b, c))));
            std::printf("  view %g,%g: median joining %.3f, %s %.3f deg (%d samples)\n", view.x,
                        view.y, joining, nameOf(kind), m, b.data.layout.sampleCount());
            EXPECT_LT(m, 1.1 * joining) << nameOf(kind);
        }
    }
}

// The pixel pairs straddling the isolated vase's smooth seams: in the reference (no seam) their
// jump is the field's own change over one pixel; the chart render without gutters jumps more,
// seam-aware filling less. Measured: 335 pairs, median jump reference 1.24, no gutter 5.69,
// gutter 5.30, seam-aware 2.87 deg.
TEST_F(ChartsEndToEnd, SeamPixelPairsSeeTheSeams) {
    const Camera c = Camera::orbit(30, 20, 2.2);
    const Baked& spaced = baked(LayoutKind::Isolated, 2);
    const auto pairs = seamPixelPairs(*spaced.tracer, spaced.data.layout, viewOf(c));
    const EvalBuffer ref = renderReference(*spaced.tracer, *latLong_, viewOf(c));
    std::vector<float> refDirections;
    for (size_t i = 0; i < ref.pixelCount(); ++i)
        refDirections.insert(refDirections.end(), {ref.direction[i].x, ref.direction[i].y,
                                                   ref.direction[i].z, ref.color[i].a});
    auto jump = [&](const std::vector<float>& d) {
        return jumpStats(pairs, pairJumps(d, pairs))["median"].get<double>();
    };
    const double truth = jump(refDirections);
    const double none = jump(renderSh(baked(LayoutKind::Isolated, 0), c, 0).directions);
    const double gutter = jump(renderSh(spaced, c, 2, false).directions);
    const double seamAware = jump(renderSh(spaced, c, 2, true).directions);
    std::printf("  %zu pairs; median jump: reference %.3f, no gutter %.3f, gutter %.3f, seam-aware %.3f deg\n",
                pairs.size(), truth, none, gutter, seamAware);
    EXPECT_GT(pairs.size(), 100u);
    EXPECT_LT(truth, 2.0);  // adjacent pixels on a smooth surface
    EXPECT_GT(none, truth);
    EXPECT_LT(seamAware, gutter);
    // Each pair is two 4-adjacent pixels.
    for (const PixelPair& p : pairs) {
        const int dx = std::abs(p.a % kSize - p.b % kSize), dy = std::abs(p.a / kSize - p.b / kSize);
        ASSERT_EQ(dx + dy, 1);
    }
}

// shrefract-eval query on a chart bake gives the runtime's refraction map at the point's UV: a
// viewer 10^5 away sees every texel from (almost) the same direction.
TEST_F(ChartsEndToEnd, QueryReadsTheChartMapAsTheRuntimeBuildsIt) {
    const Baked& b = baked(LayoutKind::Uv);
    const SurfaceLayout& L = b.data.layout;
    const glm::vec3 w = glm::normalize(glm::vec3(0.4f, 0.5f, 0.75f));
    RefractorOptions o;
    o.loader = context_->loader();
    auto refractor = Refractor::create(makeBake(b.data), o);
    refractor->update(FrameView::fromEye(1e5f * w));
    const std::vector<float> m = refractor->readRefractionMap();
    std::vector<glm::vec4> map(m.size() / 4);
    for (size_t i = 0; i < map.size(); ++i) map[i] = {m[4 * i], m[4 * i + 1], m[4 * i + 2], m[4 * i + 3]};
    // Points inside chart triangles facing the viewer.
    std::vector<glm::vec3> p, dirs;
    std::vector<glm::vec2> uv;
    for (size_t t = 0; t < L.atlas.triangles.size(); t += 37) {
        const glm::uvec3 tri = L.atlas.triangles[t];
        const glm::vec3 bary(0.2f, 0.3f, 0.5f);
        glm::vec3 q(0.0f), n(0.0f);
        glm::vec2 u(0.0f);
        for (int k = 0; k < 3; ++k) {
            q += bary[k] * L.atlas.vertexPosition[tri[k]];
            n += bary[k] * L.atlas.vertexNormal[tri[k]];
            u += bary[k] * L.atlas.vertexUV[tri[k]];
        }
        if (glm::dot(n, w) <= 0.1f) continue;
        p.push_back(q), dirs.push_back(w), uv.push_back(u);
    }
    ASSERT_GT(p.size(), 10u);
    const std::vector<glm::vec4> answer = queryBake(b.data, p, dirs);
    double worst = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        const glm::vec3 gl = glm::normalize(glm::vec3(sampleBilinear(map, L.muWidth, L.muHeight, uv[i])));
        worst = std::max(worst, double(glm::degrees(std::acos(std::min(1.0f, glm::dot(gl, glm::vec3(answer[i])))))));
    }
    std::printf("  %zu queries: largest angle to the GL map %.4f deg\n", p.size(), worst);
    // Measured 0.02 deg (the viewer's 1e-5 rad spread and float rounding); a lookup in the wrong
    // texel or without the gutters would be degrees off.
    EXPECT_LT(worst, 0.2);
}
