// Fuzz target: the environment loader (loadLatLong on an EXR), then the cube map the runtime
// would build from what it accepted, and a few lookups.
#include <cstddef>
#include <cstdint>

#include "common/error.h"
#include "common/latlong.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace shrefract;
    const std::string path = fuzz::writeInput("input.exr", data, size);
    LatLongImage image;
    try {
        image = loadLatLong(path);
    } catch (const InputError&) {
        return 0;
    }
    const CubeMapImage cube = cubeFromLatLong(image, 4);
    for (glm::vec3 d : {glm::vec3(0, 1, 0), glm::vec3(0.6f, -0.8f, 0), glm::vec3(0, 0, -1)}) {
        (void)sampleLatLong(image, d);
        (void)sampleCube(cube, d);
    }
    return 0;
}
