#include "bake/bake.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>

#include <Eigen/Core>

#include "bake/joining_layout.h"
#include "common/checksum.h"
#include "common/error.h"
#include "common/frame.h"
#include "common/limits.h"
#include "common/sh.h"

namespace shrefract {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

BakeStats& BakeStats::operator+=(const BakeStats& o) {
    samples += o.samples, paths += o.paths, rays += o.rays;
    tir += o.tir, capped += o.capped, softCapped += o.softCapped, reentered += o.reentered;
    geometricNormal += o.geometricNormal, leaked += o.leaked;
    traceSeconds += o.traceSeconds, compressSeconds += o.compressSeconds;
    wallSeconds += o.wallSeconds;
    return *this;
}

nlohmann::json BakeStats::ToJson() const {
    return {{"paths", paths}, {"rays", rays}, {"tir", tir}, {"capped", capped},
            {"softCapped", softCapped}, {"reentered", reentered},
            {"geometricNormal", geometricNormal}, {"leaked", leaked}, {"seconds", wallSeconds}};
}

BakeStats BakeStats::fromJson(const nlohmann::json& j) {
    BakeStats s;
    auto count = [&](const char* key) { return j.value(key, size_t(0)); };
    s.paths = count("paths"), s.rays = count("rays"), s.tir = count("tir");
    s.capped = count("capped"), s.softCapped = count("softCapped");
    s.reentered = count("reentered"), s.geometricNormal = count("geometricNormal");
    s.leaked = count("leaked");
    s.wallSeconds = j.value("seconds", 0.0);
    return s;
}

// What the bake's workers share: how a batch's R becomes its weights (bake/fit.h SampleFit) and
// its error model, and the grid directions in the order they are traced.
struct BakePlan::Compression {
    std::unique_ptr<SampleFit> fit;
    std::unique_ptr<ResidualFitter> residual;  // the error model, when the bake stores one
    std::vector<glm::vec3> dirs;             // grid directions, local frame
    std::vector<uint32_t> order;             // the order they are traced in: packetOrder(grid)
    std::vector<glm::vec3> checks;           // where the error model's truth is traced apart
    std::vector<uint32_t> checkOrder;        // and the order they are traced in
};

BakePlan::BakePlan(const Scene& scene, const BakeOptions& opt, const std::string& inputPath)
    : scene_(scene), opt_(opt), input_(inputPath) {
    if (opt.basis == Basis::Grid) {
        // The traced grid is the model: nothing to fit, and nothing missed at its directions; its
        // error model checks it between them (bake/residual.h).
        if (opt.grid.count() > limits::kMaxGridBasis)
            throw InputError(str("--basis grid stores every direction of --grid ", opt.grid.ToString(), " (",
                                 opt.grid.count(), "), more than the ", limits::kMaxGridBasis,
                                 " the runtime can hold per sample: use a coarser --grid"));
        opt_.order = 0;
    }
    opt_.errorOrder = storedErrorOrder(opt.errorOrder, opt.basis, opt_.order, opt.grid);
    if (opt.basis == Basis::Sh && !fitCanSolve(opt.fit, opt.order, opt.grid))
        throw InputError(str("--order ", opt.order, " stores ", shEvenCount(opt.order), " coefficients, more than the ",
                             opt.grid.count(), " directions of --grid ", opt.grid.ToString(), ": the ",
                             nameOf(opt.fit), " fit needs at least as many (a finer --grid, a lower "
                             "--order, or --fit projection)"));
    const auto t0 = Clock::now();
    if (opt.layout == LayoutKind::Joining) {
        const int rate = opt.rate > 0 ? opt.rate : rateForSampleCount(scene, opt.samples);
        layout_ = buildJoiningLayout(scene, rate);
    } else {
        ChartOptions co = opt.charts;
        co.kind = opt.layout;
        co.samples = opt.samples;
        layout_ = buildChartLayout(scene, co, &charts_);
    }
    setupSeconds_ = secondsSince(t0);
}

BakePlan::~BakePlan() = default;

void BakePlan::prepareTracing() const {
    std::call_once(prepared_, [&] {
        const int J = opt_.grid.count();
        auto c = std::make_unique<Compression>();
        if (opt_.basis == Basis::Sh)
            c->fit = std::make_unique<SampleFit>(opt_.grid, opt_.order, opt_.fit, opt_.weighting,
                                                 opt_.filterWidth, opt_.cacheDir);
        if (opt_.errorOrder >= 0)
            c->residual = std::make_unique<ResidualFitter>(opt_.basis, opt_.grid, opt_.order, opt_.errorOrder);
        c->dirs.resize(J);
        for (int j = 0; j < J; ++j) c->dirs[j] = glm::vec3(opt_.grid.direction(j));
        c->order = packetOrder(opt_.grid.nTheta, opt_.grid.nPhi);
        if (c->residual) {
            c->checks = c->residual->checkDirections();
            // The corners lie on a grid one ring short of the traced one: traced in its packet order.
            if (!c->checks.empty()) c->checkOrder = packetOrder(opt_.grid.nTheta - 1, opt_.grid.nPhi);
        }
        compression_ = std::move(c);
        tracer_ = std::make_unique<Tracer>(scene_, opt_.trace);
    });
}

SliceResult BakePlan::bakeSlice(size_t beginBatch, size_t endBatch, const SliceProgress& base) const {
    prepareTracing();
    const auto t0 = Clock::now();
    std::unique_ptr<tbb::global_control> threads;
    if (opt_.threads > 0)
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                        opt_.threads);
    const BakeOptions& opt = opt_;
    const SurfaceLayout& L = layout_;
    const Tracer& tracer = *tracer_;
    const Compression& compression = *compression_;
    const std::vector<glm::vec3>& dirs = compression.dirs;
    const std::vector<uint32_t>& order = compression.order;
    const bool weighted = compression.fit && compression.fit->needsPaths();
    const size_t n = L.position.size();
    const int K = basisCoefficients(opt.basis, opt.order, opt.grid);
    const int J = opt.grid.count();
    endBatch = std::min(endBatch, batchCount());
    beginBatch = std::min(beginBatch, endBatch);

