// Uniform subdivision of a mesh file with OpenMesh's subdividers: how the Lucy-class test mesh is
// made from bunny00 (scripts/bench-lucy), without committing a large mesh.
#pragma once

#include <cstddef>
#include <string>

#include "shrefract/enum_names.h"

namespace shrefract {

enum class Subdivision {
    Loop,   // Loop 1987: 4 triangles per triangle, a vertex per edge
    Sqrt3,  // Kobbelt 2000: 3 triangles per triangle, a vertex per face
};
template <> struct EnumNames<Subdivision> {
    static constexpr const char* what = "subdivision";
    static constexpr NamedValue<Subdivision> table[] = {{Subdivision::Loop, "loop"},
                                                        {Subdivision::Sqrt3, "sqrt3"}};
};

struct SubdivisionResult {
    size_t vertices = 0, triangles = 0;
};

// Reads `input` (checked as every mesh the bake reads), subdivides it `steps` times and writes
// the result to `output` (format by extension; positions and triangles only, so readers derive
// the normals of the smooth surface). Written through writeFile (common/output.h): staged and
// renamed, so a failure leaves an existing `output` as it was. Throws InputError naming the file
// (IoError where the OS refuses the write).
SubdivisionResult subdivideMeshFile(const std::string& input, const std::string& output,
                                    Subdivision scheme, int steps);

}  // namespace shrefract
