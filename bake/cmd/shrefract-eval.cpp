// shrefract-eval: how close a bake comes to the truth.
//   directions BAKE --pairs N --seed S --json REPORT.json   decompressed vs freshly traced
//   query BAKE --in Q.csv --out A.csv                        exit direction per (point, view)
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "bake/eval.h"
#include "common/error.h"

using namespace shrefract;

namespace {

void printTable(const nlohmann::json& r) {
    auto row = [](const char* name, const nlohmann::json& c) {
        const auto& a = c["angleDeg"];
        if (a["count"].get<size_t>() == 0) {
            std::printf("  %-11s %6.2f%%  (none)\n", name, 100 * c["share"].get<double>());
            return;
        }
        std::printf("  %-11s %6.2f%%  %8.3f %8.3f %8.3f %8.3f %8.2f   %8.4f\n", name,
                    100 * c["share"].get<double>(), a["mean"].get<double>(), a["median"].get<double>(),
                    a["p95"].get<double>(), a["p99"].get<double>(), a["max"].get<double>(),
                    c["lengthError"]["mean"].get<double>());
    };
    std::printf("direction error, degrees (%zu pairs, order %d)\n", r["pairs"].get<size_t>(), r["order"].get<int>());
    std::printf("  %-11s %7s  %8s %8s %8s %8s %8s   %8s\n", "paths", "share", "mean", "median", "p95", "p99",
                "max", "len err");
    row("all", {{"share", 1.0}, {"angleDeg", r["angleDeg"]}, {"lengthError", r["lengthError"]}});
    row("plain", r["plain"]);
    row("TIR", r["tir"]);
    row("re-entered", r["reentered"]);
    row("capped", r["capped"]);
}

// Writes text to path via a temporary file and a rename: never a half-written report.
void writeAtomically(const std::string& path, const std::string& text) {
    std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp);
        if (!f) throw inputError(path, "cannot write");
        f << text;
        if (!f) throw inputError(path, "write failed");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw inputError(path, "cannot write");
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"shrefract-eval: compare a bake with fresh traces"};
    app.require_subcommand(1);
    std::string bakePath, jsonPath, scenePath, inPath, outPath;
    size_t pairs = 100000;
    uint64_t seed = 1;
    int order = -1;
    auto* dirs = app.add_subcommand("directions", "random (sample, direction) pairs against fresh traces");
    dirs->add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    dirs->add_option("--pairs", pairs, "number of pairs")->capture_default_str()->check(CLI::Range(size_t(1), size_t(100'000'000)));
    dirs->add_option("--seed", seed, "random seed")->capture_default_str();
    dirs->add_option("--order", order, "evaluate with bands 0..order only (default: all stored)");
    dirs->add_option("--json", jsonPath, "write the report here");
    dirs->add_option("--scene", scenePath, "the baked mesh or scene, if not where the manifest says");
    auto* query = app.add_subcommand("query", "exit direction and length per (point, view direction)");
    query->add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    query->add_option("--in", inPath, "CSV rows px,py,pz,wx,wy,wz (object space, w toward the viewer)")->required();
    query->add_option("--out", outPath, "CSV rows ex,ey,ez,len")->required();
    CLI11_PARSE(app, argc, argv);

    try {
        BakeData bake = readBake(bakePath);
        if (dirs->parsed()) {
            Scene scene = sceneOfBake(bake, bakePath, scenePath);
            nlohmann::json report = evaluateDirections(bake, scene, pairs, seed, order);
            report["bake"] = bakePath;
            printTable(report);
            if (!jsonPath.empty()) writeAtomically(jsonPath, report.dump(2) + "\n");
        } else {
            std::ifstream in(inPath);
            if (!in) throw inputError(inPath, "file not found");
            std::vector<glm::vec3> p, w;
            std::string line;
            int lineNo = 0;
            while (std::getline(in, line)) {
                ++lineNo;
                if (line.empty() || line[0] == '#') continue;
                if (lineNo == 1 && line.find_first_of("0123456789") > line.find_first_of("pxw")) continue;  // header
                std::replace(line.begin(), line.end(), ',', ' ');
                std::istringstream ss(line);
                float v[6];
                for (float& x : v)
                    if (!(ss >> x) || !std::isfinite(x))
                        throw inputError(inPath, "line " + std::to_string(lineNo) + ": expected 6 numbers px,py,pz,wx,wy,wz");
                glm::vec3 dir(v[3], v[4], v[5]);
                if (glm::length(dir) < 1e-6f)
                    throw inputError(inPath, "line " + std::to_string(lineNo) + ": zero view direction");
                p.emplace_back(v[0], v[1], v[2]);
                w.push_back(dir);
            }
            std::vector<glm::vec4> a = queryBake(bake, p, w);
            std::ostringstream os;
            os.precision(9);
            os << "ex,ey,ez,len\n";
            for (const glm::vec4& x : a) os << x.x << ',' << x.y << ',' << x.z << ',' << x.w << '\n';
            writeAtomically(outPath, os.str());
            std::printf("answered %zu queries -> %s\n", a.size(), outPath.c_str());
        }
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "shrefract-eval: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shrefract-eval: error: %s\n", e.what());
        return 1;
    }
}
