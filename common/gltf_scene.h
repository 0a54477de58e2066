// glTF 2.0 input (.gltf with external or data-URI buffers, .glb) read as a scene of glass parts,
// through Debian's tinygltf. The mapping (docs/bake.md "glTF input"): every TRIANGLES primitive
// of the scene's nodes whose material has KHR_materials_transmission with transmissionFactor > 0
// is a part; KHR_materials_ior gives its IOR (1.5 when absent); KHR_materials_volume its
// absorption, κ = −ln(attenuationColor) / attenuationDistance per RGB channel, per unit of the
// scene's coordinates after node transforms (metres in glTF); nested media get their priority
// from containment of bounds or from extras.shrefract_priority. Everything else is left out with
// a note (Scene::notes): the bake models dielectrics only.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene.h"

namespace shrefract {

// The extras key (on a node or a material, the node's winning) that sets a part's priority.
inline constexpr const char* kGltfPriorityKey = "shrefract_priority";

// True for a path ending in .gltf or .glb (any case).
bool isGltfPath(const std::string& path);

// Loads a glTF file as a scene. Throws InputError naming the file and the problem: unreadable or
// malformed files, missing or truncated buffers, accessors outside their buffers or disagreeing
// in count, indices out of range, glass primitives that are not TRIANGLES, Draco or meshopt
// compression, absurd media, and files with no glass triangles in their scene.
// `places`, when given, gets where each part came from, in the parts' order (for writing a bake
// back into the file: common/gltf/gltf_export.h exportInto).
struct GltfPlace {
    int node = -1, mesh = -1, primitive = -1;
    glm::dmat4 world{1.0};  // the node's world matrix in the scene: part coordinates = world * file's
};
Scene loadGltfScene(const std::string& path, std::vector<GltfPlace>* places = nullptr);

}  // namespace shrefract
