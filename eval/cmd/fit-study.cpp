// shrefract-fit-study: which fit spends the SH bands best (issue 8, scripts/fit-study)? For random
// surface samples of a mesh it traces the full direction grid once, fits every variant (the
// paper's projection through M, plain least squares, weighted least squares with several
// weightings) and measures each against fresh traces at random off-grid directions, per path
// class, beside the data ceiling (the raw grid interpolated bilinearly). A "split" variant is a
// representation with an edge (bake/split_fit.h), alone or picked per sample against the
// whole-hemisphere fit (scripts/study-edge).
#include <CLI/CLI.hpp>

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <random>

#include "bake/fit.h"
#include "bake/split_fit.h"
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
    enum Kind { Projection, LeastSquares, Weighted, Ceiling, Split } kind;
    FitWeighting weighting;
    // Split: the two branches' order, the indicator's order and the class it marks.
    int branchOrder = 0, indicatorOrder = 0;
    uint32_t label = 0;
    bool pick = false;  // per sample, the split or the whole-hemisphere fit at --order, whichever fits the grid better
};

// "BRANCH:INDICATOR:tir|flagged[:pick]", e.g. "8:4:tir" (--split).
Variant parseSplit(const std::string& text) {
    Variant v{"split " + text, Variant::Split, {}};
    char cls[16] = {0}, pick[16] = {0};
    const int n = std::sscanf(text.c_str(), "%d:%d:%15[a-z]:%15s", &v.branchOrder, &v.indicatorOrder, cls, pick);
    if (n < 3 || v.branchOrder < 0 || v.indicatorOrder < 0 || v.branchOrder > 16 || v.indicatorOrder > 16 ||
        (std::string(cls) != "tir" && std::string(cls) != "flagged") || (n == 4 && std::string(pick) != "pick"))
        throw InputError("--split " + text + ": expected BRANCH:INDICATOR:tir|flagged[:pick], orders 0..16");
    v.pick = n == 4;
    v.label = std::string(cls) == "tir" ? uint32_t(kPathTIR) : uint32_t(kPathTIR | kPathReentered | kPathCapped);
    return v;
}

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
    std::vector<std::string> splits;
    app.add_option("--split", splits,
                   "representations with an edge to study (bake/split_fit.h), BRANCH:INDICATOR:tir|flagged[:pick] each: orders, the class, and :pick to keep per sample the split or the --order fit, whichever fits the grid better");
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
        std::vector<Variant> splitVariants;  // parsed before the tracing, so that a typo costs nothing
        for (const std::string& text : splits) splitVariants.push_back(parseSplit(text));
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
        variants.insert(variants.end(), splitVariants.begin(), splitVariants.end());
        const Eigen::MatrixXf M = compressionMatrix(grid, order).cast<float>();
        const Eigen::MatrixXf Mlsq = leastSquaresMatrix(grid, order).cast<float>();

        nlohmann::json report = {{"mesh", mesh}, {"order", order}, {"grid", gridText}, {"studySamples", S},
                                 {"directionsPerSample", D}, {"rate", L.rate}, {"variants", nlohmann::json::array()}};
        std::printf("%-44s | %-6s | %-22s | %-22s | %-22s | %s\n", "fit", "floats", "all: median p95",
                    "plain: median p95", "flagged: median, TIR", "len err mean (all, plain)");
        for (const Variant& v : variants) {
            std::vector<double> ang(size_t(S) * D), len(size_t(S) * D);
            std::unique_ptr<WeightedFitter> fitter;
            std::unique_ptr<SplitFitter> splitter;
            if (v.kind == Variant::Weighted) fitter = std::make_unique<WeightedFitter>(grid, order, v.weighting);
            if (v.pick) fitter = std::make_unique<WeightedFitter>(grid, order, FitWeighting{});
            if (v.kind == Variant::Split)
                splitter = std::make_unique<SplitFitter>(grid, v.branchOrder, v.indicatorOrder, v.label);
            std::atomic<int> picked{0};
            tbb::parallel_for(0, S, [&](int s) {
                const PathResult* paths = &gridPaths[size_t(s) * J];
                Eigen::MatrixXf R(J, 4), W(K, 4);
                for (int j = 0; j < J; ++j) R.row(j) << paths[j].exit.x, paths[j].exit.y, paths[j].exit.z, paths[j].length;
                if (v.kind == Variant::Projection) W = M * R;
                if (v.kind == Variant::LeastSquares) W = Mlsq * R;
                std::vector<float> c(J, 1.0f);
                if (fitter) {
                    fitter->confidence(paths, c.data());
                    fitter->fit(R, c.data(), W);
                }
                SplitModel split;
                if (splitter) split = splitter->fit(R, paths);
                auto whole = [&](glm::vec3 w) { return evaluateFit(order, W, w); };
                // Pick: the split only where it misses the grid's own exits by less, on the mean over
                // the grid directions, than the whole-hemisphere fit at `order` (the bake's default
                // weighting) does. The bake can do this: it knows the exits at the grid.
                bool useSplit = v.kind == Variant::Split;
                if (v.pick) {
                    double errSplit = 0, errWhole = 0;
                    for (int j = 0; j < J; ++j) {
                        const glm::vec3 w(grid.direction(j));
                        errSplit += c[j] * angleDeg(glm::vec3(splitter->evaluate(split, w)), paths[j].exit);
                        errWhole += c[j] * angleDeg(glm::vec3(whole(w)), paths[j].exit);
                    }
                    useSplit = errSplit < errWhole;
                    picked += useSplit;
                }
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
                        e = useSplit ? splitter->evaluate(split, omega[at]) : whole(omega[at]);
                    }
                    ang[at] = angleDeg(glm::vec3(e), truth[at].exit);
                    len[at] = std::abs(double(e.w) - truth[at].length);
                }
            });
            // A picked mix stores each sample's own length (variable-length coefficients): the mean.
            double floats = v.kind == Variant::Ceiling ? 4 * J : splitter ? splitter->floats() : 4 * K;
            if (v.pick) {
                const double share = double(picked.load()) / S;
                floats = share * floats + (1 - share) * 4 * K;
                std::fprintf(stderr, "fit-study: %s: %d of %d samples split\n", v.name.c_str(), picked.load(), S);
            }
            auto stats = [&](int cls) {  // 0 all, 1 plain, 2 flagged (TIR, re-entered or capped), 3 TIR
                std::vector<double> a, l;
                for (size_t at = 0; at < ang.size(); ++at) {
                    const bool chaotic = truth[at].flags & (kPathTIR | kPathReentered | kPathCapped);
                    if (cls == 1 && chaotic) continue;
                    if (cls == 2 && !chaotic) continue;
                    if (cls == 3 && !(truth[at].flags & kPathTIR)) continue;
                    a.push_back(ang[at]), l.push_back(len[at]);
                }
                return nlohmann::json{{"angleDeg", errorStats(a)}, {"lengthError", errorStats(l)}};
            };
            const nlohmann::json all = stats(0), plain = stats(1), chaotic = stats(2), tir = stats(3);
            const auto median = [](const nlohmann::json& j) {
                return j["angleDeg"]["count"].get<double>() > 0 ? j["angleDeg"]["median"].get<double>() : 0.0;
            };
            std::printf("%-44s | %6.0f | %8.2f %10.2f   | %8.2f %10.2f   | %8.2f %8.2f      | %.3f %.3f\n",
                        v.name.c_str(), floats, median(all), all["angleDeg"]["p95"].get<double>(),
                        median(plain), plain["angleDeg"]["p95"].get<double>(), median(chaotic), median(tir),
                        all["lengthError"]["mean"].get<double>(), plain["lengthError"]["mean"].get<double>());
            std::fflush(stdout);
            report["variants"].push_back({{"name", v.name}, {"weighting", v.weighting.ToString()},
                                          {"floatsPerSample", floats},
                                          {"all", all}, {"plain", plain}, {"chaotic", chaotic}, {"tir", tir}});
        }
        if (!jsonPath.empty()) writeFile(stagedJson, report.dump(1) + "\n");
        outputs.commit();
        return cli::kOk;
    });
}
