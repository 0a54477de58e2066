// Mesh files cut short: every count a file's header promises is checked against what the file
// holds, before OpenMesh reads it (OpenMesh takes a truncated OFF, PLY or ASCII STL as the part
// it got, without a word). Used by loadMesh (common/mesh.h).
#pragma once

#include <string>

namespace shrefract {

// Throws InputError naming the file when it holds less (or, for a binary STL, other) than its
// header promises:
//   OFF   text: exactly "nv nf ne" on the counts line, nv vertex lines of 3+ numbers, then nf face
//         lines "k i1 .. ik" (k >= 3) and nothing more (no face colour);
//         binary: the bytes of nv vertices and nf faces;
//   PLY   every element's count of lines, each with exactly the values its properties imply
//         (ascii), or of records (binary, lists walked);
//   STL   binary: exactly 84 + 50 n bytes for its n triangles; ASCII: 3 vertices per facet,
//         every facet closed, "endsolid" at the end;
//   OBJ   (no header) every "v" line is 3 numbers (or 4, or with 3 colour values), "vt" 1 to 3,
//         "vn" 3, and every "f" line 3 or more corners v, v/t, v//n or v/t/n whose indices name a
//         vertex, texture coordinate and normal of the file (negative: one before the line).
// `ext` is the lower-case extension with its dot. Files it cannot classify are left to OpenMesh.
void checkMeshCounts(const std::string& path, const std::string& ext);

}  // namespace shrefract
