// shrefract-fit-study: which fit spends the SH bands best (issue 8, scripts/fit-study)? For random
// surface samples of a mesh it traces the full direction grid once, fits every variant (the
// paper's projection through M, plain least squares, weighted least squares with several
// weightings) and measures each against fresh traces at random off-grid directions, per path
// class, beside the data ceiling (the raw grid interpolated bilinearly).
#include <CLI/CLI.hpp>

#include <tbb/parallel_for.h>

#include <cstdio>
#include <fstream>
#include <random>

#include "bake/fit.h"
#include "bake/joining_layout.h"
#include "bake/tracer.h"
#include "common/cli/cli.h"
#include "common/direction_grid.h"
#include "common/frame.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/sh.h"
#include "eval/directions.h"

using namespace shrefract;

namespace {

struct Variant {
    std::string name;
    enum Kind { Projection, LeastSquares, Weighted, Ceiling } kind;
    FitWeighting weighting;
};

double angleDeg(glm::vec3 a, glm::vec3 b) {
    const float len = glm::length(a);
    const double c = len > 0 ? glm::dot(a / len, b) : -1.0;
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"shrefract-fit-study: projection, least squares and weighted fits against fresh traces"};
    std::string mesh, gridText = "32x64", jsonPath, branch = "fresnel";
    int order = 8, studySamples = 1500, dirsPerSample = 64;
    size_t samples = 35000;
    double ior = 1.5;
    uint64_t seed = 1;
    // Each ingredient alone, then together (FLAGGED:DEG:DISAGREEING:TRIMDEG:TRIMMED:PASSES).
    std::vector<std::string> weightings = {"0.03:0:1:20:1:0",  "0.3:0:1:20:1:0",  "1:30:0.01:20:1:0",
                                           "1:0:1:20:0.03:1",  "0.3:30:0.01:20:1:0",
                                           "0.3:30:0.01:20:0.03:1", "0.3:30:0.01:20:0.03:2",
                                           "0.3:30:0.01:10:0.03:1", "0.3:30:0.01:10:0.03:2",
                                           "0.3:30:0.01:30:0.03:1"};
    app.add_option("mesh", mesh, "mesh or scene")->required();
    app.add_option("--weighting", weightings,
                   "weighted fits to study, FLAGGED:DEG:DISAGREEING:TRIMDEG:TRIMMED:PASSES each (bake/fit.h)")
        ->capture_default_str();
    app.add_option("--samples", samples, "the bake's sample target (sets the rate)")->capture_default_str();
    app.add_option("--study-samples", studySamples, "random surface samples studied")->capture_default_str();
    app.add_option("--dirs", dirsPerSample, "random off-grid directions per sample")->capture_default_str();
    app.add_option("--order", order)->capture_default_str();
    app.add_option("--grid", gridText)->capture_default_str();
    app.add_option("--ior", ior)->capture_default_str();
    app.add_option("--branch", branch)->capture_default_str()->check(CLI::IsMember({"fresnel", "transmit"}));
    app.add_option("--seed", seed)->capture_default_str();
    app.add_option("--json", jsonPath, "write every number here");
    return cli::run(app, "shrefract-fit-study", argc, argv, [&] {
        OutputSet outputs;  // checked before the study, written when it is complete
        const std::string stagedJson = jsonPath.empty() ? "" : outputs.add(jsonPath);
        Medium medium;
        medium.ior = ior;
        const Scene scene = loadScene(mesh, medium);
        const DirectionGrid grid = parseGrid(gridText);
        const SurfaceLayout L = buildJoiningLayout(scene, rateForSampleCount(scene, samples));
        TraceOptions topt;
        topt.branch = branch == "transmit" ? Branch::Transmit : Branch::Fresnel;
        const Tracer tracer(scene, topt);
        const int J = grid.count(), K = shEvenCount(order), S = studySamples, D = dirsPerSample;

        std::mt19937_64 rng(seed);
        std::uniform_int_distribution<int> pick(0, L.sampleCount() - 1);
        std::uniform_real_distribution<float> U(0.0f, 1.0f);
        std::vector<int> sample(S);
        std::vector<glm::vec3> omega(size_t(S) * D);
        for (int s = 0; s < S; ++s) {
            sample[s] = pick(rng);
            for (int d = 0; d < D; ++d) {
                const float z = U(rng), phi = 6.2831853f * U(rng), r = std::sqrt(std::max(0.0f, 1 - z * z));
                omega[size_t(s) * D + d] = {r * std::cos(phi), r * std::sin(phi), z};
            }
        }
        // Trace every sample's grid and its random directions once.
        std::vector<PathResult> gridPaths(size_t(S) * J), truth(size_t(S) * D);
        tbb::parallel_for(0, S, [&](int s) {
            enableFlushToZero();
            const int i = sample[s];
            const Frame f = Frame::fromNormal(L.normal[i]);
            for (int j = 0; j < J; ++j)
                gridPaths[size_t(s) * J + j] = tracer.trace(L.position[i], L.normal[i],
                                                            f.fromLocal(glm::vec3(grid.direction(j))), L.part[i]);
            for (int d = 0; d < D; ++d)
                truth[size_t(s) * D + d] = tracer.trace(L.position[i], L.normal[i],
                                                        f.fromLocal(omega[size_t(s) * D + d]), L.part[i]);
        });
        std::fprintf(stderr, "fit-study: traced %d samples x (%d grid + %d random) directions\n", S, J, D);

        std::vector<Variant> variants = {{"ceiling (raw grid, bilinear)", Variant::Ceiling, {}},
                                         {"projection (paper)", Variant::Projection, {}},
                                         {"least squares", Variant::LeastSquares, {}}};
        // Weightings from the command line (FitWeighting::parse).
        for (const std::string& text : weightings)
            variants.push_back({"weighted " + text, Variant::Weighted, FitWeighting::parse(text, "--weighting")});
        const Eigen::MatrixXf M = compressionMatrix(grid, order).cast<float>();
        const Eigen::MatrixXf Mlsq = leastSquaresMatrix(grid, order).cast<float>();

        nlohmann::json report = {{"mesh", mesh}, {"order", order}, {"grid", gridText}, {"studySamples", S},
                                 {"directionsPerSample", D}, {"rate", L.rate}, {"variants", nlohmann::json::array()}};
        std::printf("%-44s | %-22s | %-22s | %-22s | %s\n", "fit", "all: median p95", "plain: median p95",
                    "TIR/re-entered: median", "len err mean (all, plain)");
        for (const Variant& v : variants) {
            std::vector<double> ang(size_t(S) * D), len(size_t(S) * D);
            std::unique_ptr<WeightedFitter> fitter;
            if (v.kind == Variant::Weighted) fitter = std::make_unique<WeightedFitter>(grid, order, v.weighting);
            tbb::parallel_for(0, S, [&](int s) {
                Eigen::MatrixXf R(J, 4), W(K, 4);
                for (int j = 0; j < J; ++j) {
                    const PathResult& p = gridPaths[size_t(s) * J + j];
                    R.row(j) << p.exit.x, p.exit.y, p.exit.z, p.length;
                }
                if (v.kind == Variant::Projection) W = M * R;
                if (v.kind == Variant::LeastSquares) W = Mlsq * R;
                if (v.kind == Variant::Weighted) {
                    std::vector<float> c(J);
                    fitter->confidence(&gridPaths[size_t(s) * J], c.data());
                    fitter->fit(R, c.data(), W);
                }
                std::vector<float> basis(K);
                for (int d = 0; d < D; ++d) {
                    const size_t at = size_t(s) * D + d;
                    glm::vec4 e(0.0f);
                    if (v.kind == Variant::Ceiling) {
                        int index[4];
                        double weight[4];
                        const int n = grid.interpolate(glm::dvec3(omega[at]), index, weight);
                        for (int q = 0; q < n; ++q)
                            e += float(weight[q]) * glm::vec4(R(index[q], 0), R(index[q], 1), R(index[q], 2), R(index[q], 3));
                    } else {
                        shEvalEven(order, omega[at], basis.data());
                        for (int k = 0; k < K; ++k) e += basis[k] * glm::vec4(W(k, 0), W(k, 1), W(k, 2), W(k, 3));
                    }
                    ang[at] = angleDeg(glm::vec3(e), truth[at].exit);
                    len[at] = std::abs(double(e.w) - truth[at].length);
                }
            });
            auto stats = [&](int cls) {  // 0 all, 1 plain, 2 TIR or re-entered
                std::vector<double> a, l;
                for (size_t at = 0; at < ang.size(); ++at) {
                    const bool chaotic = truth[at].flags & (kPathTIR | kPathReentered | kPathCapped);
                    if (cls == 1 && chaotic) continue;
                    if (cls == 2 && !chaotic) continue;
                    a.push_back(ang[at]), l.push_back(len[at]);
                }
                return nlohmann::json{{"angleDeg", errorStats(a)}, {"lengthError", errorStats(l)}};
            };
            const nlohmann::json all = stats(0), plain = stats(1), chaotic = stats(2);
            std::printf("%-44s | %8.2f %10.2f   | %8.2f %10.2f   | %8.2f               | %.3f %.3f\n", v.name.c_str(),
                        all["angleDeg"]["median"].get<double>(), all["angleDeg"]["p95"].get<double>(),
                        plain["angleDeg"]["median"].get<double>(), plain["angleDeg"]["p95"].get<double>(),
                        chaotic["angleDeg"]["median"].get<double>(), all["lengthError"]["mean"].get<double>(),
                        plain["lengthError"]["mean"].get<double>());
            std::fflush(stdout);
            report["variants"].push_back({{"name", v.name}, {"weighting", v.weighting.ToString()},
                                          {"all", all}, {"plain", plain}, {"chaotic", chaotic}});
        }
        if (!jsonPath.empty()) writeFile(stagedJson, report.dump(1) + "\n");
        outputs.commit();
        return cli::kOk;
    });
}
