// Fuzz target: the glTF front end (loadScene on a .gltf or .glb: tinygltf, then
// common/gltf_scene.cpp's checks, transforms, media and priorities). The input's first byte picks
// the extension (even: .gltf, odd: .glb), the rest is the file. The scratch folder holds the
// small external buffers of data/scenes under their own names, so .gltf seeds that name them load.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "common/error.h"
#include "common/scene.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    namespace fs = std::filesystem;
    for (const auto& e : fs::directory_iterator(fs::path(SHREFRACT_DATA_DIR) / "scenes")) {
        if (e.path().extension() == ".bin" && fs::file_size(e.path()) < 16384)
            fs::copy_file(e.path(), shrefract::fuzz::scratchFolder() / e.path().filename(),
                          fs::copy_options::overwrite_existing);
    }
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const std::string path =
        shrefract::fuzz::writeInput(data[0] % 2 ? "input.glb" : "input.gltf", data + 1, size - 1);
    try {
        shrefract::loadScene(path);
    } catch (const shrefract::InputError&) {
    }
    return 0;
}
