// The smallest app that uses the shrefract runtime: load a bake, refract an environment through
// it for a few frames, report the stage times and save the last frame.
//
//   shrefract-example-minimal BAKE.shrefract.exr ENV.exr OUT.png
//
// Built here as `shrefract-example-minimal`; outside the tree an app does
//   find_package(shrefract REQUIRED)
//   target_link_libraries(app PRIVATE shrefract::runtime)
// Only the public headers (include/shrefract/) are used below.
#include <cmath>
#include <cstdio>
#include <exception>

#include <glm/gtc/matrix_transform.hpp>

#include "shrefract/context.h"  // headless contexts (EGL, OSMesa)
#include "shrefract/render.h"   // OffscreenTarget, writePng: only because we have no window
#include "shrefract/runtime.h"  // Bake, Environment, Refractor: what every app needs

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: %s BAKE.shrefract.exr ENV.exr OUT.png\n", argv[0]);
        return 2;
    }
    try {
        const int width = 512, height = 512;

        // 1. An OpenGL 3.3+ core context, current on this thread. Here a headless one (Mesa's
        //    surfaceless EGL: llvmpipe or a GPU, no display needed). A windowed app creates its
        //    own instead, e.g. with GLFW:
        //      glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3); ... GLFW_OPENGL_CORE_PROFILE ...
        //      glfwMakeContextCurrent(window);
        //    and passes `glfwGetProcAddress` as RefractorOptions::loader (eval/cmd/
        //    shrefract-view.cpp does exactly that).
        auto context = shrefract::createHeadlessContext(shrefract::Backend::Egl);
        std::printf("GL: %s\n", context->description().c_str());

        // 2. The bake (from shrefract-bake) and an HDR lat-long environment. Both throw an
        //    exception naming the file on bad input; the library never exits the process.
        shrefract::Bake bake = shrefract::loadBake(argv[1]);
        shrefract::Environment environment = shrefract::Environment::loadLatLong(argv[2]);
        std::printf("bake: order %d, %d samples, %d triangles, ior %.2f\n", bake.order(),
                    bake.sampleCount(), bake.triangleCount(), bake.ior());

        // 3. The refractor uploads the SH weights and compiles the generated decompression
        //    shaders in the current context. Options: shader limits ("modern": one pass;
        //    "2006": the paper's multipass budget), the order used, smoothing, tone mapping.
        shrefract::RefractorOptions options;
        options.loader = context->loader();  // how the runtime finds GL functions
        options.toneMap = false;  // linear HDR out; a windowed app sets true (display values)
        auto refractor = shrefract::Refractor::create(bake, options);
        std::printf("using order %d: %d decompression pass(es), %.1f MB of GPU textures\n",
                    refractor->order(), refractor->passCount(),
                    refractor->memory().total() / 1e6);

        // No window, so no default framebuffer: draw into an offscreen one. A windowed app
        // draws into its window's framebuffer (or any FBO it has bound) instead.
        shrefract::OffscreenTarget target(width, height);

        // 4. The frame loop. The object sits at the origin; the camera circles it.
        const glm::mat4 model(1.0f);  // object -> world (any rigid transform)
        const glm::mat4 projection =
            glm::perspective(glm::radians(45.0f), float(width) / height, 0.01f, 100.0f);
        const int frames = 4;
        for (int f = 0; f < frames; ++f) {
            float angle = glm::radians(30.0f + 10.0f * f);
            glm::vec3 eye(3.0f * std::sin(angle), 1.0f, 3.0f * std::cos(angle));
            glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f), glm::vec3(0, 1, 0));

            // update(): per-viewpoint work in texture space (paper Figure 9): local view
            // directions, SH decompression into D_mu, optional smoothing, unpack into the
            // refraction map rho. It restores the app's framebuffer and viewport.
            // The frame's camera and the object's placement, given once.
            refractor->update({view, projection, model});

            // draw(): shades the object into the bound framebuffer with depth testing, looking
            // up the environment through rho (plus Fresnel reflection and absorption). The
            // background is the app's business; here the same environment, drawn first.
            target.bind();
            environment.drawBackground(view, projection, options.toneMap, options.exposure);
            refractor->draw(environment);

            // Timings are GPU times of the last update()/draw() (GL timer queries, each stage
            // finished inside its query). Turn RefractorOptions::timings off for throughput.
            // Frame 0 is a warm-up: llvmpipe compiles shaders at first draw.
            const shrefract::Timings& t = refractor->timings();
            if (f == 0) continue;
            std::printf("frame %d: view %.2f  decompress %.2f (%d pass)  smooth %.2f  unpack %.2f"
                        "  shade %.2f ms\n",
                        f, t.view, t.decompress, t.passes, t.smooth, t.unpack, t.shade);
        }

        // 5. Read the last frame back (linear HDR) and save it; writePng applies the tone map.
        shrefract::RenderedFrame frame = target.read();
        shrefract::writePng(argv[3], frame, options.exposure);
        size_t covered = 0;  // direction buffer alpha = 1 where the glass was drawn
        for (size_t i = 3; i < frame.directions.size(); i += 4) covered += frame.directions[i] > 0;
        std::printf("wrote %s: glass covers %.1f%% of the image\n", argv[3],
                    100.0 * covered / (width * height));
        return covered > 0 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
