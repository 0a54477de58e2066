// Links the installed shrefract::runtime and uses every public entry point an app has: a
// headless context, a bake (and the InputError a missing one throws), a Refractor with typed
// options, the per-frame calls, the setters, the refraction map, the baselines, the frame helpers
// and the enum names. The centre pixel must show the glass. Exit 0 on success.
#include <cstdio>
#include <exception>

#include <glm/gtc/matrix_transform.hpp>
#include <shrefract/baselines.h>
#include <shrefract/context.h>
#include <shrefract/error.h>
#include <shrefract/render.h>
#include <shrefract/runtime.h>

namespace {

int failures = 0;

void expect(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "consumer: failed: %s\n", what);
        ++failures;
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: consumer BAKE.shrefract.exr\n");
        return 2;
    }
    using namespace shrefract;
    try {
        auto context = createHeadlessContext(parseName<Backend>("egl"));
        // The documented error type, caught by type: a missing bake names the file.
        bool caught = false;
        try {
            loadBake("missing.shrefract.exr");
        } catch (const InputError& e) {
            caught = std::string(e.what()).find("missing.shrefract.exr") != std::string::npos;
        }
        expect(caught, "loadBake of a missing file throws InputError naming it");

        Bake bake = loadBake(argv[1]);
        expect(!bake.refractionMapMesh().empty() && bake.order() >= 0 && bake.sampleCount() > 0 &&
                   bake.triangleCount() > 0 && !bake.layout().empty() && bake.ior() > 1.0f &&
                   bake.absorption() == glm::vec3(0.0f) && bake.warnings().empty(),
               "the bake's accessors");
        // A constant grey environment: the test needs no EXR beside the bake.
        Environment env = Environment::fromLatLong(2, 1, std::vector<float>(6, 0.5f));
        expect(env.cubeMap() != 0 && env.faceSize() > 0 && env.levels() >= 1, "the environment");

        RefractorOptions options;
        options.loader = context->loader();
        options.preset = ShaderPreset::Modern;
        options.path = parseName<RefractorPath>("rho");
        options.shading = Shading::Sharp;
        options.absorption = glm::vec3(0.1f);
        auto refractor = Refractor::create(bake, options);
        expect(refractor->path() == RefractorPath::Rho && nameOf(refractor->path()) == std::string("rho"),
               "the path asked for, by name");
        expect(refractor->decompression() == DecompressionSite::Texture, "texture decompression on rho");
        refractor->setOrder(-1);
        refractor->setSmoothing(false);
        refractor->setCorrection(true);
        refractor->setTimings(true);
        expect(refractor->timingsEnabled(), "stage timers on when asked for");

        const int size = 64;
        OffscreenTarget target(size, size);
        glm::vec3 eye(0.0f, 0.0f, 3.0f);
        glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f), glm::vec3(0, 1, 0));
        glm::mat4 projection = glm::perspective(glm::radians(45.0f), 1.0f, 0.01f, 100.0f);
        refractor->update({view, projection, glm::mat4(1.0f)});
        target.bind();
        refractor->draw(env);
        RenderedFrame frame = target.read();
        expect(refractor->timings().shade > 0.0 && refractor->passCount() >= 1 &&
                   refractor->memory().total() > 0,
               "stage times, passes and memory");
        expect(refractor->refractionMap() != 0 && refractor->refractionMapSize().x > 0 &&
                   !refractor->readRefractionMap().empty() && !refractor->readDirectionalMap().empty(),
               "the refraction map and D read back");

        const size_t centre = (static_cast<size_t>(size / 2) * size + size / 2) * 4;
        const float coverage = frame.directions[centre + 3];
        std::printf("consumer: %s, centre coverage %.1f, colour %.3f %.3f %.3f\n",
                    context->description().c_str(), coverage, frame.color[centre],
                    frame.color[centre + 1], frame.color[centre + 2]);
        expect(coverage == 1.0f, "the glass covers the centre pixel");

        // The frame helpers and a baseline.
        const Camera camera = Camera::orbit(30, 20, 3);
        expect(renderFrame(*refractor, env, camera, 32, 32).color.size() == 32 * 32 * 4, "renderFrame");
        expect(frameWallMs(*refractor, env, camera, 32, 32, 1) > 0.0, "frameWallMs");
        expect(refractor->timingsEnabled(), "frameWallMs leaves the timers as they were");
        BaselineOptions single;
        single.method = BaselineMethod::Single;
        single.loader = context->loader();
        auto baseline = Baseline::create(bake, {}, single);
        expect(renderFrame(*baseline, env, camera, 32, 32).color.size() == 32 * 32 * 4, "a baseline");
        expect(toneMap(glm::vec3(0.0f)) == glm::vec3(0.0f), "toneMap");
        bool refused = false;
        try {
            parseName<Shading>("frosted");
        } catch (const std::invalid_argument&) {
            refused = true;
        }
        expect(refused, "an unknown name is refused");
        return failures == 0 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
}
