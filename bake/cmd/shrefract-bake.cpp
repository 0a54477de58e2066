// shrefract-bake: a glass mesh or scene in, a NAME.shrefract.exr file of SH weights out.
// A thin shell over bake/ (bake.h); options in docs/bake.md.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "bake/bake.h"
#include "bake/joining_layout.h"
#include "bake/shard.h"
#include "bake/target.h"
#include "bake/cmd/common_cli.h"
#include "common/cli/cli.h"
#include "common/error.h"
#include "common/gltf_scene.h"
#include "common/limits.h"
#include "common/output.h"

using namespace shrefract;
namespace fs = std::filesystem;

namespace {
constexpr const char* kTool = "shrefract-bake";
using Clock = std::chrono::steady_clock;
}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"shrefract-bake: trace the refracted-path mapping of a glass object with Embree, "
                 "compress it onto spherical harmonics, write it as OpenEXR."};
    BakeOptions opt;
    std::string input, output, grid = "32x64", branch = "fresnel", precision = nameOf(opt.precision);
    double ior = 1.5;
    int rate = 0;
    size_t samples = 35000;
    std::string cache = cli::defaultCacheDir();
    bool quiet = false;
    double targetError = 0;
    std::string targetReport;
    app.add_option("input", input, "mesh (.obj .off .ply .stl), scene (.json) or glTF (.gltf .glb)")->required();
    auto* outputOpt = app.add_option("-o,--output", output, "output file, NAME.shrefract.exr (required unless --search-only)");
    std::string basis = nameOf(opt.basis);
    app.add_option("--basis", basis,
                   "sh: fit each sample's directions with SH (the paper); grid: store the traced "
                   "grid itself, one RGBA8 texel per --grid direction, no fit (docs/bake.md "
                   "\"The grid basis\")")
        ->capture_default_str()->check(CLI::IsMember({"sh", "grid"}));
    app.add_option("--order", opt.order, "SH order L: bands 0..L")->capture_default_str()->check(CLI::Range(0, limits::kMaxOrder));
    std::string layout = "joining", texels;
    app.add_option("--layout", layout,
                   "joining: every triangle on a barycentric grid (paper 5.3); isolated: charts cut "
                   "and unfolded by CGAL into an atlas (paper 5.2); uv: the mesh's own texture "
                   "coordinates as the charts")
        ->capture_default_str()->check(CLI::IsMember({"joining", "isolated", "uv"}));
    auto* rateOpt = app.add_option("--rate", rate, "joining: grid steps per triangle edge (overrides --samples)")
                        ->check(CLI::Range(1, limits::kMaxRate));
    auto* texelsOpt = app.add_option("--texels", texels,
                                     "isolated, uv: the atlas size WxH or W (square), instead of "
                                     "the one whose covered texels reach --samples");
    app.add_option("--samples", samples,
                   "target number of surface samples (joining: unique grid samples; isolated, uv: "
                   "covered texels)")
        ->capture_default_str()->check(CLI::Range(size_t(1), size_t(50'000'000)))->excludes(rateOpt)
        ->excludes(texelsOpt);
    app.add_option("--gutter", opt.charts.gutter,
                   "isolated: texels kept free around every chart; isolated, uv: gutter texels that "
                   "get seam-aware sources")
        ->capture_default_str()->check(CLI::Range(0, 64));
    app.add_option("--cone", opt.charts.coneDegrees,
                   "isolated: largest angle in degrees between a face's normal and its chart's seed")
        ->capture_default_str()->check(CLI::Range(1.0, 89.0));
    app.add_option("--grid", grid, "view directions over the hemisphere, NTHETAxNPHI")->capture_default_str();
    app.add_option("--ior", ior, "index of refraction for a bare mesh")->capture_default_str()->check(CLI::Range(limits::kMinIor, limits::kMaxIor));
    app.add_option("--branch", branch, "fresnel: larger Fresnel branch; transmit: refract unless TIR")
        ->capture_default_str()->check(CLI::IsMember({"fresnel", "transmit"}));
    app.add_option("--max-bounces", opt.trace.maxBounces, "bounce cap per path")->capture_default_str()->check(CLI::Range(1, limits::kMaxBounces));
    app.add_option("--filter", opt.filterWidth, "semi-Gaussian SH low-pass width in bands (0: none)")
        ->capture_default_str()->check(CLI::Range(0.0, limits::kMaxFilterWidth));
    std::string fit = nameOf(opt.fit), weighting = opt.weighting.ToString();
    app.add_option("--fit", fit, "projection: W = M R through the compression matrix (the paper); lsq: "
                                 "least squares on the grid samples; weighted: least squares weighted by "
                                 "each path's confidence (docs/bake.md \"Fits\")")
        ->capture_default_str()->check(CLI::IsMember({"projection", "lsq", "weighted"}));
    app.add_option("--fit-weighting", weighting,
                   "--fit weighted: FLAGGED:DEG:DISAGREEING:TRIMDEG:TRIMMED:PASSES (bake/fit.h)")
        ->capture_default_str();
    app.add_option("--error-order", opt.errorOrder,
                   "SH order of the stored error model, the stored model's angular error over the "
                   "view directions (docs/bake.md \"Error model\"; -1: none; with --basis grid it "
                   "traces the cells' corners too)")
        ->capture_default_str()->check(CLI::Range(-1, limits::kMaxErrorOrder));
    app.add_option("--precision", precision, "weight storage: f32, f16 or u8")->capture_default_str()
        ->check(CLI::IsMember({"f32", "f16", "u8"}));
    app.add_option("--threads", opt.threads, "worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
    app.add_option("--cache", cache, "folder for cached compression matrices (empty: none)")->capture_default_str();
    app.add_option("--target-error", targetError,
                   "pick the smallest basis, order, rate and grid whose median error on held-out "
                   "directions is at most DEG degrees (overrides --order, --rate, --grid; a given "
                   "--basis or --precision limits the search to it)")
        ->check(CLI::Range(0.001, 180.0));
    double budgetMB = 0;
    app.add_option("--budget", budgetMB,
                   "pick the basis, order, rate, grid and precision with the lowest median error on "
                   "held-out directions whose weights fit in MB megabytes (10^6 bytes; overrides "
                   "--order, --rate, --grid; a given --basis or --precision limits the search to it)")
        ->check(CLI::PositiveNumber)->excludes("--target-error");
    app.add_option("--target-report", targetReport, "write the --target-error or --budget search as JSON");
    bool searchOnly = false;
    app.add_flag("--search-only", searchOnly,
                 "with --target-error or --budget: print the choice and the options that bake it "
                 "(and write --target-report), then stop; no -o, nothing baked")
        ->excludes(outputOpt);
    std::string shardText, workDir, tracer = "coherent";
    int checkpoints = 0;
    bool resume = false;
    app.add_option("--shard", shardText,
                   "bake slice I of N (I/N) into the -o shard file for shrefract-merge; N alone: "
                   "the index from SLURM_ARRAY_TASK_ID");
    app.add_option("--checkpoints", checkpoints,
                   "slices a whole bake writes to its work folder as it goes (0: one per 2^24 "
                   "paths; 1: none)")->capture_default_str()->check(CLI::Range(0, 1000000));
    app.add_option("--work", workDir, "the checkpoints' folder (default: OUTPUT.work)");
    app.add_flag("--resume", resume,
                 "keep the complete checkpoints of an interrupted bake (or, with --shard, a "
                 "complete shard file) and bake only the rest");
    app.add_option("--tracer", tracer, "coherent: a sample's paths as Embree ray streams; scalar: "
                                       "one ray at a time (the reference)")
        ->capture_default_str()->check(CLI::IsMember({"coherent", "scalar"}));
    app.add_flag("-q,--quiet", quiet, "no progress output");
    const auto start = Clock::now();
    std::string checkpointDir;  // set once a checkpointed bake has begun

    return cli::run(app, kTool, argc, argv, [&] {
        try {
            // Stop cleanly on Ctrl-C or SIGTERM: the bake polls the flag, nothing is written.
            opt.cancel = cli::cancelOnSignals();
            opt.rate = rate;
            opt.samples = samples;
            opt.layout = parseName<LayoutKind>(layout);
            opt.basis = parseName<Basis>(basis);
            if (opt.basis == Basis::Grid) {
                for (const char* o : {"--order", "--fit", "--fit-weighting", "--filter"})
                    if (app.count(o) > 0)
                        throw InputError(str(o, " shapes an SH fit; --basis grid stores the traced grid unfitted"));
            }
            if (opt.layout != LayoutKind::Joining && rate > 0)
                throw InputError("--rate is for --layout joining; chart layouts take --samples or --texels");
            if (opt.layout == LayoutKind::Joining && !texels.empty())
                throw InputError("--texels is for --layout isolated or uv");
            const bool search = targetError > 0 || budgetMB > 0;
            const char* searchFlag = targetError > 0 ? "--target-error" : "--budget";
            if (searchOnly && !search) throw InputError("--search-only needs --target-error or --budget");
            if (output.empty() && !searchOnly) throw InputError("-o,--output is required");
            if (opt.layout != LayoutKind::Joining && search)
                throw InputError(str(searchFlag, " searches joining layouts only"));
            if (!texels.empty()) {
                int w = 0, h = 0;
                char x = 0, extra = 0;
                const int got = std::sscanf(texels.c_str(), "%d%c%d%c", &w, &x, &h, &extra);
                if (got == 1) h = w;
                if (!((got == 1) || (got == 3 && (x == 'x' || x == 'X'))) || w < 1 || h < 1 ||
                    w > 16384 || h > 16384)
                    throw InputError("--texels: expected WxH or W (1 to 16384), got '" + texels + "'");
                opt.charts.texels = {w, h};
            }
            opt.grid = parseGrid(grid, "--grid");
            opt.trace.branch = branch == "transmit" ? Branch::Transmit : Branch::Fresnel;
            opt.precision = parseName<Precision>(precision);
            opt.fit = parseName<Fit>(fit);
            opt.weighting = FitWeighting::parse(weighting);
            opt.cacheDir = cache;
            opt.coherent = tracer == "coherent";
            ShardSlice slice;
            if (!shardText.empty()) {
                slice = parseShard(shardText, std::getenv("SLURM_ARRAY_TASK_ID"));
                if (search)
                    throw InputError(str(searchFlag, " cannot be combined with --shard: run the search once, "
                                         "then shard with the --order, --rate, --grid and --precision it chose"));
            }
            if (workDir.empty()) workDir = output + ".work";
            // Every output checked and staged before the work: a bad path fails now, not after an
            // hour of tracing, and nothing appears under its name until all are complete.
            OutputSet outputs;
            const std::string stagedBake = searchOnly ? "" : outputs.add(output);
            const std::string stagedReport = targetReport.empty() ? "" : outputs.add(targetReport);

            Medium medium;
            medium.ior = ior;
            Scene scene = loadScene(input, medium);
            for (const std::string& n : scene.notes) std::fprintf(stderr, "note: %s\n", n.c_str());
            if (isGltfPath(input) && app.count("--ior") > 0)
                std::fprintf(stderr, "note: --ior is for a bare mesh: a glTF file's materials give "
                                     "their own IOR (KHR_materials_ior, 1.5 when absent)\n");
            for (const Part& p : scene.parts)
                for (const std::string& w : p.report.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

            if (search) {
                TargetSearchOptions topt;
                topt.goal = targetError > 0 ? TargetGoal::Error : TargetGoal::Budget;
                topt.targetDeg = targetError;
                topt.budgetBytes = static_cast<size_t>(budgetMB * 1e6);
                if (app.count("--precision") > 0) topt.precisions = {opt.precision};
                if (app.count("--basis") > 0) topt.bases = {opt.basis};
                if (!quiet) {
                    std::fprintf(stderr, "%s: searching basis, order, rate, grid and precision on held-out pairs...\n",
                                 searchFlag);
                    topt.log = [](const std::string& line) { std::fprintf(stderr, "  %s\n", line.c_str()); };
                }
                TargetSearchResult t = searchTarget(scene, opt, topt);
                const TargetCandidate& c = t.chosen;
                const TargetCandidate& p = t.reference;
                if (targetError > 0)
                    std::printf("target-error %.3g deg: %s", targetError, t.reached ? "chose" : "NOT REACHED; most accurate is");
                else
                    std::printf("budget %.3g MB: chose", budgetMB);
                std::printf(" %s, rate %d, grid %s, %s: median %.2f deg, p95 %.1f deg, %.2f MB of weights\n",
                            c.basis == Basis::Grid ? "the grid basis" : str("order ", c.order).c_str(), c.rate,
                            c.grid.ToString().c_str(), nameOf(c.precision), c.medianDeg, c.p95Deg, c.weightBytes / 1e6);
                std::printf("  paper's fixed model (order 8, rate %d, grid 32x64, f32): median %.2f deg, %.1f MB of "
                            "weights, %.3g paths\n", p.rate, p.medianDeg, p.weightBytes / 1e6, p.bakeCost);
                std::printf("  chosen: %.2fx less memory, %.2fx less tracing\n",
                            double(p.weightBytes) / std::max<size_t>(1, c.weightBytes),
                            p.bakeCost / std::max(1.0, c.bakeCost));
                // The options that bake the choice, to paste after the input and -o.
                std::printf("  bake it with: --basis %s%s --rate %d --grid %s --precision %s\n", nameOf(c.basis),
                            c.basis == Basis::Sh ? str(" --order ", c.order).c_str() : "", c.rate,
                            c.grid.ToString().c_str(), nameOf(c.precision));
                if (!targetReport.empty()) writeFile(stagedReport, t.ToJson().dump(2) + "\n");
                if (searchOnly) {
                    outputs.commit();
                    return int(cli::kOk);
                }
                opt.basis = c.basis;
                opt.order = c.order;
                opt.rate = c.rate;
                opt.grid = c.grid;
                opt.precision = c.precision;
            }

            const bool tty = cli::stderrIsTerminal();
            int lastDecile = -1;
            if (!quiet) {
                opt.progress = [&](const BakeProgress& p) {
                    double f = double(p.samplesDone) / std::max<size_t>(1, p.samplesTotal);
                    double rps = p.rays / std::max(1e-9, p.seconds);
                    // This run's pace over the samples it has done (not the resumed ones).
                    double g = double(p.samplesDone - p.samplesResumed) / std::max<size_t>(1, p.samplesTotal);
                    double eta = g > 0 ? p.seconds * (1 - f) / g : 0;
                    if (tty) {
                        int filled = static_cast<int>(f * 30);
                        std::fprintf(stderr, "\r[%-30s] %5.1f%%  %zu/%zu samples  %6.2f Mrays/s  ETA %s ",
                                     std::string(filled, '#').c_str(), 100 * f, p.samplesDone,
                                     p.samplesTotal, rps * 1e-6, cli::formatDuration(eta).c_str());
                    } else if (int(f * 10) > lastDecile) {
                        lastDecile = int(f * 10);
                        std::fprintf(stderr, "bake: %3.0f%% (%zu/%zu samples, %.2f Mrays/s, ETA %s)\n", 100 * f,
                                     p.samplesDone, p.samplesTotal, rps * 1e-6, cli::formatDuration(eta).c_str());
                    }
                };
            }
            if (opt.layout == LayoutKind::Joining && opt.rate == 0) {
                // Say what --samples becomes: the smallest rate reaching it, usually more samples.
                opt.rate = rateForSampleCount(scene, opt.samples);
                const size_t n = joiningSampleCount(scene, opt.rate);
                if (n != opt.samples)
                    cli::note(kTool, "--samples " + std::to_string(opt.samples) + ": rate " +
                                         std::to_string(opt.rate) + " gives " + std::to_string(n) +
                                         " unique samples (" +
                                         (n > opt.samples ? "the smallest rate that reaches it"
                                                          : "the largest rate; it cannot reach it") +
                                         ")");
            }

            auto note = [&](const std::string& text) {
                if (!quiet) std::fprintf(stderr, "%s%s\n", tty ? "\r" : "", text.c_str());
            };
            BakePlan plan(scene, opt, input);
            for (const std::string& w : plan.chartStats().warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
            if (!shardText.empty()) {
                // One slice into a shard file, for shrefract-merge.
                if (resume && fs::exists(output)) {
                    try {
                        const ShardData old = readShard(output);
                        if (shardMismatch(old, shardIdentity(plan), slice, plan.batchCount()).empty()) {
                            std::printf("%s: slice %d of %d is already complete\n", output.c_str(),
                                        slice.index, slice.count);
                            return int(cli::kOk);
                        }
                    } catch (const InputError& e) {
                        note(std::string("baking it again: ") + e.what());
                    }
                }
                const ShardData shard = bakeShard(plan, slice);
                if (!quiet && tty) std::fprintf(stderr, "\n");
                writeShard(stagedBake, shard);
                if (opt.cancel->load()) throw Cancelled();  // a signal during the write: keep nothing
                outputs.commit();
                const BakeStats st = BakeStats::fromJson(shard.manifest["stats"]);
                std::printf("baked %s slice %d of %d -> %s\n", input.c_str(), slice.index, slice.count,
                            output.c_str());
                std::printf("  samples     %zu of %zu (from %zu), paths %zu, rays %zu\n", shard.sampleCount,
                            plan.sampleCount(), shard.manifest["shard"].value("first", size_t(0)), st.paths,
                            st.rays);
                std::printf("  time        %.1f s wall (layout %.1f s, slice %.1f s)\n",
                            std::chrono::duration<double>(Clock::now() - start).count(), plan.setupSeconds(),
                            st.wallSeconds);
                return int(cli::kOk);
            }
            const int nCheckpoints = checkpointCount(plan, checkpoints);
            BakeResult res;
            if (nCheckpoints <= 1) {
                SliceResult all = plan.bakeSlice(0, plan.batchCount());
                res.stats = all.stats;
                res.data = plan.data(std::move(all.weights), std::move(all.errors), res.stats);
            } else {
                CheckpointOptions co;
                co.workDir = workDir;
                co.count = nCheckpoints;
                co.resume = resume;
                co.log = note;
                checkpointDir = workDir;
                res = bakeWithCheckpoints(plan, co);
            }
            res.stats.rhoOverhead = rhoOverhead(plan.layout());
            res.stats.charts = plan.chartStats();
            if (!quiet && tty) std::fprintf(stderr, "\n");
            writeBake(stagedBake, res.data);
            if (opt.cancel->load()) throw Cancelled();  // a signal during the write: keep nothing
            outputs.commit();
            if (nCheckpoints > 1) removeCheckpoints(workDir);
            res.stats.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();

            const BakeStats& s = res.stats;
            auto pct = [&](size_t k) { return 100.0 * double(k) / double(std::max<size_t>(1, s.paths)); };
            const SurfaceLayout& L = res.data.layout;
            std::printf("baked %s -> %s\n", input.c_str(), output.c_str());
            if (L.isChartLayout()) {
                const ChartStats& c = s.charts;
                std::printf("  samples     %zu covered texels of a %dx%d atlas (%.2f texels/sample), %s "
                            "layout, %d triangles\n",
                            s.samples, L.muWidth, L.muHeight, s.rhoOverhead, nameOf(L.kind), L.triangleCount);
                std::printf("  charts      %d (%d splits, %d unfolded by ARAP), gutter %d, density spread "
                            "%.2fx, largest conformal distortion %.2f\n",
                            c.charts, c.splits, c.arapCharts, L.atlas.gutter, c.densitySpread,
                            c.maxConformalDistortion);
                std::printf("  cuts        %zu smooth seam edges, %zu crease edges, %zu border edges; "
                            "%zu of %zu gutter texels seam-aware\n",
                            c.seamEdges, c.creaseEdges, c.borderEdges, c.seamSources, c.gutterTexels);
            } else {
                std::printf("  samples     %zu (rate %d, %d triangles), mu %dx%d, rho %dx%d (%.2f texels/sample)\n",
                            s.samples, L.rate, L.triangleCount, L.muWidth, L.muHeight, L.rhoWidth, L.rhoHeight,
                            s.rhoOverhead);
            }
            std::printf("  paths       %zu (%zu directions per sample%s), rays %zu (%.2f per path)\n", s.paths,
                        s.paths / std::max<size_t>(1, s.samples),
                        s.paths > s.samples * size_t(opt.grid.count()) ? ", the error model's cell corners included" : "",
                        s.rays, double(s.rays) / std::max<size_t>(1, s.paths));
            if (nCheckpoints <= 1)
                std::printf("  time        %.1f s wall (trace %.1f s, compress %.1f s thread time), %.2f Mrays/s\n",
                            s.wallSeconds, s.traceSeconds, s.compressSeconds, s.rays / s.wallSeconds * 1e-6);
            else
                std::printf("  time        %.1f s wall, %d checkpoints (%.1f s of slices in all runs)\n",
                            s.wallSeconds, nCheckpoints, res.data.manifest["stats"].value("seconds", 0.0));
            std::printf("  paths with  TIR %.2f%%, capped %.3f%% (soft %.3f%%), left and re-entered %.2f%%, "
                        "geometric-normal fallback %.3f%%, leaked %.3f%%\n",
                        pct(s.tir), pct(s.capped), pct(s.softCapped), pct(s.reentered), pct(s.geometricNormal),
                        pct(s.leaked));
            std::printf("  file        %.1f MB, %s, %d coefficients, %s\n",
                        std::filesystem::file_size(output) / 1e6, res.data.modelName().c_str(),
                        res.data.coefficientCount(), nameOf(opt.precision));
            return int(cli::kOk);
        } catch (const Cancelled&) {
            if (!checkpointDir.empty())
                std::fprintf(stderr, "\n%s: finished checkpoints stay in %s: run the same command with "
                                     "--resume to continue\n", kTool, checkpointDir.c_str());
            throw;
        }
    });
}
