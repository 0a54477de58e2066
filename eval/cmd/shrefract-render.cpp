// shrefract-render: renders a bake in front of an environment, headless (EGL or OSMesa).
//   shrefract-render BAKE --env ENV.exr [--camera orbit:AZ,EL,DIST | --eye x,y,z --target x,y,z]
//                    [--fov deg] [--size WxH] [--order L] [--backend egl|osmesa] [--out IMG.png]
//                    [--out-exr IMG.exr] [--dirs EVAL.exr] [--dump-shaders DIR]
//                    [--method sh|single|wyman|raytrace] [--wyman-tir reflect|straight|grazing]
// A thin shell over the runtime library (shrefract/render.h, shrefract/baselines.h) and, for
// raytrace and Wyman's d_N, the evaluation layer (eval/reference.h, Embree through bake/): the
// runtime library itself never links the bake. Every output is checked before the render and
// written only when all succeed (common/output.h); exit codes as every tool's (README).
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "common/cli/cli.h"
#include "common/error.h"
#include "common/evalbuffer.h"
#include "common/output.h"
#include "shrefract/baselines.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"

#include "eval/directions.h"
#include "eval/reference.h"

namespace {

double medianOf(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

std::vector<float> parseFloats(const std::string& text, size_t count, const std::string& what) {
    std::vector<float> v;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            size_t used = 0;
            v.push_back(std::stof(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw std::invalid_argument(what + ": '" + text + "' is not a list of numbers");
        }
    }
    if (v.size() != count)
        throw std::invalid_argument(what + ": expected " + std::to_string(count) + " numbers, got '" +
                                    text + "'");
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Render a shrefract bake (interactive refraction, Genevaux et al. 2006) headless"};
    std::string bakePath, envPath, camera, eye, target, size = "1024x1024", backend = "egl";
    std::string out, outExr, dirs, dumpDir, preset = "modern", form = "auto";
    float fov = 45.0f, exposure = 1.0f;
    int order = -1, frames = 5, spp = 1;
    bool smoothing = false;
    std::string method = "sh", wymanTir = "reflect", scenePath;
    bool latLongLookup = false, noVerify = false;
    app.add_option("bake", bakePath, "NAME.shrefract.exr from shrefract-bake")->required();
    app.add_option("--env", envPath, "lat-long environment EXR")->required();
    app.add_option("--camera", camera, "orbit:AZ,EL,DIST (degrees, degrees, object units)");
    app.add_option("--eye", eye, "camera position x,y,z (with --target)");
    app.add_option("--target", target, "camera target x,y,z");
    app.add_option("--fov", fov, "vertical field of view, degrees")->capture_default_str();
    app.add_option("--size", size, "image size WxH")->capture_default_str();
    app.add_option("--order", order, "SH order used at runtime (default: all stored)");
    app.add_option("--backend", backend, "headless GL: egl | osmesa")->capture_default_str();
    app.add_option("--preset", preset, "shader limits: modern | 2006")->capture_default_str();
    app.add_option("--form", form, "SH evaluation in GLSL: auto | polynomial | recurrence")
        ->capture_default_str()->check(CLI::IsMember({"auto", "polynomial", "recurrence"}));
    app.add_option("--frames", frames, "frames timed after a warm-up one")->capture_default_str();
    app.add_option("--spp", spp,
                   "raytrace: stratified samples per pixel for the colour (64: the anti-aliased "
                   "reference); the direction buffer keeps the pixel centre")
        ->capture_default_str()->check(CLI::Range(1, 4096));
    app.add_flag("--smooth", smoothing, "spatial smoothing through the neighbour lists");
    app.add_option("--exposure", exposure, "exposure before the tone map")->capture_default_str();
    app.add_option("--out", out, "tone-mapped PNG");
    app.add_option("--out-exr", outExr, "linear HDR RGBA EXR");
    app.add_option("--dirs", dirs,
                   "evaluation buffer EXR: R,G,B colour, A coverage, dir.X/Y/Z world exit "
                   "direction (docs/format.md)");
    app.add_option("--method", method, "sh | single | wyman | raytrace")->capture_default_str();
    app.add_option("--wyman-tir", wymanTir,
                   "Wyman at total internal reflection: reflect | straight | grazing")
        ->capture_default_str();
    app.add_flag("--latlong-lookup", latLongLookup,
                 "raytrace: look the environment up bilinearly in the lat-long image, not through "
                 "the runtime's cube map");
    app.add_option("--scene", scenePath,
                   "raytrace, wyman: the baked mesh or scene, if not where the manifest says");
    app.add_option("--dump-shaders", dumpDir, "write the generated GLSL into DIR");
    app.add_flag("--no-verify", noVerify, "skip the bake's checksums (faster; a corrupt file may draw garbage)");
    return shrefract::cli::run(app, "shrefract-render", argc, argv, [&] {
        // Outputs first: a path that cannot be written fails before any rendering.
        shrefract::OutputSet outputs;
        const std::string stagedPng = out.empty() ? "" : outputs.add(out);
        const std::string stagedExr = outExr.empty() ? "" : outputs.add(outExr);
        const std::string stagedDirs = dirs.empty() ? "" : outputs.add(dirs);
        int width = 0, height = 0;
        char x = 0;
        std::istringstream sizeStream(size);
        if (!(sizeStream >> width >> x >> height) || x != 'x' || width < 1 || height < 1 ||
            width > 16384 || height > 16384 || !sizeStream.eof())
            throw std::invalid_argument("--size: expected WxH, got '" + size + "'");
        shrefract::Camera cam = shrefract::Camera::orbit(30.0f, 20.0f, 3.0f);
        if (!camera.empty()) {
            if (camera.rfind("orbit:", 0) != 0)
                throw std::invalid_argument("--camera: expected orbit:AZ,EL,DIST, got '" + camera + "'");
            auto v = parseFloats(camera.substr(6), 3, "--camera");
            cam = shrefract::Camera::orbit(v[0], v[1], v[2]);
        }
        if (!eye.empty() || !target.empty()) {
            if (eye.empty() || target.empty() || !camera.empty())
                throw std::invalid_argument("--eye and --target go together, without --camera");
            auto e = parseFloats(eye, 3, "--eye"), t = parseFloats(target, 3, "--target");
            cam.eye = {e[0], e[1], e[2]};
            cam.target = {t[0], t[1], t[2]};
        }
        cam.fovDegrees = fov;
        shrefract::Backend be = shrefract::parseBackend(backend);

        if (method != "sh" && method != "single" && method != "wyman" && method != "raytrace")
            throw std::invalid_argument("--method: expected sh | single | wyman | raytrace, got '" +
                                        method + "'");
        const shrefract::WymanTir tir = shrefract::parseWymanTir(wymanTir);
        if (spp > 1 && method != "raytrace")
            throw std::invalid_argument("--spp " + std::to_string(spp) +
                                        ": only --method raytrace takes several samples per pixel");

        // Input first (cheap, and the common failure), then the context.
        shrefract::Bake bake = shrefract::loadBake(bakePath, !noVerify);
        for (const std::string& w : bake.warnings())
            std::fprintf(stderr, "shrefract-render: warning: %s: %s\n", bakePath.c_str(), w.c_str());
        if (order < -1 || order > bake.order())
            throw std::invalid_argument("--order " + std::to_string(order) + ": " + bakePath +
                                        " stores orders 0.." + std::to_string(bake.order()) +
                                        " (-1: all)");
        shrefract::RenderedFrame frame;
        frame.width = width;
        frame.height = height;
        double msPerFrame = 0;
        std::string stages;

        std::unique_ptr<shrefract::Scene> scene;
        std::unique_ptr<shrefract::Tracer> tracer;
        if (method == "raytrace" || method == "wyman") {
            scene = std::make_unique<shrefract::Scene>(
                shrefract::sceneOfBake(bake.data(), bakePath, scenePath));
            tracer = std::make_unique<shrefract::Tracer>(
                *scene, shrefract::traceOptionsOfBake(bake.data()));
        }
        if (method == "raytrace") {
            // The CPU reference: no GL context at all.
            shrefract::ReferenceEnvironment envImage(shrefract::loadLatLong(envPath), !latLongLookup);
            shrefract::ReferenceView view;
            view.eye = cam.eye, view.target = cam.target, view.up = cam.up;
            view.fovDegrees = cam.fovDegrees, view.width = width, view.height = height;
            view.spp = spp;
            shrefract::ReferenceStats stats;
            shrefract::EvalBuffer b = shrefract::renderReference(*tracer, envImage, view, &stats);
            frame.color.resize(b.pixelCount() * 4);
            frame.directions.resize(b.pixelCount() * 4);
            for (size_t i = 0; i < b.pixelCount(); ++i) {
                for (int c = 0; c < 3; ++c) {
                    frame.color[4 * i + c] = b.color[i][c];
                    frame.directions[4 * i + c] = b.direction[i][c];
                }
                frame.color[4 * i + 3] = 1.0f;
                frame.directions[4 * i + 3] = b.color[i].a;
            }
            msPerFrame = stats.milliseconds;
            std::printf("raytrace: %zu covered pixels; paths with TIR %zu, capped %zu, re-entered "
                        "%zu, geometric normal %zu, back-facing first hits %zu\n",
                        stats.covered, stats.tir, stats.capped, stats.reentered,
                        stats.geometricNormal, stats.backFacing);
            stages = "CPU wall time, Embree, all cores";
        }
        if (method != "raytrace") {
            auto context = shrefract::createHeadlessContext(be, width, height);
            std::printf("GL: %s (%s)\n", context->description().c_str(), shrefract::ToString(be));
            shrefract::Environment env = shrefract::Environment::loadLatLong(envPath);
            if (method == "sh") {
                shrefract::RefractorOptions options;
                options.preset = preset;
                options.form = form;
                options.order = order;
                options.smoothing = smoothing;
                options.loader = context->loader();
                auto refractor = shrefract::Refractor::create(bake, options);
                std::printf("bake: order %d, %d samples, %d triangles, rho %dx%d; using order %d, "
                            "%d decompression pass(es), preset %s\n",
                            bake.order(), bake.sampleCount(), bake.triangleCount(),
                            refractor->refractionMapSize().x, refractor->refractionMapSize().y,
                            refractor->order(), refractor->passCount(), preset.c_str());
                if (!dumpDir.empty()) refractor->dumpShaders(dumpDir);

                // A first frame warms up shader compilation (llvmpipe JIT-compiles at first
                // draw); the timings printed are the per-stage medians of the `frames` frames
                // after it.
                shrefract::renderFrame(*refractor, env, cam, width, height);
                std::vector<shrefract::Timings> all;
                for (int f = 0; f < std::max(1, frames); ++f) {
                    frame = shrefract::renderFrame(*refractor, env, cam, width, height);
                    all.push_back(frame.timings);
                }
                auto median = [&](double shrefract::Timings::*field) {
                    std::vector<double> v;
                    for (const auto& x : all) v.push_back(x.*field);
                    return medianOf(v);
                };
                shrefract::Timings t = frame.timings;
                t.view = median(&shrefract::Timings::view);
                t.decompress = median(&shrefract::Timings::decompress);
                t.smooth = median(&shrefract::Timings::smooth);
                t.unpack = median(&shrefract::Timings::unpack);
                t.shade = median(&shrefract::Timings::shade);
                std::printf("frames: %d timed (median per stage)\n", static_cast<int>(all.size()));
                std::printf("GPU ms: view %.3f, decompress %.3f (%d passes), smooth %.3f, unpack "
                            "%.3f, shade %.3f\n",
                            t.view, t.decompress, t.passes, t.smooth, t.unpack, t.shade);
                std::vector<double> totals;
                for (const auto& x : all)
                    totals.push_back(x.view + x.decompress + x.smooth + x.unpack + x.shade);
                msPerFrame = medianOf(totals);
                stages = "GPU, sum of the stages";
            } else {
                shrefract::BaselineOptions options;
                options.method = shrefract::parseBaselineMethod(method);
                options.tir = tir;
                options.loader = context->loader();
                std::vector<float> normalDistance;
                if (tracer) {
                    const auto& L = bake.data().layout;
                    normalDistance = shrefract::normalDistances(*tracer, L.position, L.normal);
                }
                auto baseline = shrefract::Baseline::create(bake, normalDistance, options);
                shrefract::renderFrame(*baseline, env, cam, width, height);  // warm-up
                std::vector<double> back, shade, totals;
                for (int f = 0; f < std::max(1, frames); ++f) {
                    frame = shrefract::renderFrame(*baseline, env, cam, width, height);
                    const shrefract::BaselineTimings& t = baseline->timings();
                    back.push_back(t.backFaces);
                    shade.push_back(t.shade);
                    totals.push_back(t.backFaces + t.shade);
                }
                std::printf("frames: %d timed (median per stage)\n", static_cast<int>(totals.size()));
                std::printf("GPU ms: back faces %.3f, shade %.3f\n", medianOf(back), medianOf(shade));
                msPerFrame = medianOf(totals);
                stages = "GPU, sum of the passes";
            }
        }
        std::printf("ms per frame (%s): %.3f (%s)\n", method.c_str(), msPerFrame, stages.c_str());
        size_t covered = 0;
        for (size_t i = 3; i < frame.directions.size(); i += 4) covered += frame.directions[i] > 0;
        std::printf("coverage: %.1f%% of pixels\n", 100.0 * covered / (size_t(width) * height));
        if (!out.empty()) shrefract::writePng(stagedPng, frame, exposure);
        if (!outExr.empty()) shrefract::writeExr(stagedExr, width, height, frame.color);
        if (!dirs.empty())
            shrefract::writeEvalBuffer(
                stagedDirs, shrefract::makeEvalBuffer(width, height, frame.color, frame.directions));
        outputs.commit();  // all or none
        return shrefract::cli::kOk;
    });
}
