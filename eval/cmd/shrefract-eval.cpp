// shrefract-eval: how close a bake comes to the truth.
//   directions BAKE --pairs N --seed S --json REPORT.json   decompressed vs freshly traced
//   query BAKE --in Q.csv --out A.csv                        exit direction per (point, view)
//   image --ref A.exr --test B.exr [--heatmap H.png] [--flip-map F.png] [--json R.json]
//                                                            two evaluation buffers
//   image --ref A.exr --test-png B.png [--json R.json]       a buffer and a display image
//   montage --out M.png IMG.exr... [--labels L...] [--errors] [--flip]   labelled side by side
//   compose R.exr G.exr B.exr --out D.exr    colour channel c of input c (dispersion)
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "eval/adaptive.h"
#include "eval/directions.h"
#include "eval/image_eval.h"
#include "eval/reference.h"
#include "common/cli/cli.h"
#include "common/error.h"
#include "common/output.h"
#include "common/query.h"
#include "common/sh.h"

using namespace shrefract;

namespace {

void printTable(const nlohmann::json& r) {
    const bool ceiling = r["all"].contains("ceiling");
    auto row = [&](const char* name, const nlohmann::json& c) {
        const auto& a = c["angleDeg"];
        if (a["count"].get<size_t>() == 0) {
            std::printf("  %-11s %6.2f%%  (none)\n", name, 100 * c["share"].get<double>());
            return;
        }
        std::printf("  %-11s %6.2f%%  %8.3f %8.3f %8.3f %8.3f %8.2f   %8.4f", name,
                    100 * c["share"].get<double>(), a["mean"].get<double>(), a["median"].get<double>(),
                    a["p95"].get<double>(), a["p99"].get<double>(), a["max"].get<double>(),
                    c["lengthError"]["mean"].get<double>());
        if (ceiling)
            std::printf("   | %8.3f %8.3f %8.3f   %8.4f", c["ceiling"]["angleDeg"]["mean"].get<double>(),
                        c["ceiling"]["angleDeg"]["median"].get<double>(),
                        c["ceiling"]["angleDeg"]["p95"].get<double>(),
                        c["ceiling"]["lengthError"]["mean"].get<double>());
        std::printf("\n");
    };
    std::printf("direction error, degrees (%zu pairs, %s)%s\n", r["pairs"].get<size_t>(),
                r["model"].get<std::string>().c_str(),
                ceiling ? "; right: the data ceiling, the raw grid interpolated bilinearly" : "");
    std::printf("  %-11s %7s  %8s %8s %8s %8s %8s   %8s", "paths", "share", "mean", "median", "p95",
                "p99", "max", "len err");
    if (ceiling) std::printf("   | %8s %8s %8s   %8s", "mean", "median", "p95", "len err");
    std::printf("\n");
    row("all", r["all"]);
    row("plain", r["plain"]);
    row("TIR", r["tir"]);
    row("re-entered", r["reentered"]);
    row("capped", r["capped"]);
    if (!r.contains("prediction")) return;
    const nlohmann::json& p = r["prediction"];
    std::printf("error prediction, Spearman with the measured angle: 1 - |D| %.3f", p["spearmanShortness"].get<double>());
    if (!p.contains("spearman")) {
        std::printf(" (the bake has no error model)\n");
        return;
    }
    std::printf(", error model %.3f\n  deciles of the prediction, median degrees predicted / measured:\n ",
                p["spearman"].get<double>());
    for (const auto& b : p["deciles"])
        std::printf(" %.2f/%.2f", b["predictedDeg"].get<double>(), b["measuredDeg"].get<double>());
    std::printf("\n");
}

// "0.5,1,2" -> numbers, each finite and > 0.
std::vector<double> parseTolerances(const std::string& text) {
    std::vector<double> v;
    std::stringstream ss(text);
    for (std::string t; std::getline(ss, t, ',');) {
        char* end = nullptr;
        const double x = std::strtod(t.c_str(), &end);
        if (t.empty() || *end != '\0' || !std::isfinite(x) || x <= 0)
            throw std::invalid_argument("--tolerances: '" + text +
                                        "' is not a list of positive degrees");
        v.push_back(x);
    }
    if (v.empty()) throw std::invalid_argument("--tolerances: empty");
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"shrefract-eval: compare a bake with fresh traces"};
    app.require_subcommand(1);
    std::string bakePath, jsonPath, scenePath, inPath, outPath;
    size_t pairs = 100000;
    uint64_t seed = 1;
    int order = -1;
    bool noVerify = false;
    auto* dirs = app.add_subcommand("directions", "random (sample, direction) pairs against fresh traces");
    dirs->add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    dirs->add_option("--pairs", pairs, "number of pairs")->capture_default_str()->check(CLI::Range(size_t(1), size_t(100'000'000)));
    dirs->add_option("--seed", seed, "random seed")->capture_default_str();
    dirs->add_option("--order", order, "evaluate with bands 0..order only (default: all stored)");
    dirs->add_option("--json", jsonPath, "write the report here");
    dirs->add_option("--scene", scenePath, "the baked mesh or scene, if not where the manifest says");
    dirs->add_flag("--no-verify", noVerify, "skip the bake's checksums");
    std::string tolText = "0.5,1,2,5,10";
    auto* adaptive = app.add_subcommand(
        "adaptive", "would a per-sample order pay? memory saved and error against fresh traces");
    adaptive->add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    adaptive->add_option("--tolerances", tolText, "degrees, comma-separated")->capture_default_str();
    adaptive->add_option("--pairs", pairs, "pairs for the error")->capture_default_str();
    adaptive->add_option("--json", jsonPath, "write the report here");
    adaptive->add_option("--scene", scenePath, "the baked mesh or scene, if not where the manifest says");
    std::string bakesPrefix;
    adaptive->add_option("--write-bakes", bakesPrefix,
                         "also write, per tolerance, what a per-sample order would draw: PREFIX_TOL.shrefract.exr "
                         "(each sample fitted at its own order to fresh traces, its higher bands zero, "
                         "its error model fitted anew; every band still stored)");
    auto* query = app.add_subcommand("query", "exit direction and length per (point, view direction)");
    query->add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    query->add_option("--in", inPath, "CSV rows px,py,pz,wx,wy,wz (object space, w toward the viewer)")->required();
    query->add_option("--out", outPath, "CSV rows ex,ey,ez,len")->required();
    float maxDistance = -1.0f;
    query->add_option("--max-distance", maxDistance,
                      "refuse points farther than this from the surface, object units (default: "
                      "0.001 of the bake's bounding-box diagonal)");
    std::string refPath, testPath, testPngPath, heatPath, flipPath, outPng;
    float maxDeg = 30.0f, exposure = 1.0f;
    auto* image = app.add_subcommand("image", "compare two render evaluation buffers (docs/evaluation.md)");
    image->add_option("--ref", refPath, "reference evaluation buffer EXR (shrefract-render --dirs)")->required();
    auto* testOpt = image->add_option("--test", testPath, "tested evaluation buffer EXR");
    image->add_option("--test-png", testPngPath,
                      "or a tested 8-bit display image (tone-mapped, sRGB-encoded, e.g. a browser's "
                      "frame): colour and object metrics only, no directions")
        ->excludes(testOpt);
    image->add_option("--heatmap", heatPath, "angular error heat map PNG");
    image->add_option("--flip-map", flipPath, "LDR-FLIP heat map PNG of the tone-mapped images (0 ... 1)");
    image->add_option("--max-deg", maxDeg, "heat map: degrees at the top of the ramp")->capture_default_str();
    image->add_option("--exposure", exposure, "exposure before the tone map")->capture_default_str();
    image->add_option("--json", jsonPath, "write the report here");
    std::vector<std::string> inputs, labels;
    bool withErrors = false, withFlip = false;
    auto* mont = app.add_subcommand("montage", "labelled side-by-side PNG of evaluation buffers (paper Figure 11)");
    mont->add_option("inputs", inputs, "evaluation buffer EXRs, the reference first")->required();
    mont->add_option("--labels", labels, "one label per input (default: file names)");
    mont->add_option("--out", outPng, "montage PNG")->required();
    mont->add_flag("--errors", withErrors, "a second row: angular error heat maps against the first input");
    mont->add_flag("--flip", withFlip, "a further row: LDR-FLIP maps against the first input, object FLIP beneath");
    mont->add_option("--max-deg", maxDeg, "heat map: degrees at the top of the ramp")->capture_default_str();
    mont->add_option("--exposure", exposure, "exposure before the tone map")->capture_default_str();
    std::vector<std::string> channels;
    std::string composed;
    auto* compose = app.add_subcommand(
        "compose", "one evaluation buffer from three: colour channel c of input c, coverage and "
                   "directions of the second (three grey renders at one index per channel)");
    compose->add_option("inputs", channels, "R.exr G.exr B.exr")->required()->expected(3);
    compose->add_option("--out", composed, "evaluation buffer EXR")->required();
    return cli::run(app, "shrefract-eval", argc, argv, [&] {
        // Every output checked and staged before the work (common/output.h).
        OutputSet outputs;
        const std::string stagedJson = jsonPath.empty() ? "" : outputs.add(jsonPath);
        if (image->parsed()) {
            const std::string stagedHeat = heatPath.empty() ? "" : outputs.add(heatPath);
            const std::string stagedFlip = flipPath.empty() ? "" : outputs.add(flipPath);
            if (testPath.empty() == testPngPath.empty())
                throw InputError("image: give --test (an evaluation buffer) or --test-png (a display image)");
            if (!testPngPath.empty()) {
                if (!heatPath.empty() || !flipPath.empty())
                    throw InputError("image: --heatmap and --flip-map need --test (a PNG has no directions)");
                nlohmann::json r = compareDisplayImage(readEvalBuffer(refPath), readPng8(testPngPath), exposure);
                r["ref"] = refPath;
                r["test"] = testPngPath;
                auto number = [](const nlohmann::json& v, int digits) {
                    char s[32] = "-";
                    if (!v.is_null()) std::snprintf(s, sizeof s, "%.*f", digits, v.get<double>());
                    return std::string(s);
                };
                std::printf("tone-mapped: PSNR %.2f dB, SSIM %.4f, FLIP %.4f\n", r["psnr"].get<double>(),
                            r["ssim"].get<double>(), r["flip"].get<double>());
                std::printf("object (reference coverage, %zu pixels): PSNR %s dB, SSIM %s, FLIP %s, detail ratio %s\n",
                            r["coverage"]["ref"].get<size_t>(), number(r["objectPsnr"], 2).c_str(),
                            number(r["objectSsim"], 4).c_str(), number(r["objectFlip"], 4).c_str(),
                            number(r["detailRatio"], 3).c_str());
                if (!jsonPath.empty()) writeFile(stagedJson, r.dump(2) + "\n");
                outputs.commit();
                return cli::kOk;
            }
            EvalBuffer ref = readEvalBuffer(refPath), test = readEvalBuffer(testPath);
            nlohmann::json r = compareImages(ref, test, exposure);
            r["ref"] = refPath;
            r["test"] = testPath;
            const auto& a = r["angleDeg"];
            if (a["count"].get<size_t>() > 0)
                std::printf("angular error, degrees, %zu pixels both cover: mean %.3f median %.3f p95 %.3f max %.3f\n",
                            a["count"].get<size_t>(), a["mean"].get<double>(), a["median"].get<double>(),
                            a["p95"].get<double>(), a["max"].get<double>());
            else
                std::printf("angular error: no pixel covered by both\n");
            std::printf("coverage: ref %zu, test %zu, mismatch %zu (ref only %zu, test only %zu)\n",
                        r["coverage"]["ref"].get<size_t>(), r["coverage"]["test"].get<size_t>(),
                        r["coverage"]["mismatch"].get<size_t>(), r["coverage"]["refOnly"].get<size_t>(),
                        r["coverage"]["testOnly"].get<size_t>());
            std::printf("tone-mapped: PSNR %.2f dB, SSIM %.4f, FLIP %.4f\n", r["psnr"].get<double>(),
                        r["ssim"].get<double>(), r["flip"].get<double>());
            // The object metrics are null where undefined (no object pixel, no window, no detail).
            auto number = [](const nlohmann::json& v, int digits) {
                char s[32] = "-";
                if (!v.is_null()) std::snprintf(s, sizeof s, "%.*f", digits, v.get<double>());
                return std::string(s);
            };
            std::printf("object (reference coverage): PSNR %s dB, SSIM %s, FLIP %s, detail ratio %s\n",
                        number(r["objectPsnr"], 2).c_str(), number(r["objectSsim"], 4).c_str(),
                        number(r["objectFlip"], 4).c_str(), number(r["detailRatio"], 3).c_str());
            if (!heatPath.empty()) writePng8(stagedHeat, heatMap(ref, test, maxDeg, exposure));
            if (!flipPath.empty()) writePng8(stagedFlip, flipHeatMap(ref, test, exposure));
            if (!jsonPath.empty()) writeFile(stagedJson, r.dump(2) + "\n");
            outputs.commit();
            return cli::kOk;
        }
        if (compose->parsed()) {
            const std::string stagedOut = outputs.add(composed);
            writeEvalBuffer(stagedOut, composeChannels(readEvalBuffer(channels[0]),
                                                      readEvalBuffer(channels[1]),
                                                      readEvalBuffer(channels[2])));
            outputs.commit();
            std::printf("composed -> %s\n", composed.c_str());
            return cli::kOk;
        }
        if (mont->parsed()) {
            const std::string stagedPng = outputs.add(outPng);
            if (!labels.empty() && labels.size() != inputs.size())
                throw InputError("montage: " + std::to_string(labels.size()) + " labels for " +
                                 std::to_string(inputs.size()) + " inputs");
            std::vector<EvalBuffer> buffers;
            for (const std::string& p : inputs) buffers.push_back(readEvalBuffer(p));
            const size_t errorRow = 1, flipRow = withErrors ? 2 : 1;
            std::vector<std::vector<Image8>> rows(1 + withErrors + withFlip);
            std::vector<std::vector<std::string>> text(rows.size());
            for (size_t i = 0; i < buffers.size(); ++i) {
                rows[0].push_back(toneMapped(buffers[i], exposure));
                text[0].push_back(labels.empty() ? std::filesystem::path(inputs[i]).stem().string() : labels[i]);
                if (!withErrors && !withFlip) continue;
                nlohmann::json r = compareImages(buffers[0], buffers[i], exposure);
                char line[64];
                if (withErrors) {
                    rows[errorRow].push_back(heatMap(buffers[0], buffers[i], maxDeg, exposure));
                    if (r["angleDeg"]["count"].get<size_t>() > 0)
                        std::snprintf(line, sizeof line, "median %.1f p95 %.1f deg",
                                      r["angleDeg"]["median"].get<double>(), r["angleDeg"]["p95"].get<double>());
                    else
                        std::snprintf(line, sizeof line, "no overlap");
                    text[errorRow].push_back(line);
                }
                if (withFlip) {
                    rows[flipRow].push_back(flipHeatMap(buffers[0], buffers[i], exposure));
                    if (!r["objectFlip"].is_null())
                        std::snprintf(line, sizeof line, "object FLIP %.3f", r["objectFlip"].get<double>());
                    else
                        std::snprintf(line, sizeof line, "no object");
                    text[flipRow].push_back(line);
                }
            }
            writePng8(stagedPng, montage(rows, text, 2));
            outputs.commit();
            std::printf("montage of %zu -> %s\n", buffers.size(), outPng.c_str());
            return cli::kOk;
        }
        const std::string stagedCsv = query->parsed() ? outputs.add(outPath) : "";
        const std::vector<double> tolerances =
            adaptive->parsed() ? parseTolerances(tolText) : std::vector<double>();
        std::vector<std::string> bakePaths, stagedBakes;
        if (!bakesPrefix.empty())
            for (const double tol : tolerances) {
                char name[64];
                std::snprintf(name, sizeof name, "_%g.shrefract.exr", tol);
                bakePaths.push_back(bakesPrefix + name);
                stagedBakes.push_back(outputs.add(bakePaths.back()));
            }
        ReadOptions readOptions;
        readOptions.verify = !noVerify;
        BakeData bake = readBake(bakePath, readOptions);
        for (const std::string& w : bake.warnings)
            std::fprintf(stderr, "shrefract-eval: warning: %s: %s\n", bakePath.c_str(), w.c_str());
        if (order < -1 || order > bake.order)
            throw std::invalid_argument("--order " + std::to_string(order) + ": " + bakePath +
                                        " stores orders 0.." + std::to_string(bake.order) +
                                        " (-1: all)");
        if (adaptive->parsed() && bake.basis != Basis::Sh)
            throw InputError(bakePath + ": adaptive drops SH bands; this bake stores the grid basis");
        if (adaptive->parsed()) {
            Scene scene = sceneOfBake(bake, bakePath, scenePath);
            const size_t n = bake.layout.position.size();
            nlohmann::json full = evaluateDirections(bake, scene, pairs, seed);
            nlohmann::json report = {{"bake", bakePath}, {"order", bake.order},
                                     {"full", {{"median", full["angleDeg"]["median"]}, {"p95", full["angleDeg"]["p95"]}}},
                                     {"tolerances", nlohmann::json::array()}};
            std::printf("per-sample adaptive order (bake order %d): full-order error median %.2f, p95 %.1f deg\n",
                        bake.order, full["angleDeg"]["median"].get<double>(), full["angleDeg"]["p95"].get<double>());
            std::printf("  %9s  %12s  %14s  %10s  %8s\n", "tolerance", "mean order", "weights kept", "median", "p95");
            std::vector<std::vector<int>> allOrders;
            for (const double tol : tolerances) {
                std::vector<int> orders = adaptiveOrders(bake, tol);
                allOrders.push_back(orders);
                double kept = 0, meanOrder = 0;
                for (int o : orders) kept += shEvenCount(o), meanOrder += o;
                kept /= double(n) * shEvenCount(bake.order);
                meanOrder /= double(n);
                nlohmann::json r = evaluateDirections(bake, scene, pairs, seed, -1, 0.0f, 1.0f, &orders);
                std::printf("  %8.2f°  %12.2f  %13.1f%%  %10.2f  %8.1f\n", tol, meanOrder, 100 * kept,
                            r["angleDeg"]["median"].get<double>(), r["angleDeg"]["p95"].get<double>());
                report["tolerances"].push_back({{"toleranceDeg", tol}, {"meanOrder", meanOrder},
                                                {"weightsKept", kept}, {"median", r["angleDeg"]["median"]},
                                                {"p95", r["angleDeg"]["p95"]}});
            }
            if (!bakePaths.empty()) {
                std::printf("tracing every sample's grid again to fit %zu bakes at their per-sample orders\n",
                            bakePaths.size());
                std::vector<BakeData> perSample = perSampleOrderBakes(bake, scene, allOrders);
                for (size_t t = 0; t < perSample.size(); ++t) {
                    nlohmann::json& entry = report["tolerances"][t];
                    perSample[t].manifest["perSampleOrder"] = {
                        {"from", bakePath}, {"toleranceDeg", entry["toleranceDeg"]},
                        {"meanOrder", entry["meanOrder"]}, {"weightsKept", entry["weightsKept"]}};
                    writeBake(stagedBakes[t], perSample[t]);
                    entry["bake"] = bakePaths[t];
                    std::printf("  %g deg -> %s\n", tolerances[t], bakePaths[t].c_str());
                }
            }
            if (!jsonPath.empty()) writeFile(stagedJson, report.dump(2) + "\n");
        } else if (dirs->parsed()) {
            Scene scene = sceneOfBake(bake, bakePath, scenePath);
            nlohmann::json report = evaluateDirections(bake, scene, pairs, seed, order);
            report["bake"] = bakePath;
            printTable(report);
            if (!jsonPath.empty()) writeFile(stagedJson, report.dump(2) + "\n");
        } else {
            const std::vector<Query> queries = readQueries(inPath);
            std::vector<glm::vec3> p, w;
            for (const Query& q : queries) p.push_back(q.point), w.push_back(q.view);
            std::vector<glm::vec4> a;
            try {
                a = queryBake(bake, p, w, maxDistance);
            } catch (const QueryRefused& e) {
                throw inputError(inPath, "line " + std::to_string(queries[e.index].line) + ": " +
                                             e.what());
            }
            std::ostringstream os;
            os.precision(9);
            os << "ex,ey,ez,len\n";
            for (const glm::vec4& x : a) os << x.x << ',' << x.y << ',' << x.z << ',' << x.w << '\n';
            writeFile(stagedCsv, os.str());
            std::printf("answered %zu queries -> %s\n", a.size(), outPath.c_str());
        }
        outputs.commit();
        return cli::kOk;
    });
}
