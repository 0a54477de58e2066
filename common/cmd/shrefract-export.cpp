// shrefract-export: a bake (and environments) as a glTF 2.0 binary file for the web material
// (web/) and any glTF viewer. A thin shell over common/gltf/gltf_export.h; the format is
// docs/format.md "glTF export: SHREFRACT_sh_refraction".
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "common/bakefile.h"
#include "common/cli/cli.h"
#include "common/error.h"
#include "common/gltf/gltf_export.h"
#include "common/latlong.h"
#include "common/output.h"

using namespace shrefract;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
    CLI::App app{"shrefract-export: a bake as a glTF 2.0 binary (GLB) with the weights (SH or grid) in the "
                 "SHREFRACT_sh_refraction extension, optionally with prefiltered environments"};
    std::string bakePath, output, name, into;
    std::vector<std::string> environments;
    int faceSize = 0;
    bool noVerify = false;
    app.add_option("bake", bakePath, "NAME.shrefract.exr (a joining layout); omit it to write environments only");
    app.add_option("-o,--output", output, "the GLB to write")->required();
    app.add_option("--environment", environments,
                   "lat-long EXR environment(s) to add, prefiltered as the runtime does (repeatable)");
    app.add_option("--face-size", faceSize, "environment cube face size (default: the image height / 2, as the runtime)")
        ->check(CLI::Range(0, 4096));
    app.add_option("--into", into,
                   "the glTF scene (.gltf or .glb) the bake was made from: write it back as one GLB "
                   "whose glass primitives carry the bake, everything else as it was");
    app.add_option("--name", name, "the refraction's and the mesh's name (default: from the bake's file name)");
    app.add_flag("--no-verify", noVerify, "skip the bake's checksums");
    int maxTexture = kMaxGltfTexture;
    app.add_option("--max-texture", maxTexture,
                   "the weight pages' largest side in texels: 4096 (phones), down to 2048 for "
                   "any WebGL 2 (more, smaller pages)")
        ->capture_default_str()->check(CLI::Range(16, 16384));
    return cli::run(app, "shrefract-export", argc, argv, [&] {
        if (bakePath.empty() && environments.empty())
            throw std::invalid_argument("nothing to export: give a bake, --environment, or both");
        if (!into.empty() && bakePath.empty()) throw std::invalid_argument("--into needs the bake to write into it");
        if (!into.empty() && fs::exists(into) && fs::exists(output) && fs::equivalent(into, output))
            throw inputError(output, "is the --into scene: the output would overwrite its input");
        OutputSet outputs;  // checked and staged before the work (common/output.h)
        const std::string staged = outputs.add(output);
        GltfExport what;
        what.maxTexture = maxTexture;
        BakeData bake;
        if (!bakePath.empty()) {
            ReadOptions options;
            options.verify = !noVerify;
            bake = readBake(bakePath, options);
            what.bake = &bake;
            what.name = name;
            if (what.name.empty()) {
                what.name = fs::path(bakePath).filename().string();
                const auto dot = what.name.find('.');
                if (dot != std::string::npos && dot > 0) what.name.resize(dot);
            }
        }
        for (const std::string& path : environments) {
            GltfEnvironment e;
            e.name = fs::path(path).stem().string();
            e.base = cubeFromLatLong(loadLatLong(path), faceSize);
            what.environments.push_back(std::move(e));
        }
        std::vector<uint8_t> glb;
        if (!into.empty()) {
            glb = exportInto(bake, into, what.environments, maxTexture);  // its errors name the scene
        } else {
            try {
                glb = exportGlb(what);
            } catch (const InputError& e) {
                throw inputError(bakePath, e.what());
            }
        }
        writeFile(staged, std::string(glb.begin(), glb.end()));
        outputs.commit();
        std::printf("wrote %s: %.2f MB", output.c_str(), glb.size() / 1e6);
        if (what.bake && bake.basis == Basis::Grid)
            std::printf(", %d samples, grid basis %s", bake.layout.sampleCount(), bake.grid.ToString().c_str());
        else if (what.bake)
            std::printf(", %d samples at order %d", bake.layout.sampleCount(), bake.order);
        if (!environments.empty()) std::printf(", %zu environment(s)", environments.size());
        if (!into.empty()) std::printf(", into the scene of %s", into.c_str());
        std::printf("\n");
        return int(cli::kOk);
    });
}
