// shrefract-bench-runtime: per-frame cost of the runtime on one bake, as JSON (run by
// scripts/bench-runtime). For each interpolation path x preset x order x viewport:
//   - throughput: stage timer queries off, median wall ms of a whole frame (update + draw +
//     glFinish) and its GPU time (one GL_TIME_ELAPSED query around the frame);
//   - breakdown: stage timer queries on (each stage finished inside its query), median ms of
//     view, decompress, smooth, unpack, shade;
//   - GPU texture bytes the refractor allocated with only bands 0..L uploaded (paper Fig. 12);
// and, in the same run, a baseline: the same mesh drawn with one environment lookup per pixel
// (refracted view direction at the front face, no decompression), for the ratio
// runtime frame / plain environment-mapped draw, and an empty frame (the target cleared and
// finished, nothing drawn): what every frame pays before it draws anything. --memory-bakes adds
// the GPU memory per part of other bakes of the same mesh (f16, u8) on every path.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "bake_data.h"
#include "common/bakefile.h"
#include "common/cli/cli.h"
#include "common/output.h"
#include "gl.h"
#include "shrefract/context.h"
#include "shrefract/baselines.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"

namespace {

using namespace shrefract;
using namespace shrefract::gl;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}


struct FrameTimes {
    double wall = 0, gpu = 0;
};

// Runs `frames` frames after `warmup`, camera orbiting 1 degree per frame; `body(eye, view,
// projection)` draws one. Returns medians; `perFrame` sees each timed frame.
template <typename Body, typename PerFrame>
FrameTimes timeFrames(OffscreenTarget& target, int warmup, int frames, bool gpuQuery, Body body,
                      PerFrame perFrame) {
    GLuint query = 0;
    glGenQueries(1, &query);
    std::vector<double> wall, gpu;
    const glm::mat4 projection = glm::perspective(
        glm::radians(45.0f), float(target.width()) / target.height(), 0.01f, 100.0f);
    for (int f = 0; f < warmup + frames; ++f) {
        Camera cam = Camera::orbit(30.0f + f, 20.0f, 3.0f);
        glm::mat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
        glFinish();
        auto t0 = Clock::now();
        if (gpuQuery) glBeginQuery(GL_TIME_ELAPSED, query);
        target.bind();
        body(cam.eye, view, projection);
        // Finish inside the query: llvmpipe rasterizes at the flush, not at submission.
        glFinish();
        if (gpuQuery) glEndQuery(GL_TIME_ELAPSED);
        auto t1 = Clock::now();
        ensureLoaded(currentContextLoader());
        if (f < warmup) continue;
        wall.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        if (gpuQuery) {
            GLuint64 ns = 0;
            glGetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
            gpu.push_back(ns * 1e-6);
        }
        perFrame();
    }
    glDeleteQueries(1, &query);
    return {median(wall), median(gpu)};
}

nlohmann::json memoryJson(const GpuMemory& m) {
    return {{"weights", m.weights},       {"samples", m.samples},
            {"rho", m.rho},               {"mesh", m.mesh},
            {"neighbours", m.neighbours}, {"targets", m.targets},
            {"total_bytes", m.total()},   {"total_MB", m.total() / 1e6}};
}

