#include "eval/render_method.h"

#include <algorithm>
#include <cstdio>
#include <functional>

#include "bake/tracer.h"
#include "common/decompress.h"
#include "common/error.h"
#include "eval/directions.h"
#include "eval/reference.h"
#include "eval/seams.h"
#include "runtime/src/bake_data.h"

namespace shrefract {

struct RenderMethod::Impl {
    RenderRequest request;
    Bake bake;
    std::unique_ptr<BakeData> seamBake;  // whose seams to measure the render's jump across
    std::unique_ptr<Scene> scene;
    std::unique_ptr<Tracer> tracer;
    std::unique_ptr<ReferenceEnvironment> envImage;  // raytrace
    std::unique_ptr<PixelFit> pixelFit;              // raytrace --exits other than exact
    std::unique_ptr<HeadlessContext> context;        // GL methods
    std::unique_ptr<Environment> env;
    std::unique_ptr<Refractor> refractor, bracket;
    std::unique_ptr<Baseline> baseline;
    std::string timing;

    RenderedFrame raytrace(const Camera& c, double* ms) const;
    void setUpSh(const Camera& camera, nlohmann::json& summary);
};

RenderMethod::RenderMethod(const RenderRequest& request, const Camera& camera, nlohmann::json& summary)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.request = request;
    const RenderRequest& r = m.request;
    m.bake = loadBake(r.bakePath, r.verify);
    for (const std::string& w : m.bake.warnings())
        std::fprintf(stderr, "shrefract-render: warning: %s: %s\n", r.bakePath.c_str(), w.c_str());
    if (r.sh.order < -1 || r.sh.order > m.bake.order())
        throw std::invalid_argument("--order " + std::to_string(r.sh.order) + ": " + r.bakePath +
                                    " stores orders 0.." + std::to_string(m.bake.order()) + " (-1: all)");
    const BakeData& data = bakeData(m.bake);
    if (!r.seamsOf.empty())
        m.seamBake = std::make_unique<BakeData>(readBake(r.seamsOf));
    else if (data.layout.isChartLayout())
        m.seamBake = std::make_unique<BakeData>(data);
    if (!r.seamsOf.empty() && !m.seamBake->layout.isChartLayout())
        throw std::invalid_argument("--seams-of " + r.seamsOf + ": a joining bake has no seams");
    if (r.method == "raytrace" || r.method == "wyman" || m.seamBake) {
        m.scene = std::make_unique<Scene>(sceneOfBake(data, r.bakePath, r.scenePath));
        if (r.sh.absorption)
            for (Part& p : m.scene->parts) p.medium.absorption = *r.sh.absorption;
        m.tracer = std::make_unique<Tracer>(*m.scene, traceOptionsOfBake(data));
    }
    if (r.method == "raytrace") {  // the CPU reference: no GL context at all
        m.envImage = std::make_unique<ReferenceEnvironment>(loadLatLong(r.envPath), !r.latLongLookup);
        m.timing = "CPU wall time, Embree, all cores";
        if (r.exits != PixelExits::Exact) {
            m.pixelFit = std::make_unique<PixelFit>(data, r.exits);
            std::printf("exits: %s, fitted at every pixel's entry point to the bake's %dx%d grid\n",
                        nameOf(r.exits), data.manifest["grid"][0].get<int>(),
                        data.manifest["grid"][1].get<int>());
        }
        summary["exits"] = nameOf(r.exits);
        return;
    }
    m.context = createHeadlessContext(r.backend, r.width, r.height);
    std::printf("GL: %s (%s)\n", m.context->description().c_str(), nameOf(r.backend));
    summary["renderer"] = m.context->description();
    m.env = std::make_unique<Environment>(Environment::loadLatLong(r.envPath));
    m.timing = "wall: update + background + draw + glFinish, no read-back; median of " +
               std::to_string(std::max(1, r.frames)) + " after a warm-up";
    if (r.method == "sh") {
        m.setUpSh(camera, summary);
        return;
    }
    BaselineOptions options;
    options.method = parseName<BaselineMethod>(r.method);
    options.absorption = r.sh.absorption;
    options.timings = r.stageTimers;
    options.tir = r.tir;
    options.loader = m.context->loader();
    std::vector<float> normalDistance;
    if (m.tracer) normalDistance = normalDistances(*m.tracer, data.layout);
    m.baseline = Baseline::create(m.bake, normalDistance, options);
}

