// shrefract-fit-study: which fit spends the SH bands best (issue 8, scripts/fit-study)? For random
// surface samples of a mesh it traces the full direction grid once, fits every variant (the
// paper's projection through M, plain least squares, weighted least squares with several
// weightings) and measures each against fresh traces at random off-grid directions, per path
// class, beside the data ceiling (the raw grid interpolated bilinearly). A "split" variant is a
// representation with an edge (bake/split_fit.h), alone or picked per sample against the
// whole-hemisphere fit (scripts/study-edge). A "learned" variant spends K coefficients on a basis
// learned from the mesh itself instead of the SH (--learned; docs/bake.md "A learned basis").
#include <CLI/CLI.hpp>

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <random>

#include "bake/fit.h"
#include "bake/learned_basis.h"
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
    enum Kind { Projection, LeastSquares, Weighted, Ceiling, Split, Learned, LearnedVector } kind;
    FitWeighting weighting;
    // Split: the two branches' order, the indicator's order and the class it marks.
    int branchOrder = 0, indicatorOrder = 0;
    uint32_t label = 0;
    bool pick = false;  // per sample, the split or the whole-hemisphere fit at --order, whichever fits the grid better
    int learned = 0;    // Learned, LearnedVector: how many of the learned basis functions
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
    std::vector<int> learned, learnedVector;
    int learnSamples = 3000;
    app.add_option("--learned", learned,
                   "learned bases to study, K coefficients each: the K functions of the grid that carry "
                   "most of the exits of --learn-samples other samples, fitted with the default weighting")
        ->check(CLI::Range(1, 1024));
    app.add_option("--learned-vector", learnedVector,
                   "learned vector bases to study, K coefficients each: K functions to (local exit, "
                   "length), one coefficient each")
        ->check(CLI::Range(1, 4096));
    app.add_option("--learn-samples", learnSamples, "random surface samples the learned basis is learned from")
        ->capture_default_str()->check(CLI::PositiveNumber);
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
        // The learned bases' sizes, checked before any tracing.
        const int Kmax = learned.empty() ? 0 : *std::max_element(learned.begin(), learned.end());
        const int KVmax = learnedVector.empty() ? 0 : *std::max_element(learnedVector.begin(), learnedVector.end());
        if (Kmax > J)
            throw InputError("--learned " + std::to_string(Kmax) + ": more functions than the grid's " +
                             std::to_string(J) + " directions");
        if (KVmax > learnSamples)
            throw InputError("--learned-vector " + std::to_string(KVmax) + ": more functions than --learn-samples " +
                             std::to_string(learnSamples));

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
        // The default weighting's c_j: what the learned bases are learned and fitted with.
        const WeightedFitter defaultConfidence(grid, order, FitWeighting{});
        // Sample i's paths along the J grid directions, into out[0..J).
        auto traceGrid = [&](int i, PathResult* out) {
            const Frame f = Frame::fromNormal(L.normal[i]);
            for (int j = 0; j < J; ++j)
                out[j] = tracer.trace(L.position[i], L.normal[i], f.fromLocal(glm::vec3(grid.direction(j))), L.part[i]);
        };
        // Trace every sample's grid and its random directions once.
        std::vector<PathResult> gridPaths(size_t(S) * J), truth(size_t(S) * D);
        tbb::parallel_for(0, S, [&](int s) {
            enableFlushToZero();
            const int i = sample[s];
            const Frame f = Frame::fromNormal(L.normal[i]);
            traceGrid(i, &gridPaths[size_t(s) * J]);
            for (int d = 0; d < D; ++d)
                truth[size_t(s) * D + d] = tracer.trace(L.position[i], L.normal[i],
                                                        f.fromLocal(omega[size_t(s) * D + d]), L.part[i]);
        });
        std::fprintf(stderr, "fit-study: traced %d samples x (%d grid + %d random) directions\n", S, J, D);

        // The learned basis, from other samples than the studied ones (so the study measures how it
        // carries over to samples it has not seen, as a bake's basis would to the runtime's
        // interpolated points).
        Eigen::MatrixXf learnedBasis, learnedVectorBasis;
        std::vector<double> learnedEnergy, learnedVectorEnergy;
        if (Kmax > 0 || KVmax > 0) {
            std::vector<PathResult> learnPaths(size_t(learnSamples) * J);
            std::mt19937_64 learnRng(seed ^ 0x9e3779b97f4a7c15ull);
            std::vector<int> learnSample(learnSamples);
            std::vector<Frame> learnFrames;
            for (int& i : learnSample) i = pick(learnRng), learnFrames.push_back(Frame::fromNormal(L.normal[i]));
            tbb::parallel_for(0, learnSamples, [&](int s) {
                enableFlushToZero();
                traceGrid(learnSample[s], &learnPaths[size_t(s) * J]);
            });
            if (Kmax > 0) {
                LearnedBasis b = learnScalarBasis(learnPaths, grid, defaultConfidence, Kmax);
                learnedBasis = std::move(b.values), learnedEnergy = std::move(b.energy);
            }
            if (KVmax > 0) {
                LearnedBasis b = learnVectorBasis(learnPaths, grid, defaultConfidence, learnFrames, KVmax);
                learnedVectorBasis = std::move(b.values), learnedVectorEnergy = std::move(b.energy);
            }
            auto say = [&](const char* what, const std::vector<int>& ks, const std::vector<double>& energy) {
                double captured = 0;
                for (size_t k = 0; k < energy.size(); ++k) {
                    captured += energy[k];
                    if (std::find(ks.begin(), ks.end(), int(k) + 1) != ks.end())
                        std::fprintf(stderr, "fit-study: %s from %d samples: %zu functions carry %.5f of the energy\n",
                                     what, learnSamples, k + 1, captured);
                }
            };
            say("learned basis", learned, learnedEnergy);
            say("learned vector basis", learnedVector, learnedVectorEnergy);
        }

        std::vector<Variant> variants = {{"ceiling (raw grid, bilinear)", Variant::Ceiling, {}},
                                         {"projection (paper)", Variant::Projection, {}},
                                         {"least squares", Variant::LeastSquares, {}}};
        // Weightings from the command line (FitWeighting::parse).
        for (const std::string& text : weightings)
            variants.push_back({"weighted " + text, Variant::Weighted, FitWeighting::parse(text, "--weighting")});
        variants.insert(variants.end(), splitVariants.begin(), splitVariants.end());
        for (int k : learned) {
            Variant v{"learned " + std::to_string(k) + " (weighted " + FitWeighting{}.ToString() + ")",
                      Variant::Learned, FitWeighting{}};
            v.learned = k;
            variants.push_back(v);
        }
        for (int k : learnedVector) {
            Variant v{"learned vector " + std::to_string(k) + " (weighted " + FitWeighting{}.ToString() + ")",
                      Variant::LearnedVector, FitWeighting{}};
            v.learned = k;
            variants.push_back(v);
        }
        const Eigen::MatrixXf M = compressionMatrix(grid, order).cast<float>();
        const Eigen::MatrixXf Mlsq = leastSquaresMatrix(grid, order).cast<float>();

        nlohmann::json report = {{"mesh", mesh}, {"order", order}, {"grid", gridText}, {"studySamples", S},
                                 {"directionsPerSample", D}, {"rate", L.rate}, {"variants", nlohmann::json::array()}};
        if (!learned.empty())
            report["learned"] = {{"samples", learnSamples}, {"energy", learnedEnergy}, {"vectorEnergy", learnedVectorEnergy}};
        std::printf("%-44s | %-6s | %-22s | %-22s | %-22s | %s\n", "fit", "floats", "all: median p95",
                    "plain: median p95", "flagged: median, TIR", "len err mean (all, plain)");
        for (const Variant& v : variants) {
            std::vector<double> ang(size_t(S) * D), len(size_t(S) * D);
            std::unique_ptr<WeightedFitter> fitter;
            std::unique_ptr<SplitFitter> splitter;
            if (v.kind == Variant::Weighted) fitter = std::make_unique<WeightedFitter>(grid, order, v.weighting);
            if (v.pick) fitter = std::make_unique<WeightedFitter>(grid, order, FitWeighting{});
            if (v.kind == Variant::Learned)
                fitter = std::make_unique<WeightedFitter>(grid, learnedBasis.leftCols(v.learned), v.weighting);
            if (v.kind == Variant::Split)
                splitter = std::make_unique<SplitFitter>(grid, v.branchOrder, v.indicatorOrder, v.label);
            std::atomic<int> picked{0};
            tbb::parallel_for(0, S, [&](int s) {
                const PathResult* paths = &gridPaths[size_t(s) * J];
                Eigen::MatrixXf R(J, 4), W(fitter ? fitter->coefficients() : K, 4);
                // The vector basis fits the exits as its sample's frame sees them, and its
                // reconstruction goes back to object space before it is measured.
                const Frame frame = Frame::fromNormal(L.normal[sample[s]]);
                const bool local = v.kind == Variant::LearnedVector;
                for (int j = 0; j < J; ++j) {
                    const glm::vec3 e = local ? frame.toLocal(paths[j].exit) : paths[j].exit;
                    R.row(j) << e.x, e.y, e.z, paths[j].length;
                }
                if (v.kind == Variant::Projection) W = M * R;
                if (v.kind == Variant::LeastSquares) W = Mlsq * R;
                std::vector<float> c(J, 1.0f);
                if (fitter) {
                    fitter->confidence(paths, c.data());
                    fitter->fit(R, c.data(), W);
                }
                // A learned basis is known at the grid directions only: between them it is read as the
                // grid is, bilinearly, so its fit is evaluated through its values at the grid.
                Eigen::MatrixXf Rlearned;
                if (v.kind == Variant::Learned) Rlearned = learnedBasis.leftCols(v.learned) * W;
                if (v.kind == Variant::LearnedVector) {
                    std::vector<float> cj(J);
                    defaultConfidence.confidence(paths, cj.data());
                    Rlearned = fitVectorBasis(learnedVectorBasis.leftCols(v.learned), R, grid, cj, v.weighting);
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
                    if (v.kind == Variant::Ceiling || v.kind == Variant::Learned || v.kind == Variant::LearnedVector) {
                        const Eigen::MatrixXf& G = v.kind == Variant::Ceiling ? R : Rlearned;
                        int index[4];
                        double weight[4];
                        const int n = grid.interpolate(glm::dvec3(omega[at]), index, weight);
                        for (int q = 0; q < n; ++q)
                            e += float(weight[q]) * glm::vec4(G(index[q], 0), G(index[q], 1), G(index[q], 2), G(index[q], 3));
                    } else {
                        e = useSplit ? splitter->evaluate(split, omega[at]) : whole(omega[at]);
                    }
                    if (local) e = glm::vec4(frame.fromLocal(glm::vec3(e)), e.w);
                    ang[at] = angleDeg(glm::vec3(e), truth[at].exit);
                    len[at] = std::abs(double(e.w) - truth[at].length);
                }
            });
            // A picked mix stores each sample's own length (variable-length coefficients): the mean.
            double floats = v.kind == Variant::Ceiling ? 4 * J
                          : v.kind == Variant::Learned ? 4 * v.learned
                          : v.kind == Variant::LearnedVector ? v.learned
                          : splitter ? splitter->floats() : 4 * K;
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
