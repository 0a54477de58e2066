// A scene: one or more glass parts, each a mesh and a medium. Either a bare mesh file (one part,
// IOR from the caller) or a JSON scene file; format in docs/bake.md.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/mesh.h"

namespace shrefract {

// A dielectric medium. Nested dielectrics: where parts overlap, the higher priority wins.
struct Medium {
    std::string name = "glass";
    double ior = 1.5;
    glm::dvec3 absorption{0.0};  // kappa per RGB channel, per object-space unit
    int priority = 0;
};

struct Part {
    std::string name;
    std::string meshPath;
    Mesh mesh;
    Medium medium;
    MeshReport report;
};

struct Scene {
    std::string path;  // the file given
    std::vector<Part> parts;
    // What the loader left out or could not decide, one line each, already naming the file (glTF:
    // primitives that are not glass, overlapping media of equal priority); tools print them.
    std::vector<std::string> notes;
};

// What is wrong with a medium, or "" when it is fine: ior in [limits::kMinIor, kMaxIor], each
// absorption finite and >= 0. The one check for the bake's --ior, scene files and the media in a
// bake file's manifest.
std::string mediumProblem(const Medium& m);

// Loads `path`: a .json scene, a glTF file (.gltf, .glb: common/gltf_scene.h, which gives every
// part its medium, so `defaultMedium` is not used), or a mesh file as one part with medium
// `defaultMedium`.
// Throws InputError naming the file on any problem (including every mesh's own errors and
// absurd media: ior not in [1, 5], negative or non-finite absorption).
Scene loadScene(const std::string& path, const Medium& defaultMedium = Medium());

}  // namespace shrefract
