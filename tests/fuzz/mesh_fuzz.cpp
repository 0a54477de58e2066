// Fuzz target: the mesh front end (loadMesh: our checks, then OpenMesh) for OFF, OBJ, PLY and STL.
// The input's first byte picks the extension, the rest is the file.
#include <cstddef>
#include <cstdint>

#include "common/error.h"
#include "common/mesh.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* const kNames[4] = {"input.off", "input.obj", "input.ply", "input.stl"};
    const std::string path = shrefract::fuzz::writeInput(kNames[data[0] % 4], data + 1, size - 1);
    try {
        shrefract::MeshReport report;
        shrefract::loadMesh(path, &report);
    } catch (const shrefract::InputError&) {
    }
    return 0;
}
