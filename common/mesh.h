// Triangle meshes from OBJ, OFF, PLY and STL files (OpenMesh), validated.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;     // per vertex, unit length, outward
    std::vector<glm::uvec3> triangles;  // counter-clockwise seen from outside
    // Texture coordinates per triangle corner (uvs[3 t + k] for corner k of triangle t), from the
    // file (OBJ `vt`, PLY vertex `u v` or `s t`); empty when the file has none.
    std::vector<glm::vec2> uvs;
    bool normalsFromFile = false;

    glm::vec3 boundsMin() const;
    glm::vec3 boundsMax() const;
    // A stable FNV-1a checksum of positions and triangles (hex), for the manifest.
    std::string checksum() const;
};

// What loading found that is worth telling the user; none of it stops the load.
struct MeshReport {
    size_t degenerateTriangles = 0;  // zero-area triangles, skipped
    size_t borderEdges = 0;          // open mesh: paths may leak
    size_t nonManifoldEdges = 0;     // edges shared by more than two triangles
    std::vector<std::string> warnings;  // one line each, already naming the file
};

// Loads and validates. Polygons are triangulated; vertex normals come from the file when it has
// them, else are area-weighted face normals. Throws InputError naming the file on: not found,
// unsupported extension, unparsable, cut short (fewer vertices or faces than its header
// promises: common/mesh_counts.h), empty (no triangles left), NaN/inf coordinates.
Mesh loadMesh(const std::string& path, MeshReport* report = nullptr);

// A mesh as a reader found it, before validation: what loadMesh takes from OpenMesh, and what
// the glTF reader (common/gltf_scene.h) takes from a primitive's accessors.
struct MeshArrays {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;  // indices into positions (the reader checks the range)
    std::vector<glm::vec3> normals;     // per vertex, from the file; empty: computed
    std::vector<glm::vec2> uvs;         // per triangle corner; empty: none
    std::vector<bool> reconnected;      // per triangle: OpenMesh split it off; empty: none were
    size_t droppedDegenerate = 0;       // faces the reader dropped for a repeated vertex
};

// The second half of loadMesh, for any reader: NaN/inf positions refused, degenerate triangles
// skipped, topology reported, inward winding flipped, normals taken (flipped when they oppose the
// winding) or computed, area-weighted. Same arrays, same Mesh, bit for bit, whichever file they
// came from. Messages and warnings name `path`.
Mesh finishMesh(const std::string& path, const MeshArrays& arrays, MeshReport* report = nullptr);

}  // namespace shrefract