// "direct:vertex" -> options.path "direct", options.decompression "vertex".
void applyPath(const std::string& text, RefractorOptions& o) {
    const size_t colon = text.find(':');
    o.path = parseName<RefractorPath>(text.substr(0, colon));
    o.decompression = colon == std::string::npos ? DecompressionSite::Auto
                                                 : parseName<DecompressionSite>(text.substr(colon + 1));
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) out.push_back(item);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Per-frame cost of the shrefract runtime, as JSON"};
    std::string bakePath, envPath, orders = "1,4,8", sizes = "1024x1024,1350x1100",
                                      presets = "2006,modern", backend = "egl", jsonPath,
                                      paths = "rho,direct", memoryBakes;
    int frames = 15, warmup = 3;
    bool smoothing = false;  // the runtime's default (vertex decompression needs it off)
    app.add_option("bake", bakePath, "NAME.shrefract.exr")->required();
    app.add_option("--env", envPath, "lat-long environment EXR")->required();
    app.add_option("--orders", orders, "SH orders used, comma-separated")->capture_default_str();
    app.add_option("--sizes", sizes, "viewports WxH, comma-separated")->capture_default_str();
    app.add_option("--presets", presets, "shader limit presets")->capture_default_str();
    app.add_option("--paths", paths,
                   "interpolation paths, comma-separated: rho, direct (auto decompression), "
                   "direct:vertex, direct:texture")->capture_default_str();
    app.add_option("--memory-bakes", memoryBakes,
                   "other bakes of the same mesh (e.g. f16, u8), comma-separated: GPU memory per "
                   "part on every path at their full order");
    app.add_option("--backend", backend, "egl | osmesa")->capture_default_str();
    app.add_option("--frames", frames, "timed frames per measurement")->capture_default_str();
    app.add_option("--warmup", warmup, "untimed frames first")->capture_default_str();
    app.add_option("--smooth", smoothing, "neighbour-list smoothing on (true/false)")
        ->capture_default_str();
    app.add_option("--json", jsonPath, "output file (default: stdout)");
    return cli::run(app, "shrefract-bench-runtime", argc, argv, [&] {
        Bake bake = loadBake(bakePath);
        auto context = createHeadlessContext(parseName<Backend>(backend));
        Environment env = Environment::loadLatLong(envPath);
        ensureLoaded(currentContextLoader());
        std::fprintf(stderr, "GL: %s\n", context->description().c_str());

        nlohmann::json out;
        out["renderer"] = context->description();
        out["backend"] = backend;
        out["bake"] = {{"path", bakePath},
                       {"order", bake.order()},
                       {"samples", bake.sampleCount()},
                       {"triangles", bake.triangleCount()}};
        out["method"] = {
            {"frames", frames},
            {"warmup", warmup},
            {"statistic", "median"},
            {"smoothing", smoothing},
            {"frame", "update() + draw() of the object into a cleared RGBA32F offscreen target + "
                      "glFinish; no background"},
            {"throughput", "stage timer queries off; wall = CPU clock around the frame, gpu = one "
                           "GL_TIME_ELAPSED query around it (glFinish inside)"},
            {"stages", "stage timer queries on: each stage ends with glFinish inside its "
                       "GL_TIME_ELAPSED query (a pipeline drain per stage)"},
            {"memory", "texel bytes at the requested internal formats, bands 0..L uploaded"},
            {"baseline", "same mesh, one environment lookup along the view ray refracted at the "
                         "front face, no decompression"},
            {"paper_figure12_MB", {{"1", 9}, {"4", 13}, {"8", 23}}}};

        std::vector<glm::ivec2> viewports;
        for (const std::string& s : split(sizes)) {
            int w = 0, h = 0;
            if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1)
                throw std::invalid_argument("--sizes: bad viewport '" + s + "'");
            viewports.push_back({w, h});
        }

        // Baseline per viewport.
        nlohmann::json baseline = nlohmann::json::object();
        std::vector<double> baselineMs;
        {
            // The plain environment-mapped draw is the single-sided refraction baseline.
            BaselineOptions bo;
            bo.method = BaselineMethod::Single;
            bo.timings = false;
            std::unique_ptr<Baseline> plain = Baseline::create(bake, {}, bo);
            for (glm::ivec2 vp : viewports) {
                OffscreenTarget target(vp.x, vp.y);
                FrameTimes t = timeFrames(
                    target, warmup, frames, true,
                    [&](glm::vec3 eye, const glm::mat4& view, const glm::mat4& projection) {
                        (void)eye;
                        plain->draw(view, projection, glm::mat4(1.0f), env);
                    },
                    [] {});
                std::string key = std::to_string(vp.x) + "x" + std::to_string(vp.y);
                baseline[key] = {{"frame_wall_ms", t.wall}, {"frame_gpu_ms", t.gpu}};
                baselineMs.push_back(t.wall);
                std::fprintf(stderr, "baseline %s: %.2f ms\n", key.c_str(), t.wall);
            }
        }
        out["baseline"] = baseline;

        // An empty frame per viewport: the target bound (cleared) and finished, nothing drawn.
        nlohmann::json empty = nlohmann::json::object();
        for (glm::ivec2 vp : viewports) {
            OffscreenTarget target(vp.x, vp.y);
            FrameTimes t = timeFrames(
                target, warmup, frames, true, [](glm::vec3, const glm::mat4&, const glm::mat4&) {},
                [] {});
            const std::string key = std::to_string(vp.x) + "x" + std::to_string(vp.y);
            empty[key] = {{"frame_wall_ms", t.wall}, {"frame_gpu_ms", t.gpu}};
            std::fprintf(stderr, "empty frame %s: %.2f ms\n", key.c_str(), t.wall);
        }
        out["empty_frame"] = empty;

        nlohmann::json runs = nlohmann::json::array();
        nlohmann::json memory = nlohmann::json::object();
        for (const std::string& pathText : split(paths)) {
          for (const std::string& preset : split(presets)) {
            for (const std::string& orderText : split(orders)) {
                const int order = std::stoi(orderText);
                if (order > bake.order()) {
                    std::fprintf(stderr, "skipping order %d > bake order %d\n", order,
                                 bake.order());
                    continue;
                }
                RefractorOptions options;
                applyPath(pathText, options);
                options.preset = parseName<ShaderPreset>(preset);
                options.order = order;
                options.maxOrder = order;  // upload only what this order uses (Figure 12)
                options.smoothing = smoothing;
                options.loader = context->loader();
                std::unique_ptr<Refractor> refractor;
                try {
                    refractor = Refractor::create(bake, options);
                } catch (const std::invalid_argument& e) {  // e.g. vertex decompression at 2006
                    std::fprintf(stderr, "skipping %s %s order %d: %s\n", pathText.c_str(),
                                 preset.c_str(), order, e.what());
                    continue;
                }

                for (size_t v = 0; v < viewports.size(); ++v) {
                    glm::ivec2 vp = viewports[v];
                    OffscreenTarget target(vp.x, vp.y);
                    auto body = [&](glm::vec3 eye, const glm::mat4& view,
                                    const glm::mat4& projection) {
                        (void)eye;
                        refractor->update({view, projection, glm::mat4(1.0f)});
                        refractor->draw(env);
                    };
                    refractor->setTimings(false);
                    FrameTimes t = timeFrames(target, warmup, frames, true, body, [] {});
                    refractor->setTimings(true);
                    std::vector<double> st[5];
                    FrameTimes timed = timeFrames(target, 1, frames, false, body, [&] {
                        const Timings& s = refractor->timings();
                        const double values[5] = {s.view, s.decompress, s.smooth, s.unpack,
                                                  s.shade};
                        for (int i = 0; i < 5; ++i) st[i].push_back(values[i]);
                    });
                    nlohmann::json run = {
                        {"path", nameOf(refractor->path())},
                        {"decompression", nameOf(refractor->decompression())},
                        {"preset", preset},
                        {"order", order},
                        {"viewport", std::to_string(vp.x) + "x" + std::to_string(vp.y)},
                        {"passes", refractor->passCount()},
                        {"frame_wall_ms", t.wall},
                        {"frame_gpu_ms", t.gpu},
                        {"fps", t.wall > 0 ? 1000.0 / t.wall : 0.0},
                        {"ratio_to_baseline", baselineMs[v] > 0 ? t.wall / baselineMs[v] : 0.0},
                        {"stages_ms",
                         {{"view", median(st[0])},
                          {"decompress", median(st[1])},
                          {"smooth", median(st[2])},
                          {"unpack", median(st[3])},
                          {"shade", median(st[4])}}},
                        {"frame_wall_ms_with_stage_timers", timed.wall}};
                    std::fprintf(stderr, "%s %s order %d %dx%d: %.2f ms (x%.2f baseline)\n",
                                 pathText.c_str(), preset.c_str(), order, vp.x, vp.y, t.wall,
                                 run["ratio_to_baseline"].get<double>());
                    runs.push_back(run);
                }
                // After the frames: render targets are made on first use.
                memory[pathText + " " + preset + " " + std::to_string(order)] =
                    memoryJson(refractor->memory());
            }
          }
        }
        out["runs"] = runs;
        out["memory"] = memory;

        // Ratios of the measured frames: direct over rho (modern preset), per order and viewport.
        nlohmann::json ratios = nlohmann::json::array();
        for (const auto& a : runs)
            for (const auto& b : runs)
                if (a["path"] == "direct" && b["path"] == "rho" && a["preset"] == "modern" &&
                    b["preset"] == "modern" && a["order"] == b["order"] &&
                    a["viewport"] == b["viewport"])
                    ratios.push_back({{"order", a["order"]}, {"viewport", a["viewport"]},
                                      {"decompression", a["decompression"]},
                                      {"direct_over_rho", a["frame_wall_ms"].get<double>() /
                                                              b["frame_wall_ms"].get<double>()}});
        out["ratios"] = ratios;

        // Memory of other bakes of the mesh (stored precisions), every path, full order.
        nlohmann::json others = nlohmann::json::array();
        for (const std::string& path : split(memoryBakes)) {
            Bake other = loadBake(path);
            for (const std::string& pathText : split(paths)) {
                RefractorOptions options;
                applyPath(pathText, options);
                options.loader = context->loader();
                std::unique_ptr<Refractor> r;
                try {
                    r = Refractor::create(other, options);
                } catch (const std::invalid_argument&) {
                    continue;
                }
                r->update(FrameView::fromEye(glm::vec3(0.0f, 0.0f, 3.0f)));  // render targets are made on first use
                others.push_back({{"bake", path},
                                  {"precision", bakeData(other).manifest.value("precision", "")},
                                  {"path", nameOf(r->path())},
                                  {"decompression", nameOf(r->decompression())},
                                  {"memory", memoryJson(r->memory())}});
                std::fprintf(stderr, "%s %s: %.2f MB\n", path.c_str(), pathText.c_str(),
                             r->memory().total() / 1e6);
            }
        }
        out["memory_other_bakes"] = others;

        const std::string text = out.dump(2) + "\n";
        if (jsonPath.empty()) {
            std::fputs(text.c_str(), stdout);
        } else {
            writeFile(jsonPath, text);
        }
        return cli::kOk;
    });
}