    SliceResult out;
    out.first = std::min(beginBatch * kBakeBatch, n);
    out.count = std::min(endBatch * kBakeBatch, n) - out.first;
    out.weights.assign(size_t(K) * out.count * 4, 0.0f);
    const int Ke = compression.residual ? compression.residual->errorCoefficients() : 0;
    out.errors.assign(size_t(Ke) * out.count, 0.0f);
    const size_t first = out.first, count = out.count;

    std::atomic<size_t> done{0}, rays{0};
    std::atomic<size_t> tir{0}, capped{0}, soft{0}, reent{0}, geo{0}, leaked{0};
    std::atomic<int64_t> traceNs{0}, compressNs{0};
    std::mutex progressMutex;
    auto lastReport = Clock::now();

    const std::vector<glm::vec3>& checks = compression.checks;
    const int Jc = int(checks.size());

    tbb::parallel_for(tbb::blocked_range<size_t>(beginBatch, endBatch, 1), [&](const tbb::blocked_range<size_t>& range) {
        enableFlushToZero();
        Eigen::MatrixXf R(J, 4 * kBakeBatch), C(Jc, 4 * kBakeBatch), Wt(4 * kBakeBatch, K), E(Ke, kBakeBatch);
        std::vector<glm::vec3> omegas(std::max(J, Jc));
        std::vector<PathResult> paths(std::max(J, Jc));
        std::vector<PathResult> batchPaths(weighted ? size_t(J) * kBakeBatch : 0);  // [s * J + j]
        size_t localRays = 0, ntir = 0, ncap = 0, nsoft = 0, nre = 0, ngeo = 0, nleak = 0;
        // Traces sample i toward `local` (traced in `packet` order) into M's columns 4s..4s+3:
        // exit x, y, z and length, row j for direction j. Returns the paths, paths[q] direction
        // packet[q]'s.
        auto traceSample = [&](size_t i, size_t s, const std::vector<glm::vec3>& local,
                               const std::vector<uint32_t>& packet, Eigen::MatrixXf& M) {
            const int n = int(local.size());
            const Frame frame = Frame::fromNormal(L.normal[i]);
            for (int q = 0; q < n; ++q) omegas[q] = frame.fromLocal(local[packet[q]]);
            if (opt.coherent) {
                tracer.traceCoherent(L.position[i], L.normal[i], omegas.data(), n, L.part[i], paths.data());
            } else {
                for (int q = 0; q < n; ++q) paths[q] = tracer.trace(L.position[i], L.normal[i], omegas[q], L.part[i]);
            }
            for (int q = 0; q < n; ++q) {
                const PathResult& p = paths[q];
                const int j = int(packet[q]);
                M(j, 4 * s + 0) = p.exit.x;
                M(j, 4 * s + 1) = p.exit.y;
                M(j, 4 * s + 2) = p.exit.z;
                M(j, 4 * s + 3) = p.length;
                localRays += p.rays;
                ntir += (p.flags & kPathTIR) != 0;
                ncap += (p.flags & kPathCapped) != 0;
                nsoft += (p.flags & kPathSoftCapped) != 0;
                nre += (p.flags & kPathReentered) != 0;
                ngeo += (p.flags & kPathGeometricNormal) != 0;
                nleak += (p.flags & kPathLeaked) != 0;
            }
        };
        for (size_t b = range.begin(); b != range.end(); ++b) {
            if (opt.cancel && opt.cancel->load()) return;
            const size_t batchFirst = b * kBakeBatch;
            const size_t batchCount = std::min<size_t>(kBakeBatch, n - batchFirst);
            // 1. Trace the batch: R holds every sample's exits and lengths, one column each; C the
            // same at the error model's own check directions, where it has them.
            auto tTrace = Clock::now();
            localRays = ntir = ncap = nsoft = nre = ngeo = nleak = 0;
            R.setZero();
            for (size_t s = 0; s < batchCount; ++s) {
                traceSample(batchFirst + s, s, dirs, order, R);
                if (weighted)
                    for (int q = 0; q < J; ++q) batchPaths[s * J + order[q]] = paths[q];
                if (Jc > 0) traceSample(batchFirst + s, s, checks, compression.checkOrder, C);
            }
            // 2. Compress the batch: the projection W = M R, one GEMM; or one weighted solve per
            // sample, the band filter applied to its weights.
            auto tGemm = Clock::now();
            if (compression.fit)
                compression.fit->fit(R, weighted ? batchPaths.data() : nullptr, int(batchCount), Wt);
            else
                Wt = R.transpose();  // the grid basis: weight j is the traced value at direction j
            // 3. Store its weights, and the error model of what they miss.
            for (int k = 0; k < K; ++k)
                std::copy_n(Wt.col(k).data(), 4 * batchCount,
                            &out.weights[(size_t(k) * count + batchFirst - first) * 4]);
            if (Ke > 0) {
                compression.residual->fit(R, C, Wt, int(batchCount), E);
                for (int k = 0; k < Ke; ++k)
                    for (size_t s = 0; s < batchCount; ++s)
                        out.errors[size_t(k) * count + batchFirst - first + s] = E(k, s);
            }
            auto tEnd = Clock::now();
            traceNs += std::chrono::duration_cast<std::chrono::nanoseconds>(tGemm - tTrace).count();
            compressNs += std::chrono::duration_cast<std::chrono::nanoseconds>(tEnd - tGemm).count();
            rays += localRays, tir += ntir, capped += ncap, soft += nsoft, reent += nre;
            geo += ngeo, leaked += nleak;
            size_t nowDone = done += batchCount;
            if (opt.progress && progressMutex.try_lock()) {
                std::lock_guard<std::mutex> g(progressMutex, std::adopt_lock);
                if (secondsSince(lastReport) > 0.2 || nowDone == count) {
                    lastReport = Clock::now();
                    opt.progress(BakeProgress{base.samplesDone + nowDone, n, base.samplesResumed,
                                              base.rays + rays.load(), base.seconds + secondsSince(t0)});
                }
            }
        }
    });
    if (opt.cancel && opt.cancel->load()) throw Cancelled();

