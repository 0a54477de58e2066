// The one way shrefract opens a glTF file through tinygltf, shared by the scene reader
// (common/gltf_scene.cpp) and the round trip of the export (common/gltf/gltf_export.cpp), so the
// export reads the scene once and with the same checks. Includes tinygltf: for those two only.
#pragma once

#include <tiny_gltf.h>

#include <string>
#include <vector>

#include "common/gltf_scene.h"

namespace shrefract {

// Reads `path` (.gltf with its files, .glb) into `model`: buffers from regular files only (a FIFO
// or device named by a URI is refused, not read), images never decoded: with keepImages their
// encoded bytes stay in Image::image, otherwise they are dropped. Throws InputError naming the file.
void readGltfModel(const std::string& path, tinygltf::Model& model, bool keepImages);

// The glass scene of a model readGltfModel read (loadGltfScene is both in one).
Scene gltfSceneOf(const std::string& path, const tinygltf::Model& model,
                  std::vector<GltfPlace>* places = nullptr);

}  // namespace shrefract
