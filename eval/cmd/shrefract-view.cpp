// shrefract-view: interactive viewer for a bake (GLFW window, OpenGL 3.3 core).
//   shrefract-view BAKE --env ENV.exr [--size WxH] [--order L] [--preset modern|2006] [--smooth]
//                  [--exposure E] [--screenshot OUT.png --frames N] [--no-object]
// Controls: left drag orbits, scroll zooms, Up/Down (or +/-) change the SH order used
// (progressive decompression), S toggles smoothing, M cycles methods, T toggles per-stage
// timings, G toggles the gutters and A seam-aware filling (chart bakes), P or F12 saves a
// screenshot, Esc quits. The title bar shows frame and stage times,
// which are also printed once a second. No GUI toolkit: the HUD is the title bar and stdout.
#define GLFW_INCLUDE_NONE  // GL comes from the runtime's loader (gl.h), not GL/gl.h
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "runtime/src/bake_data.h"
#include "gl.h"  // the runtime's loader: the viewer needs a handful of GL calls of its own
#include "common/bakefile.h"
#include "common/cli/cli.h"
#include "common/output.h"
#include "common/png.h"
#include "shrefract/baselines.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "eval/directions.h"
#include "eval/reference.h"

namespace {

using namespace shrefract::gl;

// Methods the viewer switches between with M. Wyman's d_N is cast with Embree (eval/reference.h).
const char* kMethods[] = {"sh", "single", "wyman"};

struct Viewer {
    float azimuth = 30.0f, elevation = 20.0f, distance = 3.0f;
    float radius = 1.0f;       // of the object's bounding sphere
    glm::vec3 centre{0.0f};    // orbit target
    bool dragging = false;
    double lastX = 0, lastY = 0;
    int order = 0, maxOrder = 0, method = 0;
    bool smoothing = false, timings = true, screenshot = false, quit = false;
    bool gutters = true, seamAware = true;  // chart bakes: the bake's gutter rings, seam sources
};


// Reads the back buffer (display values: everything is drawn tone mapped) into a PNG.
void saveScreenshot(const std::string& path, int w, int h) {
    std::vector<unsigned char> rows(static_cast<size_t>(w) * h * 3), flipped(rows.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
    const size_t stride = static_cast<size_t>(w) * 3;
    for (int y = 0; y < h; ++y)
        std::copy_n(&rows[(h - 1 - y) * stride], stride, &flipped[y * stride]);
    shrefract::writePngRgb8(path, w, h, flipped.data());
    std::printf("saved %s (%dx%d)\n", shrefract::outputName(path).c_str(), w, h);
}

Viewer& state(GLFWwindow* window) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(window)); }

void onKey(GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    Viewer& v = state(window);
    switch (key) {
        case GLFW_KEY_ESCAPE: v.quit = true; break;
        case GLFW_KEY_UP: case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD:
            v.order = std::min(v.order + 1, v.maxOrder); break;
        case GLFW_KEY_DOWN: case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT:
            v.order = std::max(v.order - 1, 0); break;
        case GLFW_KEY_S: v.smoothing = !v.smoothing; break;
        case GLFW_KEY_M: v.method = (v.method + 1) % static_cast<int>(std::size(kMethods)); break;
        case GLFW_KEY_T: v.timings = !v.timings; break;
        case GLFW_KEY_G: v.gutters = !v.gutters; break;
        case GLFW_KEY_A: v.seamAware = !v.seamAware; break;
        case GLFW_KEY_P: case GLFW_KEY_F12: v.screenshot = true; break;
        default: break;
    }
}

void onMouseButton(GLFWwindow* window, int button, int action, int) {
    Viewer& v = state(window);
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    v.dragging = action == GLFW_PRESS;
    glfwGetCursorPos(window, &v.lastX, &v.lastY);
}

void onCursor(GLFWwindow* window, double x, double y) {
    Viewer& v = state(window);
    if (!v.dragging) return;
    v.azimuth -= 0.4f * static_cast<float>(x - v.lastX);
    v.elevation = std::clamp(v.elevation + 0.4f * static_cast<float>(y - v.lastY), -89.0f, 89.0f);
    v.lastX = x;
    v.lastY = y;
}

void onScroll(GLFWwindow* window, double, double dy) {
    Viewer& v = state(window);
    v.distance = std::clamp(v.distance * std::pow(0.9f, static_cast<float>(dy)), 0.05f * v.radius,
                            50.0f * v.radius);
}