RenderMethod::~RenderMethod() = default;

void RenderMethod::Impl::setUpSh(const Camera& camera, nlohmann::json& summary) {
    const RenderRequest& r = request;
    RefractorOptions options = r.sh;
    options.maxOrder = options.order;  // only the bands used go to the GPU (paper Figure 12)
    options.loader = context->loader();
    options.timings = r.stageTimers;
    refractor = Refractor::create(bake, options);
    if (r.ior.x > 0) {
        refractor->setIor(r.ior);
        if (!r.bracketPath.empty()) {
            bracket = Refractor::create(loadBake(r.bracketPath, r.verify), options);
            refractor->setIorBracket(bracket.get());
        }
        std::printf("index of refraction %g,%g,%g from the bake's %g%s\n", r.ior.x, r.ior.y, r.ior.z,
                    bake.ior(), bracket ? " and the bracketing bake's" : " and the straight path");
    }
    const bool joining = bake.layout() == "joining";
    std::printf("bake: %s, %d samples, %d triangles, %s layout, %s %dx%d; using "
                "order %d, %d decompression pass(es), preset %s, path %s, decompression %s, "
                "shading %s, %d tap(s); GPU memory %.2f MB\n",
                bakeData(bake).modelName().c_str(), bake.sampleCount(), bake.triangleCount(), bake.layout().c_str(),
                joining ? "rho" : "atlas", refractor->refractionMapSize().x,
                refractor->refractionMapSize().y, refractor->order(), refractor->passCount(),
                nameOf(options.preset), nameOf(refractor->path()), nameOf(refractor->decompression()),
                nameOf(refractor->shading()), refractor->taps(), refractor->memory().total() / 1e6);
    if (!joining)
        std::printf("charts: gutter %d texels, seam-aware %s\n", refractor->gutter(),
                    refractor->seamAware() ? "on" : "off");
    summary["order"] = refractor->order();
    summary["passes"] = refractor->passCount();
    summary["path"] = nameOf(refractor->path());
    summary["decompression"] = nameOf(refractor->decompression());
    summary["shading"] = nameOf(refractor->shading());
    summary["taps"] = refractor->taps();
    if (!r.dumpDir.empty()) refractor->dumpShaders(r.dumpDir);
    if (!joining) {  // the map's own jump across the seams
        refractor->update(FrameView::fromEye(camera.eye));
        const std::vector<float> mp = refractor->readRefractionMap();
        std::vector<glm::vec4> map(mp.size() / 4);
        for (size_t i = 0; i < map.size(); ++i) map[i] = {mp[4 * i], mp[4 * i + 1], mp[4 * i + 2], mp[4 * i + 3]};
        nlohmann::json st = jumpStats({}, seamJumps(bakeData(bake).layout, map));
        summary["mapSeams"] = st;
        if (st["count"].get<size_t>() > 0)
            std::printf("refraction map across %zu smooth seam points: jump median %.3f, p95 %.3f deg\n",
                        st["count"].get<size_t>(), st["median"].get<double>(), st["p95"].get<double>());
    }
}

RenderedFrame RenderMethod::Impl::raytrace(const Camera& c, double* ms) const {
    const RenderRequest& r = request;
    ReferenceView view;
    view.eye = c.eye, view.target = c.target, view.up = c.up;
    view.fovDegrees = c.fovDegrees, view.width = r.width, view.height = r.height;
    view.spp = r.spp;
    ReferenceStats stats;
    const EvalBuffer b = r.ior.x > 0 ? renderDispersed(*scene, traceOptionsOfBake(bakeData(bake)),
                                                       *envImage, view, r.ior, &stats)
                                     : renderReference(*tracer, *envImage, view, &stats, pixelFit.get());
    RenderedFrame f;
    f.width = r.width, f.height = r.height;
    f.color.resize(b.pixelCount() * 4);
    f.directions.resize(b.pixelCount() * 4);
    for (size_t i = 0; i < b.pixelCount(); ++i) {
        for (int ch = 0; ch < 3; ++ch) {
            f.color[4 * i + ch] = b.color[i][ch];
            f.directions[4 * i + ch] = b.direction[i][ch];
        }
        f.color[4 * i + 3] = 1.0f;
        f.directions[4 * i + 3] = b.color[i].a;
    }
    *ms = stats.milliseconds;
    std::printf("raytrace: %zu covered pixels; paths with TIR %zu, capped %zu, re-entered %zu, "
                "geometric normal %zu, back-facing first hits %zu\n",
                stats.covered, stats.tir, stats.capped, stats.reentered, stats.geometricNormal,
                stats.backFacing);
    return f;
}

