// What shrefract-render draws a bake with, set up once: the SH runtime, a baseline (single-sided,
// Wyman 2005) or the Embree reference. The tool parses its command line into a RenderRequest and
// asks a RenderMethod for frames; everything between lives here.
#pragma once

#include <memory>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common/bakefile.h"
#include "eval/pixel_fit.h"
#include "shrefract/baselines.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"

namespace shrefract {

struct RenderRequest {
    std::string method = "sh";  // sh | single | wyman | raytrace
    std::string bakePath, envPath;
    std::string scenePath;      // raytrace, wyman, seams: the baked scene if not where the manifest says
    std::string bracketPath;    // sh with ior: a second bake at another index
    std::string seamsOf;        // a chart bake whose seams to measure the render's jump across
    std::string dumpDir;        // sh: where to write the generated GLSL
    int width = 1024, height = 1024;
    int frames = 5;             // GL methods: frames timed after the warm-up
    int spp = 1;                // raytrace: samples per pixel
    PixelExits exits = PixelExits::Exact;  // raytrace: the traced exits, or a fit at each pixel
    glm::vec3 ior{0.0f};        // 0: the bake's own
    Backend backend = Backend::Egl;
    bool latLongLookup = false, verify = true, stageTimers = false;
    RefractorOptions sh;        // the SH runtime's options; absorption applies to every method
    WymanTir tir = WymanTir::Reflect;
};

class RenderMethod {
public:
    // Loads the bake (and scene, environment, context) and sets the method up, printing what it
    // set up and adding it to `summary`. Throws InputError / std::invalid_argument for bad input.
    RenderMethod(const RenderRequest& request, const Camera& camera, nlohmann::json& summary);
    ~RenderMethod();
    RenderMethod(const RenderMethod&) = delete;
    RenderMethod& operator=(const RenderMethod&) = delete;

    // One camera's frame; `ms`: the reference's CPU time (GL methods: see wallMs).
    RenderedFrame render(const Camera& camera, double* ms);
    bool timesFrames() const;               // a GL method: wallMs() measures it
    double wallMs(const Camera& camera);    // frameWallMs, stage timers off
    const std::string& timing() const;      // what its ms per frame is
    // After a warm frame: the GPU stage times (when asked for) and memory, printed and added.
    void reportWarmFrame(const RenderedFrame& frame, nlohmann::json& summary) const;
    // The exit direction's jump across the smooth seams of a chart bake (this bake, or
    // RenderRequest::seamsOf), at the pixel pairs that straddle one: printed, added to `summary`
    // and returned; null when there is no chart bake to measure.
    nlohmann::json reportSeams(const RenderedFrame& frame, const Camera& camera,
                               nlohmann::json& summary) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace shrefract