    BakeStats& st = out.stats;
    st.samples = count;
    st.paths = count * size_t(J + Jc);
    st.rays = rays, st.tir = tir, st.capped = capped, st.softCapped = soft;
    st.reentered = reent, st.geometricNormal = geo, st.leaked = leaked;
    st.traceSeconds = traceNs * 1e-9, st.compressSeconds = compressNs * 1e-9;
    st.wallSeconds = secondsSince(t0);
    return out;
}

nlohmann::json BakePlan::manifest(const BakeStats& stats) const {
    nlohmann::json layoutInfo = {{"kind", nameOf(layout_.kind)}};
    if (layout_.isChartLayout()) {
        const ChartStats& c = charts_;
        layoutInfo["method"] = layout_.kind == LayoutKind::Isolated ? nameOf(opt_.charts.method) : "mesh uv";
        layoutInfo["seamMesh"] = c.seamMesh;
        layoutInfo["coneDegrees"] = opt_.charts.coneDegrees;
        layoutInfo["maxDensityRatio"] = opt_.charts.maxDensityRatio;
        layoutInfo["splits"] = c.splits;
        layoutInfo["arapCharts"] = c.arapCharts;
        layoutInfo["texelsPerObjectUnit"] = c.texelsPerObjectUnit;
        layoutInfo["densitySpread"] = c.densitySpread;
        layoutInfo["maxConformalDistortion"] = c.maxConformalDistortion;
        layoutInfo["seamEdges"] = c.seamEdges;
        layoutInfo["creaseEdges"] = c.creaseEdges;
        layoutInfo["borderEdges"] = c.borderEdges;
        layoutInfo["gutterTexels"] = c.gutterTexels;
    }
    // Paths absolute, so that the same bake run from another folder (a scheduler's job, a
    // merge) describes itself the same way.
    auto absolute = [](const std::string& path) {
        std::error_code ec;
        auto abs = std::filesystem::absolute(path, ec);
        return ec ? path : abs.lexically_normal().string();
    };
    nlohmann::json media = nlohmann::json::array();
    for (const Part& p : scene_.parts) {
        media.push_back({{"name", p.medium.name},
                         {"mesh", absolute(p.meshPath)},
                         {"ior", p.medium.ior},
                         {"absorption", {p.medium.absorption.x, p.medium.absorption.y, p.medium.absorption.z}},
                         {"priority", p.medium.priority},
                         {"meshChecksum", p.mesh.checksum()},
                         {"triangles", p.mesh.triangles.size()}});
    }
    nlohmann::json m = {
        {"input", absolute(input_)},
        {"grid", {opt_.grid.nTheta, opt_.grid.nPhi}},
        {"filterWidth", opt_.filterWidth},
        {"fit", nameOf(opt_.fit)},
        {"fitWeighting", opt_.fit == Fit::Weighted ? opt_.weighting.ToString() : ""},
        {"branch", opt_.trace.branch == Branch::Fresnel ? "fresnel" : "transmit"},
        {"maxBounces", opt_.trace.maxBounces},
        {"tracer", opt_.coherent ? "coherent" : "scalar"},
        {"media", media},
        {"frame", "Duff et al. 2017 orthonormal basis from the shading normal, z = normal"},
        {"layout", layoutInfo},
        {"stats", stats.ToJson()},
    };
    if (opt_.basis == Basis::Grid)
        m["gridBasis"] = {{"stored", "the traced exit at grid direction j = i * nPhi + k (docs/format.md)"},
                          {"interpolation", "bilinear in (theta, phi), wrapping in phi, reflected across the pole"},
                          {"channels", "exit x, y, z (object space), path length"}};
    else
        m["sh"] = {{"convention", "real, orthonormal, no Condon-Shortley phase (docs/conventions.md)"},
                   {"stored", "l+m even, even order: l = 0..L, m = -l, -l+2, ..., l"},
                   {"channels", "exit x, y, z (object space), path length"}};
    return m;
}

