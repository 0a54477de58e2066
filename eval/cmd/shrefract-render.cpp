// shrefract-render: renders a bake in front of an environment, headless (EGL or OSMesa), with the
// SH runtime, a baseline or the ray-traced reference (README "shrefract-render"). A thin shell:
// it parses the command line into a RenderRequest, and eval/render_method.h sets the method up
// and draws; the flicker and dispersion measures are eval/'s (image_eval.h, reference.h). Every
// output is checked before the render and written only when all succeed (common/output.h); exit
// codes as every tool's (README).
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "common/cli/cli.h"
#include "common/error.h"
#include "common/evalbuffer.h"
#include "common/output.h"
#include "eval/image_eval.h"
#include "eval/render_method.h"

namespace {

using namespace shrefract;

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
    std::string bakePath, envPath, camera, eye, target, size = "1024x1024";
    std::string out, outExr, dirs, dumpDir;
    Backend backend = Backend::Egl;
    float fov = 45.0f, exposure = 1.0f;
    int order = -1, frames = 5, spp = 1;
    bool smoothing = false;
    std::string method = "sh", scenePath, absorption, flicker, flickerJson;
    WymanTir tir = WymanTir::Reflect;
    PixelExits exits = PixelExits::Exact;
    bool latLongLookup = false, noVerify = false;
    std::string iorText, bracketPath;
    RefractorOptions sh;  // defaults shown in --help
    app.add_option("bake", bakePath, "NAME.shrefract.exr from shrefract-bake")->required();
    app.add_option("--env", envPath, "lat-long environment EXR")->required();
    app.add_option("--camera", camera, "orbit:AZ,EL,DIST (degrees, degrees, object units)");
    app.add_option("--eye", eye, "camera position x,y,z (with --target)");
    app.add_option("--target", target, "camera target x,y,z");
    app.add_option("--fov", fov, "vertical field of view, degrees")->capture_default_str();
    app.add_option("--size", size, "image size WxH")->capture_default_str();
    app.add_option("--order", order, "SH order used at runtime (default: all stored)");
    cli::addEnumOption(app, "--backend", backend, "headless GL: egl | osmesa");
    cli::addEnumOption(app, "--preset", sh.preset, "shader limits: modern | 2006");
    cli::addEnumOption(app, "--path", sh.path,
                       "sh: interpolation, direct | rho | charts | auto (direct for modern, rho for "
                       "2006, charts for chart bakes)");
    cli::addEnumOption(app, "--decompression", sh.decompression, "sh, direct path: vertex | texture | auto");
    cli::addEnumOption(app, "--shading", sh.shading,
                       "sh: spread (lobes from the predicted error, or the SH length, and the pixel "
                       "footprint) | sharp (the paper's lookup) | blend (the two mixed by the lobe's "
                       "width) | jitter (one stable direction drawn from the lobe) | auto (jitter "
                       "on SH bakes, blend on grid-basis ones)");
    app.add_option("--jitter-cell", sh.jitterCell, "sh, jitter shading: the cell of one drawn direction, a fraction of the object's bounding-box diagonal")
        ->capture_default_str()->check(CLI::Range(1e-6f, 10.0f));
    app.add_option("--jitter-gate", sh.jitterGate, "sh, jitter shading: the lobe width (radians) from which the draw widens and the lookup covers the exit's pixel (0: ungated)")
        ->capture_default_str()->check(CLI::Range(0.0f, 10.0f));
    app.add_option("--taps", sh.taps, "sh: lookups per pixel, averaged: 1 (its centre) | 4 (at +-1/4 pixel) | -1 (4 on grid-basis bakes, 1 on SH)")
        ->capture_default_str()->check(CLI::IsMember({-1, 1, 4}));
    app.add_option("--blend-sigma", sh.blendSigma, "sh, blend shading: lobe width (radians) at which the lobe has half the weight")
        ->capture_default_str()->check(CLI::Range(1e-4f, 10.0f));
    bool noErrorModel = false;
    app.add_flag("--no-error-model", noErrorModel,
                 "sh: lobe widths from the SH length alone, not from the bake's error model");
    app.add_option("--spread-scale", sh.spreadScale, "sh, spread shading: lobe width factor")
        ->capture_default_str()->check(CLI::Range(0.0f, 100.0f));
    app.add_option("--footprint-scale", sh.footprintScale, "sh, spread shading: screen footprint factor")
        ->capture_default_str()->check(CLI::Range(0.0f, 100.0f));
    app.add_flag("--half-weights", sh.halfWeights, "sh: upload float32 weights as RGBA16F");
    cli::addEnumOption(app, "--form", sh.form, "SH evaluation in GLSL: auto | polynomial | recurrence");
    app.add_option("--frames", frames, "frames timed after a warm-up (median wall ms per frame)")->capture_default_str();
    app.add_option("--spp", spp,
                   "raytrace: stratified samples per pixel for the colour (64: the anti-aliased "
                   "reference); the direction buffer keeps the pixel centre")
        ->capture_default_str()->check(CLI::Range(1, 4096));
    app.add_flag("--smooth", smoothing, "spatial smoothing (neighbour lists; texture space for charts)");
    int gutter = -1;
    std::string seamAware = "on";
    app.add_option("--gutter", gutter,
                   "chart layouts: gutter rings filled by dilation (default: the bake's; 0: none)")
        ->check(CLI::Range(-1, 64));
    app.add_option("--seam-aware", seamAware,
                   "chart layouts: gutter texels at smooth seams take the values across the cut")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    app.add_option("--exposure", exposure, "exposure before the tone map")->capture_default_str();
    app.add_option("--absorption", absorption,
                   "kappa r,g,b per object-space unit for every method, instead of the bake's media "
                   "(tinted glass without re-baking: the paths do not depend on it)");
    app.add_option("--out", out, "tone-mapped PNG");
    app.add_option("--out-exr", outExr, "linear HDR RGBA EXR");
    app.add_option("--dirs", dirs,
                   "evaluation buffer EXR: R,G,B colour, A coverage, dir.X/Y/Z world exit "
                   "direction (docs/format.md)");
    app.add_option("--method", method, "sh | single | wyman | raytrace")->capture_default_str()
        ->check(CLI::IsMember({"sh", "single", "wyman", "raytrace"}));
    cli::addEnumOption(app, "--wyman-tir", tir,
                       "Wyman at total internal reflection: reflect | straight | grazing");
    cli::addEnumOption(app, "--exits", exits,
                       "raytrace: each pixel's exit from its traced path (exact), or from the bake's "
                       "representation fitted to the grid traced at the pixel's own entry point: "
                       "fit | split | grid (docs/evaluation.md \"Pixel fits\"; slow: a grid per pixel)");
    app.add_flag("--latlong-lookup", latLongLookup,
                 "raytrace: look the environment up bilinearly in the lat-long image, not through "
                 "the runtime's cube map");
    app.add_option("--scene", scenePath,
                   "raytrace, wyman: the baked mesh or scene, if not where the manifest says");
    app.add_option("--flicker", flicker,
                   "N:STEP: render N frames orbiting STEP degrees of azimuth apart from --camera and "
                   "report the mean absolute difference of consecutive tone-mapped frames");
    app.add_option("--flicker-json", flickerJson, "write the --flicker result here");
    app.add_option("--dump-shaders", dumpDir, "write the generated GLSL into DIR");
    app.add_option("--ior", iorText,
                   "index of refraction N, or one per channel R,G,B (dispersion): raytrace traces the "
                   "scene's first part at it, sh interpolates (docs/runtime.md \"Variable IOR\")");
    app.add_option("--ior-bracket", bracketPath,
                   "sh with --ior: a second bake of the same mesh at another index, interpolated "
                   "with BAKE per channel instead of the straight path");
    std::string seamsOf, seamsJson, jsonPath;
    bool stageTimers = false;
    app.add_option("--json", jsonPath,
                   "write what the render measured here as JSON (- for stdout): ms per frame and "
                   "how it was timed, GPU memory, coverage, seams, flicker; what scripts read");
    app.add_flag("--stage-timers", stageTimers,
                 "GL timer queries around each stage of the warm frame, printed as GPU ms (each "
                 "waits for the GPU; the ms per frame is always measured without them)");
    app.add_option("--seams-of", seamsOf,
                   "a chart bake whose smooth seams to measure the render's jump across "
                   "(default: this bake, if it is one)");
    app.add_option("--seams-json", seamsJson, "write the seam jump statistics here (JSON)");
    app.add_flag("--no-verify", noVerify, "skip the bake's checksums (faster; a corrupt file may draw garbage)");
    return shrefract::cli::run(app, "shrefract-render", argc, argv, [&] {
        // Outputs first: a path that cannot be written fails before any rendering.
        shrefract::OutputSet outputs;
        const std::string stagedPng = out.empty() ? "" : outputs.add(out);
        const std::string stagedExr = outExr.empty() ? "" : outputs.add(outExr);
        const std::string stagedDirs = dirs.empty() ? "" : outputs.add(dirs);
        const std::string stagedFlicker = flickerJson.empty() ? "" : outputs.add(flickerJson);
        const std::string stagedSeams = seamsJson.empty() ? "" : outputs.add(seamsJson);
        const std::string stagedJson = jsonPath.empty() || jsonPath == "-" ? "" : outputs.add(jsonPath);
        nlohmann::json summary = {{"method", method}, {"bake", bakePath}};
        int width = 0, height = 0;
        char x = 0;
        std::istringstream sizeStream(size);
        if (!(sizeStream >> width >> x >> height) || x != 'x' || width < 1 || height < 1 ||
            width > 16384 || height > 16384 || !sizeStream.eof())
            throw std::invalid_argument("--size: expected WxH, got '" + size + "'");
        Camera cam = Camera::orbit(30.0f, 20.0f, 3.0f);
        std::vector<float> orbit = {30.0f, 20.0f, 3.0f};
        if (!camera.empty()) {
            if (camera.rfind("orbit:", 0) != 0)
                throw std::invalid_argument("--camera: expected orbit:AZ,EL,DIST, got '" + camera + "'");
            orbit = parseFloats(camera.substr(6), 3, "--camera");
            cam = Camera::orbit(orbit[0], orbit[1], orbit[2]);
        }
        if (!eye.empty() || !target.empty()) {
            if (eye.empty() || target.empty() || !camera.empty())
                throw std::invalid_argument("--eye and --target go together, without --camera");
            auto e = parseFloats(eye, 3, "--eye"), t = parseFloats(target, 3, "--target");
            cam.eye = {e[0], e[1], e[2]};
            cam.target = {t[0], t[1], t[2]};
        }
        cam.fovDegrees = fov;
        int flickerFrames = 0;
        float flickerStep = 0;
        if (!flicker.empty()) {
            char colon = 0;
            std::istringstream in(flicker);
            if (!(in >> flickerFrames >> colon >> flickerStep) || colon != ':' || !in.eof() ||
                flickerFrames < 2 || flickerFrames > 10000 || !std::isfinite(flickerStep))
                throw std::invalid_argument("--flicker: expected N:STEP with N >= 2, got '" + flicker + "'");
            if (!eye.empty()) throw std::invalid_argument("--flicker orbits: give --camera orbit:AZ,EL,DIST");
        }
        if (exits != PixelExits::Exact && (method != "raytrace" || spp > 1 || !iorText.empty()))
            throw std::invalid_argument(std::string("--exits ") + nameOf(exits) +
                                        ": only --method raytrace at one sample per pixel and the "
                                        "bake's own index fits a grid at each pixel");
        if (spp > 1 && method != "raytrace")
            throw std::invalid_argument("--spp " + std::to_string(spp) +
                                        ": only --method raytrace takes several samples per pixel");

        glm::vec3 ior(0.0f);  // 0: the bake's own
        if (!iorText.empty()) {
            auto v = parseFloats(iorText, iorText.find(',') == std::string::npos ? 1 : 3, "--ior");
            ior = v.size() == 1 ? glm::vec3(v[0]) : glm::vec3(v[0], v[1], v[2]);
            if (glm::any(glm::lessThan(ior, glm::vec3(1.0f))) ||
                glm::any(glm::greaterThan(ior, glm::vec3(5.0f))))
                throw std::invalid_argument("--ior: every index must lie in [1, 5], got '" +
                                            iorText + "'");
            if (method != "sh" && method != "raytrace")
                throw std::invalid_argument("--ior works with --method sh or raytrace");
        }
        if (!bracketPath.empty() && (iorText.empty() || method != "sh"))
            throw std::invalid_argument("--ior-bracket needs --ior and --method sh");

        // Input first (cheap, and the common failure), then the context.
        Bake bake = loadBake(bakePath, !noVerify);
        for (const std::string& w : bake.warnings())
            std::fprintf(stderr, "shrefract-render: warning: %s: %s\n", bakePath.c_str(), w.c_str());
        if (order < -1 || order > bake.order())
            throw std::invalid_argument("--order " + std::to_string(order) + ": " + bakePath +
                                        " stores orders 0.." + std::to_string(bake.order()) +
                                        " (-1: all)");
        if (!absorption.empty()) {
            const std::vector<float> kappa = parseFloats(absorption, 3, "--absorption");
            for (float k : kappa)
                if (!(k >= 0.0f) || !std::isfinite(k))
                    throw std::invalid_argument("--absorption: kappa must be finite and >= 0, got '" + absorption + "'");
            sh.absorption = glm::vec3(kappa[0], kappa[1], kappa[2]);
        }
        RenderRequest request;
        request.method = method;
        request.bakePath = bakePath, request.envPath = envPath, request.scenePath = scenePath;
        request.bracketPath = bracketPath, request.seamsOf = seamsOf, request.dumpDir = dumpDir;
        request.width = width, request.height = height, request.frames = frames, request.spp = spp;
        request.ior = ior;
        request.backend = backend, request.tir = tir, request.exits = exits;
        request.latLongLookup = latLongLookup, request.verify = !noVerify;
        request.stageTimers = stageTimers;
        request.sh = sh;
        request.sh.errorModel = !noErrorModel;
        request.sh.order = order;
        request.sh.smoothing = smoothing;
        request.sh.gutter = gutter;
        request.sh.seamAware = seamAware == "on";
        RenderMethod m(request, cam, summary);  // input first (cheap, the common failure), then GL

        RenderedFrame frame;
        double msPerFrame = 0;
        if (flickerFrames > 0) {
            // A slow orbit: the mean absolute frame-to-frame change (issue 8's flicker ratio is
            // this over the 64-spp reference's). Frame 0 is the --camera view.
            std::vector<double> diffs;
            RenderedFrame previous;
            for (int f = 0; f < flickerFrames; ++f) {
                Camera c = Camera::orbit(orbit[0] + f * flickerStep, orbit[1], orbit[2]);
                c.fovDegrees = fov;
                frame = m.render(c, &msPerFrame);
                if (f > 0) diffs.push_back(meanAbsToneMappedDifference(previous.color, frame.color, exposure));
                previous = frame;
            }
            double mean = 0;
            for (double d : diffs) mean += d;
            mean /= double(diffs.size());
            std::printf("flicker: %d frames %g deg apart, mean |frame - previous| = %.6f (tone-mapped)\n",
                        flickerFrames, flickerStep, mean);
            if (!flickerJson.empty())
                writeFile(stagedFlicker,
                          nlohmann::json{{"method", method}, {"frames", flickerFrames}, {"stepDeg", flickerStep},
                                         {"meanAbsDifference", mean}, {"differences", diffs}}.dump(1) + "\n");
            summary["flicker"] = {{"frames", flickerFrames}, {"stepDeg", flickerStep},
                                  {"meanAbsDifference", mean}};
        } else {
            // The reference is traced once. A GL method draws a warm-up frame first (llvmpipe
            // JIT-compiles shaders at the first draw), so that the GPU stage times printed below
            // are those of a warm frame.
            if (m.timesFrames()) m.render(cam, &msPerFrame);
            frame = m.render(cam, &msPerFrame);
            m.reportWarmFrame(frame, summary);
        }
        if (m.timesFrames()) msPerFrame = m.wallMs(cam);
        std::printf("ms per frame (%s): %.3f (%s)\n", method.c_str(), msPerFrame, m.timing().c_str());
        summary["msPerFrame"] = msPerFrame;
        summary["timing"] = m.timing();
        const nlohmann::json seams = m.reportSeams(frame, cam, summary);
        if (!seamsJson.empty() && !seams.is_null()) writeFile(stagedSeams, seams.dump(2) + "\n");
        size_t covered = 0;
        for (size_t i = 3; i < frame.directions.size(); i += 4) covered += frame.directions[i] > 0;
        std::printf("coverage: %.1f%% of pixels\n", 100.0 * covered / (size_t(width) * height));
        summary["coverage"] = double(covered) / (double(width) * height);
        if (!stagedJson.empty()) writeFile(stagedJson, summary.dump(1) + "\n");
        if (!out.empty()) shrefract::writePng(stagedPng, frame, exposure);
        if (!outExr.empty()) shrefract::writeExr(stagedExr, width, height, frame.color);
        if (!dirs.empty())
            shrefract::writeEvalBuffer(
                stagedDirs, shrefract::makeEvalBuffer(width, height, frame.color, frame.directions));
        outputs.commit();  // all or none
        if (jsonPath == "-") std::printf("%s\n", summary.dump(1).c_str());
        return shrefract::cli::kOk;
    });
}
