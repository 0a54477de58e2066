// Links the installed shrefract::runtime: headless EGL context, a bake from the command line,
// one frame, and the centre pixel must show the glass. Exit 0 on success.
#include <cstdio>
#include <exception>

#include <glm/gtc/matrix_transform.hpp>
#include <shrefract/context.h>
#include <shrefract/render.h>
#include <shrefract/runtime.h>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: consumer BAKE.shrefract.exr\n");
        return 2;
    }
    try {
        auto context = shrefract::createHeadlessContext(shrefract::Backend::Egl);
        shrefract::Bake bake = shrefract::loadBake(argv[1]);
        // A constant grey environment: the test needs no EXR beside the bake.
        shrefract::Environment env =
            shrefract::Environment::fromLatLong(2, 1, std::vector<float>(6, 0.5f));
        shrefract::RefractorOptions options;
        options.loader = context->loader();
        auto refractor = shrefract::Refractor::create(bake, options);

        const int size = 64;
        shrefract::OffscreenTarget target(size, size);
        glm::vec3 eye(0.0f, 0.0f, 3.0f);
        glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f), glm::vec3(0, 1, 0));
        glm::mat4 projection = glm::perspective(glm::radians(45.0f), 1.0f, 0.01f, 100.0f);
        refractor->update(eye);
        target.bind();
        refractor->draw(view, projection, glm::mat4(1.0f), env);
        shrefract::RenderedFrame frame = target.read();

        const size_t centre = (static_cast<size_t>(size / 2) * size + size / 2) * 4;
        const float coverage = frame.directions[centre + 3];
        std::printf("consumer: %s, centre coverage %.1f, colour %.3f %.3f %.3f\n",
                    context->description().c_str(), coverage, frame.color[centre],
                    frame.color[centre + 1], frame.color[centre + 2]);
        return coverage == 1.0f ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
}
