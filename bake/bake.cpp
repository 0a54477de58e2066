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

#include "bake/layout.h"
#include "common/error.h"
#include "common/frame.h"
#include "common/sh.h"

namespace shrefract {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Samples per GEMM: R is J x 4B. 32 keeps R (2048 x 128 floats = 1 MiB) in L2-ish reach and
// leaves enough batches for load balance.
constexpr int kBatch = 32;

}  // namespace

const char* ToString(Fit fit) {
    switch (fit) {
        case Fit::Projection:
            return "projection";
        case Fit::LeastSquares:
            return "lsq";
        case Fit::Weighted:
            return "weighted";
    }
    return "unknown";
}

Fit parseFit(const std::string& text) {
    for (Fit f : {Fit::Projection, Fit::LeastSquares, Fit::Weighted})
        if (text == ToString(f)) return f;
    throw InputError("unknown fit \"" + text + "\" (expected projection, lsq or weighted)");
}

std::vector<int> evenBands(int L) {
    std::vector<int> bands;
    for (const ShLM& f : shEvenFunctions(L)) bands.push_back(f.l);
    return bands;
}

BakeResult bake(const Scene& scene, const BakeOptions& opt, const std::string& inputPath) {
    const auto t0 = Clock::now();
    std::unique_ptr<tbb::global_control> threads;
    if (opt.threads > 0)
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                        opt.threads);
    BakeResult out;
    BakeData& data = out.data;
    data.order = opt.order;
    data.precision = opt.precision;
    const int rate = opt.rate > 0 ? opt.rate : rateForSampleCount(scene, opt.samples);
    data.layout = buildJoiningLayout(scene, rate);
    const SurfaceLayout& L = data.layout;
    const size_t n = L.position.size();
    const int K = shEvenCount(opt.order);
    const int J = opt.grid.count();

    // W = M R: the compression matrix in float for the GEMM, with the band filter folded into
    // its rows (filtering the weights equals filtering M's rows: diag(h) (M R) = (diag(h) M) R).
    // The weighted fit solves per sample; the others are one matrix for every sample.
    const bool weighted = opt.fit == Fit::Weighted;
    std::unique_ptr<WeightedFitter> fitter;
    Eigen::MatrixXf Mt;
    std::vector<double> h = shBandFilter(opt.order, opt.filterWidth);
    std::vector<int> band = evenBands(opt.order);
    if (weighted) {
        fitter = std::make_unique<WeightedFitter>(opt.grid, opt.order, opt.weighting);
    } else {
        Eigen::MatrixXd Md = opt.fit == Fit::LeastSquares
                                 ? leastSquaresMatrix(opt.grid, opt.order)
                                 : compressionMatrixCached(opt.grid, opt.order, opt.cacheDir);
        for (int k = 0; k < K; ++k) Md.row(k) *= h[band[k]];
        // Stored transposed: the GEMM then yields W^T, whose column k (coefficient k of every
        // sample in the batch, x y z len interleaved) is one contiguous copy into the weights.
        Mt = Md.transpose().cast<float>();
    }

    std::vector<glm::vec3> dirs(J);
    for (int j = 0; j < J; ++j) dirs[j] = glm::vec3(opt.grid.direction(j));

    data.weights.assign(size_t(K) * n * 4, 0.0f);
    Tracer tracer(scene, opt.trace);

    std::atomic<size_t> done{0}, rays{0};
    std::atomic<size_t> tir{0}, capped{0}, soft{0}, reent{0}, geo{0}, leaked{0};
    std::atomic<int64_t> traceNs{0}, compressNs{0};
    std::mutex progressMutex;
    auto lastReport = Clock::now();
    const size_t batches = (n + kBatch - 1) / kBatch;

    tbb::parallel_for(tbb::blocked_range<size_t>(0, batches, 1), [&](const tbb::blocked_range<size_t>& range) {
        enableFlushToZero();
        Eigen::MatrixXf R(J, 4 * kBatch), Wt(4 * kBatch, K), W(K, 4);
        std::vector<PathResult> paths(weighted ? size_t(J) * kBatch : 0);
        std::vector<float> confidence(weighted ? J : 0);
        for (size_t b = range.begin(); b != range.end(); ++b) {
            if (opt.cancel && opt.cancel->load()) return;
            const size_t first = b * kBatch, count = std::min<size_t>(kBatch, n - first);
            auto tTrace = Clock::now();
            size_t localRays = 0, ntir = 0, ncap = 0, nsoft = 0, nre = 0, ngeo = 0, nleak = 0;
            R.setZero();
            for (size_t s = 0; s < count; ++s) {
                const size_t i = first + s;
                const Frame frame = Frame::fromNormal(L.normal[i]);
                for (int j = 0; j < J; ++j) {
                    const glm::vec3 omega = frame.fromLocal(dirs[j]);
                    PathResult p = tracer.trace(L.position[i], L.normal[i], omega, L.part[i]);
                    if (opt.footprintSamples > 1) {
                        // The mean over the footprint: points along the segments to the grid
                        // neighbours (listed after the sample itself), spread evenly over them,
                        // at a quarter and two fifths of the way.
                        const uint32_t first = L.neighbourOffset[i] + 1, others = L.neighbourCount[i] - 1;
                        const uint32_t extra = uint32_t(opt.footprintSamples - 1);
                        glm::vec3 sumExit = p.exit;
                        float sumLength = p.length;
                        int used = 1;
                        for (int f = 1; f < opt.footprintSamples && others > 0; ++f) {
                            const uint32_t nb = L.neighbourIndex[first + (uint32_t(f - 1) * others) / extra];
                            const float t = f % 2 ? 0.25f : 0.4f;
                            const glm::vec3 pf = glm::mix(L.position[i], L.position[nb], t);
                            const glm::vec3 nf = glm::normalize(glm::mix(L.normal[i], L.normal[nb], t));
                            if (glm::dot(nf, omega) <= 0.0f) continue;  // the view is below it there
                            const PathResult q = tracer.trace(pf, nf, omega, L.part[i]);
                            sumExit += q.exit;
                            sumLength += q.length;
                            localRays += q.rays;
                            ++used;
                        }
                        p.exit = sumExit / float(used);
                        p.length = sumLength / float(used);
                    }
                    if (weighted) paths[s * J + j] = p;
                    R(j, 4 * s + 0) = p.exit.x;
                    R(j, 4 * s + 1) = p.exit.y;
                    R(j, 4 * s + 2) = p.exit.z;
                    R(j, 4 * s + 3) = p.length;
                    localRays += p.rays;
                    ntir += (p.flags & kPathTIR) != 0;
                    ncap += (p.flags & kPathCapped) != 0;
                    nsoft += (p.flags & kPathSoftCapped) != 0;
                    nre += (p.flags & kPathReentered) != 0;
                    ngeo += (p.flags & kPathGeometricNormal) != 0;
                    nleak += (p.flags & kPathLeaked) != 0;
                }
            }
            auto tGemm = Clock::now();
            if (weighted) {
                // One solve per sample, the band filter applied to its weights.
                for (size_t s = 0; s < count; ++s) {
                    fitter->confidence(&paths[s * J], confidence.data());
                    fitter->fit(R.middleCols(4 * s, 4), confidence.data(), W);
                    for (int k = 0; k < K; ++k) W.row(k) *= float(h[band[k]]);
                    Wt.middleRows(4 * s, 4) = W.transpose();
                }
            } else {
                Wt.noalias() = R.transpose() * Mt;  // the projection W = M R: one GEMM per batch
            }
            for (int k = 0; k < K; ++k)
                std::copy_n(Wt.col(k).data(), 4 * count, &data.weights[(size_t(k) * n + first) * 4]);
            auto tEnd = Clock::now();
            traceNs += std::chrono::duration_cast<std::chrono::nanoseconds>(tGemm - tTrace).count();
            compressNs += std::chrono::duration_cast<std::chrono::nanoseconds>(tEnd - tGemm).count();
            rays += localRays, tir += ntir, capped += ncap, soft += nsoft, reent += nre;
            geo += ngeo, leaked += nleak;
            size_t nowDone = done += count;
            if (opt.progress && progressMutex.try_lock()) {
                std::lock_guard<std::mutex> g(progressMutex, std::adopt_lock);
                if (secondsSince(lastReport) > 0.2 || nowDone == n) {
                    lastReport = Clock::now();
                    opt.progress(BakeProgress{nowDone, n, rays.load(), secondsSince(t0)});
                }
            }
        }
    });
    if (opt.cancel && opt.cancel->load()) throw Cancelled();

    BakeStats& st = out.stats;
    st.samples = n;
    st.paths = n * size_t(J);
    st.rays = rays, st.tir = tir, st.capped = capped, st.softCapped = soft;
    st.reentered = reent, st.geometricNormal = geo, st.leaked = leaked;
    st.traceSeconds = traceNs * 1e-9, st.compressSeconds = compressNs * 1e-9;
    st.wallSeconds = secondsSince(t0);
    st.rhoOverhead = rhoOverhead(L);

    nlohmann::json media = nlohmann::json::array();
    std::vector<std::string> checksums;
    for (const Part& p : scene.parts) {
        media.push_back({{"name", p.medium.name},
                         {"mesh", p.meshPath},
                         {"ior", p.medium.ior},
                         {"absorption", {p.medium.absorption.x, p.medium.absorption.y, p.medium.absorption.z}},
                         {"priority", p.medium.priority},
                         {"meshChecksum", p.mesh.checksum()},
                         {"triangles", p.mesh.triangles.size()}});
    }
    std::error_code ec;
    auto abs = std::filesystem::absolute(inputPath, ec);
    data.manifest = {
        {"input", ec ? inputPath : abs.string()},
        {"grid", {opt.grid.nTheta, opt.grid.nPhi}},
        {"filterWidth", opt.filterWidth},
        {"fit", ToString(opt.fit)},
        {"fitWeighting", weighted ? opt.weighting.ToString() : ""},
        {"branch", opt.trace.branch == Branch::Fresnel ? "fresnel" : "transmit"},
        {"maxBounces", opt.trace.maxBounces},
        {"media", media},
        {"sh", {{"convention", "real, orthonormal, no Condon-Shortley phase (docs/conventions.md)"},
                {"stored", "l+m even, even order: l = 0..L, m = -l, -l+2, ..., l"},
                {"channels", "exit x, y, z (object space), path length"}}},
        {"frame", "Duff et al. 2017 orthonormal basis from the shading normal, z = normal"},
        {"stats", {{"paths", st.paths}, {"rays", st.rays}, {"tir", st.tir}, {"capped", st.capped},
                   {"softCapped", st.softCapped}, {"reentered", st.reentered},
                   {"geometricNormal", st.geometricNormal}, {"leaked", st.leaked},
                   {"seconds", st.wallSeconds}}},
    };
    return out;
}

}  // namespace shrefract
