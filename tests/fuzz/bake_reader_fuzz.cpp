// Fuzz target: the bake-file reader (readBake), verified and unverified, then a walk over what it
// accepted as the runtime would walk it: every triangle's grid samples, the CPU decompressor, the
// rho interpolation. Seeds: small real bakes (tests/fuzz/make-seeds).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/bakefile.h"
#include "common/decompress.h"
#include "common/error.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace shrefract;
    const std::string path = fuzz::writeInput("input.shrefract.exr", data, size);
    ReadOptions options;
    options.verify = size % 4 == 0;  // mostly unverified: the checksums would stop most mutations
    BakeData d;
    try {
        d = readBake(path, options);
    } catch (const InputError&) {
        return 0;
    }
    const SurfaceLayout& L = d.layout;
    std::vector<glm::vec4> values(L.position.size(), glm::vec4(0.0f));
    for (int i = 0; i < L.sampleCount() && i < 64; ++i)
        values[i] = decompressSample(d, i, localViewDirection(L, i, glm::vec3(0.3f, 0.4f, 0.866f)));
    for (int t = 0; t < L.triangleCount && t < 64; ++t) {
        for (int j = 0; j <= L.rate; ++j)
            for (int i = 0; i + j <= L.rate; ++i) (void)L.sampleAt(t, i, j);
        (void)interpolateRho(L, values.data(), t, 0.25f, 0.5f);
    }
    return 0;
}
