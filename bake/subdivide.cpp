#include "bake/subdivide.h"

#include <filesystem>
#include <sstream>

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
#include "common/output.h"

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

    // OpenMesh picks the format by the target's extension; the bytes then go through the one
    // staged write every output uses (common/output.h): fsynced, renamed, a link never replaced.
    // 9 significant digits: every float position written exactly (text formats).
    std::ostringstream bytes;
    const std::string ext = std::filesystem::path(output).extension().string();
    if (ext.empty() ||
        !OpenMesh::IO::write_mesh(om, bytes, ext, OpenMesh::IO::Options::Default, 9))
        throw inputError(output, "cannot write a mesh with this extension (use .obj, .off, .ply or .stl)");
    writeFile(output, bytes.str());
    return {om.n_vertices(), om.n_faces()};
}

}  // namespace shrefract
