// Fuzz target: the scene JSON (loadScene on a .json file). The scratch folder holds small meshes
// under every name the project's scenes use (data/scenes), so seeds from those scenes load.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "common/error.h"
#include "common/scene.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    namespace fs = std::filesystem;
    const fs::path scenes = fs::path(SHREFRACT_DATA_DIR) / "scenes";
    const fs::path cube = scenes / "cube.off";
    for (const auto& e : fs::directory_iterator(scenes)) {
        if (e.path().extension() != ".off") continue;
        // The larger meshes stand in as the cube: the target is the scene file, not OpenMesh.
        const fs::path from = fs::file_size(e.path()) < 4096 ? e.path() : cube;
        fs::copy_file(from, shrefract::fuzz::scratchFolder() / e.path().filename(),
                      fs::copy_options::overwrite_existing);
    }
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = shrefract::fuzz::writeInput("scene.json", data, size);
    try {
        shrefract::loadScene(path);
    } catch (const shrefract::InputError&) {
    }
    return 0;
}