RenderedFrame RenderMethod::render(const Camera& camera, double* ms) {
    Impl& m = *impl_;
    const RenderRequest& r = m.request;
    if (m.refractor) return renderFrame(*m.refractor, *m.env, camera, r.width, r.height);
    if (m.baseline) return renderFrame(*m.baseline, *m.env, camera, r.width, r.height);
    return m.raytrace(camera, ms);
}

bool RenderMethod::timesFrames() const { return impl_->context != nullptr; }

double RenderMethod::wallMs(const Camera& camera) {
    Impl& m = *impl_;
    const RenderRequest& r = m.request;
    const int frames = std::max(1, r.frames);
    if (m.refractor) return frameWallMs(*m.refractor, *m.env, camera, r.width, r.height, frames);
    if (m.baseline) return frameWallMs(*m.baseline, *m.env, camera, r.width, r.height, frames);
    throw std::logic_error("RenderMethod::wallMs: the reference is not timed per frame");
}

const std::string& RenderMethod::timing() const { return impl_->timing; }

void RenderMethod::reportWarmFrame(const RenderedFrame& frame, nlohmann::json& summary) const {
    const Impl& m = *impl_;
    if (m.refractor) {
        const Timings& t = frame.timings;
        if (m.request.stageTimers) {
            std::printf("GPU ms: view %.3f, decompress %.3f (%d passes), smooth %.3f, unpack %.3f, "
                        "shade %.3f\n",
                        t.view, t.decompress, t.passes, t.smooth, t.unpack, t.shade);
            summary["stageMs"] = {{"view", t.view}, {"decompress", t.decompress}, {"smooth", t.smooth},
                                  {"unpack", t.unpack}, {"shade", t.shade}};
        }
        const GpuMemory& g = m.refractor->memory();
        const double extra = m.bracket ? m.bracket->memory().total() / 1e6 : 0.0;
        if (m.bracket)
            std::printf("GPU memory: %.1f MB + bracketing bake %.1f MB\n", g.total() / 1e6, extra);
        else
            std::printf("GPU memory: %.1f MB\n", g.total() / 1e6);
        summary["gpuMemoryMB"] = g.total() / 1e6 + extra;
        summary["gpuMemoryPartsMB"] = {{"weights", g.weights / 1e6}, {"samples", g.samples / 1e6},
                                       {"rho", g.rho / 1e6},         {"neighbours", g.neighbours / 1e6},
                                       {"mesh", g.mesh / 1e6},       {"targets", g.targets / 1e6},
                                       {"bracketingBake", extra}};
    } else if (m.baseline && m.request.stageTimers) {
        const BaselineTimings& t = m.baseline->timings();
        std::printf("GPU ms: back faces %.3f, shade %.3f\n", t.backFaces, t.shade);
        summary["stageMs"] = {{"backFaces", t.backFaces}, {"shade", t.shade}};
    }
}

nlohmann::json RenderMethod::reportSeams(const RenderedFrame& frame, const Camera& camera,
                                         nlohmann::json& summary) const {
    const Impl& m = *impl_;
    if (!m.seamBake) return nullptr;
    ReferenceView view;
    view.eye = camera.eye, view.target = camera.target, view.up = camera.up;
    view.fovDegrees = camera.fovDegrees, view.width = m.request.width, view.height = m.request.height;
    const auto pairs = seamPixelPairs(*m.tracer, m.seamBake->layout, view);
    nlohmann::json st = jumpStats(pairs, pairJumps(frame.directions, pairs));
    if (st["count"].get<size_t>() > 0)
        std::printf("seams: %zu pixel pairs straddle a smooth seam; exit direction jump mean %.3f, "
                    "median %.3f, p95 %.3f deg\n",
                    st["count"].get<size_t>(), st["mean"].get<double>(), st["median"].get<double>(),
                    st["p95"].get<double>());
    else
        std::printf("seams: no pixel pair straddles a visible smooth seam\n");
    summary["seams"] = st;
    return st;
}

}  // namespace shrefract