BakeData BakePlan::data(std::vector<float> weights, std::vector<float> errors,
                        const BakeStats& stats) const {
    BakeData d;
    d.basis = opt_.basis;
    d.order = opt_.order;
    d.grid = opt_.grid;
    d.precision = opt_.precision;
    d.layout = layout_;
    d.weights = std::move(weights);
    d.errorOrder = opt_.errorOrder < 0 ? -1 : opt_.errorOrder;
    d.errors = std::move(errors);
    d.manifest = manifest(stats);
    if (opt_.basis == Basis::Sh && opt_.fit != Fit::Projection) {
        // The weighted fit solves even rank-deficient problems (bake/fit.cpp's double path); if
        // a least-squares fit still comes out non-finite, say so, not that a weight is NaN.
        const auto bad = std::find_if(d.weights.begin(), d.weights.end(), [](float w) { return !std::isfinite(w); });
        if (bad != d.weights.end())
            throw InputError(str("sample ", size_t(bad - d.weights.begin()) / 4 % d.layout.position.size(), ": the ",
                                 nameOf(opt_.fit), " fit gave a non-finite weight at order ", opt_.order, " (",
                                 shEvenCount(opt_.order), " coefficients from the ", opt_.grid.count(),
                                 " directions of --grid ", opt_.grid.ToString(),
                                 "): too few directions once it discounts the uncertain ones; use a finer "
                                 "--grid or a lower --order"));
    }
    quantizeWeights(d);  // what the file will hold, so the in-memory bake draws as it
    return d;
}

std::string BakePlan::layoutChecksum() const {
    Checksum sum;
    const size_t n = layout_.position.size();
    sum.update(layout_.position.data(), n * sizeof(glm::vec3));
    sum.update(layout_.normal.data(), n * sizeof(glm::vec3));
    sum.update(layout_.part.data(), n * sizeof(uint32_t));
    return sum.hex();
}

BakeResult bake(const Scene& scene, const BakeOptions& opt, const std::string& inputPath) {
    const auto t0 = Clock::now();
    BakePlan plan(scene, opt, inputPath);
    SliceResult all = plan.bakeSlice(0, plan.batchCount());
    BakeResult out;
    out.stats = all.stats;
    out.stats.wallSeconds = secondsSince(t0);
    out.stats.rhoOverhead = rhoOverhead(plan.layout());
    out.stats.charts = plan.chartStats();
    out.data = plan.data(std::move(all.weights), std::move(all.errors), out.stats);
    return out;
}

}  // namespace shrefract