void onGlfwError(int code, const char* text) {
    std::fprintf(stderr, "shrefract-view: GLFW error 0x%x: %s\n", code, text);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Interactive viewer for a shrefract bake"};
    std::string bakePath, envPath, size = "1024x768", screenshotPath;
    shrefract::ShaderPreset preset = shrefract::ShaderPreset::Modern;
    int order = -1, frames = 0;
    float exposure = 1.0f;
    bool smoothing = false, noObject = false, noVerify = false;
    app.add_option("bake", bakePath, "NAME.shrefract.exr from shrefract-bake")->required();
    app.add_option("--env", envPath, "lat-long environment EXR")->required();
    app.add_option("--size", size, "window size WxH")->capture_default_str();
    app.add_option("--order", order, "SH order used at start (default: all stored)");
    shrefract::cli::addEnumOption(app, "--preset", preset, "shader limits: modern | 2006");
    app.add_flag("--smooth", smoothing, "start with spatial smoothing on");
    app.add_option("--exposure", exposure, "exposure before the tone map")->capture_default_str();
    app.add_option("--screenshot", screenshotPath, "save the last frame here and exit (with --frames)");
    app.add_option("--frames", frames, "render N frames, then exit (0: run until Esc)");
    app.add_flag("--no-object", noObject, "draw the environment only (a reference for tests)");
    app.add_flag("--no-verify", noVerify, "skip the bake's checksums (faster; a corrupt file may draw garbage)");
    std::string startMethod = "sh";
    app.add_option("--method", startMethod, "method at start (M cycles): sh | single | wyman")
        ->capture_default_str();
    return shrefract::cli::run(app, "shrefract-view", argc, argv, [&] {
        // The final screenshot is checked and staged before any window opens (common/output.h).
        shrefract::OutputSet outputs;
        const std::string stagedShot = screenshotPath.empty() ? "" : outputs.add(screenshotPath);
        int width = 0, height = 0;
        char x = 0;
        std::istringstream sizeStream(size);
        if (!(sizeStream >> width >> x >> height) || x != 'x' || width < 16 || height < 16)
            throw std::invalid_argument("--size: expected WxH (at least 16x16), got '" + size + "'");
        if (!screenshotPath.empty() && frames <= 0) frames = 1;

        glfwSetErrorCallback(onGlfwError);
        if (!glfwInit()) throw std::runtime_error("cannot initialise GLFW (no display?)");
        // Closes the window and GLFW on every way out, after the GL objects declared below.
        struct Glfw {
            GLFWwindow* window = nullptr;
            ~Glfw() {
                if (window) glfwDestroyWindow(window);
                glfwTerminate();
            }
        } glfw;
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
        glfwWindowHint(GLFW_DEPTH_BITS, 24);
        GLFWwindow* window = glfw.window = glfwCreateWindow(width, height, "shrefract-view", nullptr, nullptr);
        if (!window) throw std::runtime_error("cannot open a window with OpenGL 3.3 core");
        glfwMakeContextCurrent(window);
        glfwSwapInterval(frames > 0 ? 0 : 1);

        ensureLoaded(reinterpret_cast<Loader>(&glfwGetProcAddress));
        std::printf("GL: %s, %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                    reinterpret_cast<const char*>(glGetString(GL_VERSION)));
        shrefract::Bake bake = shrefract::loadBake(bakePath, !noVerify);
        for (const std::string& w : bake.warnings())
            std::fprintf(stderr, "shrefract-view: warning: %s: %s\n", bakePath.c_str(), w.c_str());
        if (order < -1 || order > bake.order())
            throw std::invalid_argument("--order " + std::to_string(order) + ": " + bakePath +
                                        " stores orders 0.." + std::to_string(bake.order()) +
                                        " (-1: all)");
        shrefract::Environment env = shrefract::Environment::loadLatLong(envPath);
        shrefract::RefractorOptions options;
        options.preset = preset;
        options.order = order;
        options.smoothing = smoothing;
        options.toneMap = true;  // straight to the window: display values
        options.exposure = exposure;
        options.loader = reinterpret_cast<Loader>(&glfwGetProcAddress);
        auto refractor = shrefract::Refractor::create(bake, options);

        // The other methods share the mesh; Wyman's d_N is cast once here.
        std::vector<float> normalDistance;
        {
            shrefract::Scene scene = shrefract::sceneOfBake(bakeData(bake), bakePath);
            shrefract::Tracer tracer(scene, shrefract::traceOptionsOfBake(bakeData(bake)));
            normalDistance = shrefract::normalDistances(tracer, bakeData(bake).layout);
        }
        std::vector<std::unique_ptr<shrefract::Baseline>> baselines;
        for (shrefract::BaselineMethod m : {shrefract::BaselineMethod::Single, shrefract::BaselineMethod::Wyman}) {
            if (m == shrefract::BaselineMethod::Wyman && normalDistance.empty()) break;
            shrefract::BaselineOptions bo;
            bo.method = m;
            bo.loader = options.loader;
            bo.toneMap = true;
            bo.exposure = exposure;
            baselines.push_back(shrefract::Baseline::create(bake, normalDistance, bo));
        }

        Viewer v;
        {
            glm::vec3 lo(1e30f), hi(-1e30f);
            for (glm::vec3 p : bakeData(bake).layout.position) lo = glm::min(lo, p), hi = glm::max(hi, p);
            v.centre = 0.5f * (lo + hi);
            v.radius = std::max(0.5f * glm::length(hi - lo), 1e-30f);
            v.distance = 3.0f * v.radius;
        }
        v.order = refractor->order();
        v.method = -1;
        for (int k = 0; k < static_cast<int>(std::size(kMethods)); ++k)
            if (startMethod == kMethods[k]) v.method = k;
        if (v.method < 0) throw std::invalid_argument("--method: not available here: " + startMethod);
        v.maxOrder = bake.order();
        v.smoothing = smoothing;
        glfwSetWindowUserPointer(window, &v);
        glfwSetKeyCallback(window, onKey);
        glfwSetMouseButtonCallback(window, onMouseButton);
        glfwSetCursorPosCallback(window, onCursor);
        glfwSetScrollCallback(window, onScroll);
        std::printf("bake: %s, %d samples, %d triangles, %s layout; %.1f MB of GPU textures\n"
                    "keys: drag orbit, scroll zoom, Up/Down order, S smoothing, M method, "
                    "T timings, G gutters, A seam-aware (charts), P/F12 screenshot, Esc quit\n",
                    bakeData(bake).modelName().c_str(), bake.sampleCount(), bake.triangleCount(), bake.layout().c_str(),
                    refractor->memory().total() / 1e6);
        const bool charts = bake.layout() != "joining";

        using Clock = std::chrono::steady_clock;
        auto last = Clock::now(), lastReport = last;
        double frameMs = 0;
        int frame = 0, shots = 0;
        while (!glfwWindowShouldClose(window) && !v.quit) {
            if (v.order != refractor->order()) refractor->setOrder(v.order);
            refractor->setSmoothing(v.smoothing);
            refractor->setTimings(v.timings);
            refractor->setGutter(v.gutters ? -1 : 0);
            refractor->setSeamAware(v.seamAware);

            int fbw = 0, fbh = 0;
            glfwGetFramebufferSize(window, &fbw, &fbh);
            shrefract::Camera cam = shrefract::Camera::orbit(v.azimuth, v.elevation, v.distance, v.centre);
            glm::mat4 view = shrefract::viewMatrix(cam);
            glm::mat4 projection = shrefract::projectionMatrix(cam, fbw, std::max(1, fbh));
            const bool sh = v.method == 0;
            if (!noObject && sh) refractor->update({view, projection, glm::mat4(1.0f)});
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            glViewport(0, 0, fbw, fbh);
            glClearColor(0, 0, 0, 1);
            glDepthMask(GL_TRUE);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            env.drawBackground(view, projection, true, exposure);
            if (!noObject && sh) refractor->draw(env);
            if (!noObject && !sh) baselines[v.method - 1]->draw(view, projection, glm::mat4(1.0f), env);
            ensureLoaded(reinterpret_cast<Loader>(&glfwGetProcAddress));

            ++frame;
            const bool last_frame = frames > 0 && frame >= frames;
            if (v.screenshot || (last_frame && !screenshotPath.empty())) {
                glFinish();
                const bool final = last_frame && !screenshotPath.empty();
                saveScreenshot(final ? stagedShot : "shrefract-view-" + std::to_string(shots++) + ".png",
                               fbw, fbh);
                if (final) outputs.commit();
                v.screenshot = false;
            }
            glfwSwapBuffers(window);
            glfwPollEvents();

            auto now = Clock::now();
            frameMs = std::chrono::duration<double, std::milli>(now - last).count();
            last = now;
            char title[320];
            if (sh) {
                const shrefract::Timings& t = refractor->timings();
                char chartState[64] = "";
                if (charts)
                    std::snprintf(chartState, sizeof chartState, " gutter %d seam-aware %s",
                                  refractor->gutter(), refractor->seamAware() ? "on" : "off");
                std::snprintf(title, sizeof title,
                              "shrefract-view | sh order %d (%s, %d pass) smooth %s%s | %.1f ms/frame | "
                              "view %.2f dec %.2f smooth %.2f %s %.2f shade %.2f ms",
                              refractor->order(), shrefract::nameOf(refractor->path()), refractor->passCount(),
                              v.smoothing ? "on" : "off", chartState, frameMs, t.view, t.decompress,
                              t.smooth, charts ? "gutters" : "unpack", t.unpack, t.shade);
            } else {
                // The baselines have no SH order and no SH stages: only their own passes.
                const shrefract::BaselineTimings& t = baselines[v.method - 1]->timings();
                std::snprintf(title, sizeof title,
                              "shrefract-view | %s | %.1f ms/frame | back faces %.2f shade %.2f ms",
                              kMethods[v.method], frameMs, t.backFaces, t.shade);
            }
            glfwSetWindowTitle(window, title);
            if (now - lastReport > std::chrono::seconds(1) || last_frame) {
                // Stdout gets the title without its "shrefract-view | " prefix.
                std::printf("%s%s\n", title + 17, v.timings ? "" : " (stage timings off)");
                std::fflush(stdout);
                lastReport = now;
            }
            if (last_frame) break;
        }
        return shrefract::cli::kOk;
    });
}
