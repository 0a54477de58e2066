// Offscreen rendering of a bake for tools and tests: the library behind shrefract-render.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shrefract/runtime.h"

namespace shrefract {
class Baseline;
}

namespace shrefract {

struct Camera {
    glm::vec3 eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
    float fovDegrees = 45.0f;
    // "AZ,EL,DIST" in degrees and object units around `target`; throws std::invalid_argument.
    static Camera orbit(float azimuthDeg, float elevationDeg, float distance,
                        glm::vec3 target = glm::vec3(0.0f));
};

// One rendered frame: RGBA floats row-major, row 0 = top.
struct RenderedFrame {
    int width = 0, height = 0;
    std::vector<float> color;       // linear HDR radiance, background included, A = 1
    std::vector<float> directions;  // world exit direction (xyz) + coverage (w) per pixel
    Timings timings;
};

// A framebuffer object in the current context for apps with no window (headless EGL has no
// default framebuffer): colour RGBA32F (draw buffer 0), direction buffer RGBA32F (1), depth.
class OffscreenTarget {
public:
    // Throws std::runtime_error if the driver refuses the framebuffer.
    OffscreenTarget(int width, int height);
    ~OffscreenTarget();
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;
    // Binds it with both draw buffers, sets the viewport, clears colour (to 0) and depth.
    void bind();
    // Waits for the GPU and reads both buffers back (rows top-down); timings left zero.
    RenderedFrame read() const;
    int width() const { return width_; }
    int height() const { return height_; }
    unsigned framebuffer() const { return fbo_; }

private:
    int width_ = 0, height_ = 0;
    unsigned fbo_ = 0, color_ = 0, directions_ = 0, depth_ = 0;
};

// Renders one frame in the current context (object at the origin, identity model).
RenderedFrame renderFrame(Refractor& refractor, const Environment& environment, const Camera& camera,
                  int width, int height);
// The same frame with a baseline method (shrefract/baselines.h); frame.timings stays zero: read
// baseline.timings().
RenderedFrame renderFrame(Baseline& baseline, const Environment& environment, const Camera& camera,
                          int width, int height);
// Wall-clock milliseconds per frame as an app sees it: `camera`'s frame drawn into an offscreen
// target (update, environment background, object) and waited for with glFinish, nothing read
// back. First a warm-up of at least two frames and half a second (llvmpipe compiles shaders at the
// first draw; a GPU that idled comes up to clock), then the median of `frames` frames. GL timer
// queries are no substitute on llvmpipe: they miss most of its rasterizer's work
// (docs/runtime.md, "Benchmark").
double frameWallMs(Refractor& refractor, const Environment& environment, const Camera& camera,
                   int width, int height, int frames);
double frameWallMs(Baseline& baseline, const Environment& environment, const Camera& camera,
                   int width, int height, int frames);
// The view and projection matrices renderFrame uses (glm::lookAt, glm::perspective, near 0.01,
// far 1000): the reference renderer's camera must match them (docs/evaluation.md).
glm::mat4 viewMatrix(const Camera& camera);
glm::mat4 projectionMatrix(const Camera& camera, int width, int height);

// Writes 8-bit sRGB PNG of toneMap(color), or float RGBA EXR. Both write a temporary file beside
// `path` and rename it when complete: a failure (std::runtime_error naming the file and the OS's
// reason) leaves `path` as it was, and a symbolic link, FIFO or device there is never replaced.
void writePng(const std::string& path, const RenderedFrame& frame, float exposure = 1.0f);
void writeExr(const std::string& path, int width, int height, const std::vector<float>& rgba);

}  // namespace shrefract
