// The bake benchmark behind scripts/bench-bake: the whole bake at the paper's settings, and in
// the same run the ceilings it is measured against (machines are shared and noisy; ratios
// taken within one run are what mean something):
//  - rays/s of a bare Embree loop over the very rays the bake shot (no shading, no Fresnel), one
//    rtcIntersect1 each, against the scalar tracer and the coherent one (a sample's paths as
//    Embree ray streams, step by step) tracing the same paths;
//  - GFLOP/s of a bare Eigen GEMM of the projection's shape.
#include <sys/resource.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdio>
#include <fstream>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "bake/bake.h"
#include "bake/cmd/common_cli.h"
#include "bake/joining_layout.h"
#include "common/cli/cli.h"
#include "common/frame.h"
#include "common/output.h"
#include "common/sh.h"

using namespace shrefract;
using Clock = std::chrono::steady_clock;

static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
// CPU seconds of this process (all threads): on a shared machine, what a phase cost us rather
// than how long it waited for the cores.
static double cpuSeconds() {
    rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
    CLI::App app{"bench-bake: bake throughput against bare Embree and bare GEMM ceilings"};
    std::string input = "data/meshes/bunny00.off", json = "bench-bake.json";
    size_t samples = 35000;
    int stride = 16, order = 8;
    app.add_option("--mesh", input)->capture_default_str();
    app.add_option("--samples", samples)->capture_default_str();
    app.add_option("--order", order)->capture_default_str();
    app.add_option("--stride", stride, "ceiling measured on every stride-th sample")->capture_default_str();
    app.add_option("--json", json)->capture_default_str();
    std::string tracerName = "coherent";
    app.add_option("--tracer", tracerName, "the whole bake's tracer")->capture_default_str()
        ->check(CLI::IsMember({"coherent", "scalar"}));
    bool noBake = false, noFitRatio = false;
    app.add_flag("--no-bake", noBake, "only the tracing ceilings (skips the whole bake and the GEMM)");
    app.add_flag("--no-fit-ratio", noFitRatio,
                 "skip the second whole bake with --fit projection (the weighted fit's cost ratio)");
    return cli::run(app, "shrefract-bench-bake", argc, argv, [&] {
        Scene scene = loadScene(input);
        BakeOptions opt;
        opt.samples = samples;
        opt.order = order;
        opt.cacheDir = cli::defaultCacheDir();
        opt.coherent = tracerName == "coherent";

        // 1. The whole bake, as shrefract-bake runs it (the default fit: weighted), then the same
        // bake with the paper's projection: the weighted fit's cost, in wall and in CPU seconds (the
        // machine may be shared: CPU seconds are what the bake itself spent).
        BakeResult res;
        nlohmann::json fits;
        if (noBake) {
            res.data.layout = buildJoiningLayout(scene, rateForSampleCount(scene, samples));
        } else {
            double c = cpuSeconds();
            res = bake(scene, opt, input);
            const double cpuDefault = cpuSeconds() - c;
            fits[nameOf(opt.fit)] = {{"seconds", res.stats.wallSeconds}, {"cpuSeconds", cpuDefault},
                                       {"compressThreadSeconds", res.stats.compressSeconds}};
            if (!noFitRatio && opt.fit != Fit::Projection) {
                BakeOptions p = opt;
                p.fit = Fit::Projection;
                c = cpuSeconds();
                const BakeStats ps = bake(scene, p, input).stats;
                const double cpuProjection = cpuSeconds() - c;
                fits["projection"] = {{"seconds", ps.wallSeconds}, {"cpuSeconds", cpuProjection},
                                      {"compressThreadSeconds", ps.compressSeconds}};
                fits["ratio"] = {{"wall", res.stats.wallSeconds / ps.wallSeconds},
                                 {"cpu", cpuDefault / cpuProjection},
                                 {"target", 1.3},
                                 {"note", std::string(nameOf(opt.fit)) + " over projection, same run"}};
            }
            if (!noFitRatio && opt.errorOrder >= 0) {
                // The error model's cost (docs/bake.md "Error model"): the same bake without it.
                BakeOptions n = opt;
                n.errorOrder = -1;
                c = cpuSeconds();
                const BakeStats ns = bake(scene, n, input).stats;
                const double cpuNone = cpuSeconds() - c;
                fits["errorModel"] = {{"order", opt.errorOrder},
                                      {"withoutSeconds", ns.wallSeconds},
                                      {"withoutCpuSeconds", cpuNone},
                                      {"ratio", {{"wall", res.stats.wallSeconds / ns.wallSeconds},
                                                 {"cpu", cpuDefault / cpuNone}}},
                                      {"note", "the default bake over the same without an error model, same run"}};
            }
        }
        const BakeStats& st = res.stats;
        rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        const double peakMB = ru.ru_maxrss / 1024.0;

        // 2. Ceiling: the rays of a subset of samples, logged, then replayed through a bare loop.
        const SurfaceLayout& L = res.data.layout;
        Tracer tracer(scene, opt.trace);
        std::vector<int> subset;
        for (int i = 0; i < L.sampleCount(); i += stride) subset.push_back(i);
        const int J = opt.grid.count();
        std::vector<glm::vec3> dirs(J);
        for (int j = 0; j < J; ++j) dirs[j] = glm::vec3(opt.grid.direction(j));
        std::vector<std::vector<LoggedRay>> logs(subset.size());
        tbb::parallel_for(size_t(0), subset.size(), [&](size_t s) {
            enableFlushToZero();
            int i = subset[s];
            Frame f = Frame::fromNormal(L.normal[i]);
            for (int j = 0; j < J; ++j) tracer.trace(L.position[i], L.normal[i], f.fromLocal(dirs[j]), L.part[i], &logs[s]);
        });
        size_t subsetRays = 0;
        for (auto& l : logs) subsetRays += l.size();
        // Full tracing of the subset (no logging) ...
        auto t0 = Clock::now();
        double c0 = cpuSeconds();
        tbb::parallel_for(size_t(0), subset.size(), [&](size_t s) {
            enableFlushToZero();
            int i = subset[s];
            Frame f = Frame::fromNormal(L.normal[i]);
            for (int j = 0; j < J; ++j) tracer.trace(L.position[i], L.normal[i], f.fromLocal(dirs[j]), L.part[i]);
        });
        const double traceSec = since(t0), traceCpu = cpuSeconds() - c0;
        // ... the coherent tracing of the same paths ...
        const std::vector<uint32_t> packets = packetOrder(opt.grid.nTheta, opt.grid.nPhi);
        std::atomic<size_t> coherentRays{0};
        t0 = Clock::now();
        c0 = cpuSeconds();
        tbb::parallel_for(size_t(0), subset.size(), [&](size_t s) {
            enableFlushToZero();
            int i = subset[s];
            Frame f = Frame::fromNormal(L.normal[i]);
            std::vector<glm::vec3> omegas(J);
            std::vector<PathResult> paths(J);
            for (int j = 0; j < J; ++j) omegas[j] = f.fromLocal(dirs[packets[j]]);  // as the bake does
            tracer.traceCoherent(L.position[i], L.normal[i], omegas.data(), J, L.part[i], paths.data());
            size_t r = 0;
            for (const PathResult& p : paths) r += p.rays;
            coherentRays += r;
        });
        const double coherentSec = since(t0), coherentCpu = cpuSeconds() - c0;
        // ... against the bare loop over the same rays.
        t0 = Clock::now();
        c0 = cpuSeconds();
        std::atomic<size_t> hits{0};
        tbb::parallel_for(size_t(0), subset.size(), [&](size_t s) {
            enableFlushToZero();
            size_t h = 0;
            float t;
            for (const LoggedRay& r : logs[s]) h += tracer.intersect(r.org, r.dir, &t);
            hits += h;
        });
        const double bareSec = since(t0), bareCpu = cpuSeconds() - c0;

        // 3. Compression: the bake's GEMM thread time against a bare GEMM of the same shape.
        const int K = shEvenCount(order), cols = 4 * 32;
        // The same shape and operand order as the bake: W^T (cols x K) = R^T (cols x J) M^T (J x K).
        Eigen::MatrixXf Mt = Eigen::MatrixXf::Random(J, K), R = Eigen::MatrixXf::Random(J, cols), W(cols, K);
        const size_t batches = (L.sampleCount() + 31) / 32;
        t0 = Clock::now();
        for (size_t b = 0; b < batches; ++b) {
            W.noalias() = R.transpose() * Mt;
            R(b % J, 0) += W(0, 0) * 1e-30f;  // keep the optimizer honest
        }
        const double gemmSec = since(t0);
        const double flops = 2.0 * K * J * cols * batches;

        const double bakeRps = st.rays / st.wallSeconds;
        const double subsetRps = subsetRays / traceSec, bareRps = subsetRays / bareSec;
        nlohmann::json out = {
            {"mesh", input},
            {"samples", st.samples},
            {"directions", J},
            {"order", order},
            {"threads", tbb::this_task_arena::max_concurrency()},
            {"bake", {{"tracer", opt.coherent ? "coherent" : "scalar"}, {"seconds", st.wallSeconds}, {"paths", st.paths}, {"rays", st.rays},
                      {"pathsPerSecond", st.paths / st.wallSeconds}, {"raysPerSecond", bakeRps},
                      {"peakMemoryMB", peakMB}}},
            {"ceiling", {{"samples", subset.size()}, {"rays", subsetRays},
                         {"tracedRaysPerSecond", subsetRps}, {"bareEmbreeRaysPerSecond", bareRps},
                         {"ratio", subsetRps / bareRps},
                         {"coherentRays", coherentRays.load()},
                         {"coherentRaysPerSecond", coherentRays / coherentSec},
                         {"coherentRatio", coherentRays / coherentSec / bareRps},
                         {"cpuTime", {{"tracedRaysPerCpuSecond", subsetRays / traceCpu},
                                      {"coherentRaysPerCpuSecond", coherentRays / coherentCpu},
                                      {"bareEmbreeRaysPerCpuSecond", subsetRays / bareCpu},
                                      {"ratio", bareCpu / traceCpu},
                                      {"coherentRatio", (coherentRays / coherentCpu) / (subsetRays / bareCpu)}}},
                         {"target", 1.0},
                         {"note", "ratio: scalar tracer (one rtcIntersect1 per segment) / bare loop; "
                                  "coherentRatio: coherent tracer (a sample's paths step by step, the "
                                  "first step in 16-ray packets) / the same bare single-ray loop over "
                                  "the same rays"}}},
            {"compression", {{"bakeGflops", flops / st.compressSeconds * 1e-9},
                             {"bareGemmGflops", flops / gemmSec * 1e-9},
                             {"ratio", gemmSec / st.compressSeconds}, {"target", 0.7},
                             {"note", "bake: GEMM + scatter into the weight arrays, thread time; bare: GEMM alone, one thread"}}},
            {"targets", {{"bakeUnder120s", st.wallSeconds < 120}}},
            {"fits", fits},
        };
        if (noBake) {
            out.erase("bake"), out.erase("compression"), out.erase("targets"), out.erase("fits");
            out["samples"] = L.sampleCount();
        }
        writeFile(json, out.dump(2) + "\n");
        std::printf("%s\n", out.dump(2).c_str());
        return int(cli::kOk);
    });
}
