#include "bake/subdivide.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

// GCC 12's false "may be used uninitialized" inside OpenMesh's VectorT (as in common/mesh.cpp).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh>

#include "common/error.h"
#include "common/mesh.h"

namespace shrefract {

using OMesh = OpenMesh::TriMesh_ArrayKernelT<>;

SubdivisionResult subdivideMeshFile(const std::string& input, const std::string& output,
                                    Subdivision scheme, int steps) {
    if (steps < 0 || steps > 6) throw inputError(output, "subdivision steps must be 0..6");
    const Mesh mesh = loadMesh(input);
    OMesh om;
    std::vector<OMesh::VertexHandle> v;
    v.reserve(mesh.positions.size());
    for (const glm::vec3& p : mesh.positions) v.push_back(om.add_vertex(OMesh::Point(p.x, p.y, p.z)));
    for (const glm::uvec3& t : mesh.triangles)
        if (!om.add_face(v[t.x], v[t.y], v[t.z]).is_valid())
            throw inputError(input, "a triangle OpenMesh cannot connect (non-manifold): cannot subdivide");
    bool ok = true;
    if (scheme == Subdivision::Loop) {
        OpenMesh::Subdivider::Uniform::LoopT<OMesh> loop;
        ok = loop.attach(om) && loop(size_t(steps));
        loop.detach();
    } else {
        OpenMesh::Subdivider::Uniform::Sqrt3T<OMesh> sqrt3;
        ok = sqrt3.attach(om) && sqrt3(size_t(steps));
        sqrt3.detach();
    }
    if (!ok) throw inputError(input, "OpenMesh's subdivider failed");

    // OpenMesh picks the format by extension: the temporary keeps it.
    const std::filesystem::path out(output);
    const std::string tmp = (out.parent_path() / (out.stem().string() + ".tmp." + std::to_string(::getpid()) +
                                                  out.extension().string())).string();
    // 9 significant digits: every float position written exactly (text formats).
    if (!OpenMesh::IO::write_mesh(om, tmp, OpenMesh::IO::Options::Default, 9)) {
        std::remove(tmp.c_str());
        throw inputError(output, "cannot write (unknown extension or unwritable folder)");
    }
    if (std::rename(tmp.c_str(), output.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw inputError(output, "cannot rename the temporary file to it");
    }
    return {om.n_vertices(), om.n_faces()};
}

}  // namespace shrefract
