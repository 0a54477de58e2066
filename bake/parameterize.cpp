// The one translation unit that includes CGAL (bake/parameterize.h). GPL-3.0-or-later code: the
// bake only.
#include "bake/parameterize.h"

#include <algorithm>
#include <map>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/Seam_mesh.h>
#include <CGAL/Surface_mesh_parameterization/ARAP_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

namespace shrefract {


namespace {

namespace SMP = CGAL::Surface_mesh_parameterization;
using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using SmVertex = SurfaceMesh::Vertex_index;
using SmHalfedge = SurfaceMesh::Halfedge_index;
using SmEdge = SurfaceMesh::Edge_index;
using SmFace = SurfaceMesh::Face_index;
using SeamEdgeMap = SurfaceMesh::Property_map<SmEdge, bool>;
using SeamVertexMap = SurfaceMesh::Property_map<SmVertex, bool>;
using SeamMesh = CGAL::Seam_mesh<SurfaceMesh, SeamEdgeMap, SeamVertexMap>;
using UvMap = SurfaceMesh::Property_map<SmHalfedge, Kernel::Point_2>;

// A Surface_mesh of the triangles `faces` of `mesh`, with each face's original triangle and each
// vertex's original vertex; false when CGAL refuses a face (a non-manifold configuration).
struct Built {
    std::vector<size_t> triangleOfFace;
    std::vector<uint32_t> vertexOf;
};
bool buildSurfaceMesh(const ChartedMesh& mesh, const std::vector<size_t>& faces, SurfaceMesh& sm,
                      Built& built) {
    std::map<uint32_t, SmVertex> vertex;
    auto vertexOf = [&](uint32_t v) {
        auto it = vertex.find(v);
        if (it != vertex.end()) return it->second;
        const glm::dvec3 p = mesh.positions[v];
        const SmVertex added = sm.add_vertex(Kernel::Point_3(p.x, p.y, p.z));
        if (built.vertexOf.size() <= size_t(added)) built.vertexOf.resize(size_t(added) + 1);
        built.vertexOf[size_t(added)] = v;
        return vertex.emplace(v, added).first->second;
    };
    std::vector<size_t>& triangleOfFace = built.triangleOfFace;
    for (size_t t : faces) {
        const glm::uvec3 tri = mesh.triangles[t];
        const SmFace f = sm.add_face(vertexOf(tri[0]), vertexOf(tri[1]), vertexOf(tri[2]));
        if (f == SurfaceMesh::null_face()) return false;
        if (triangleOfFace.size() <= size_t(f)) triangleOfFace.resize(size_t(f) + 1);
        triangleOfFace[size_t(f)] = t;
    }
    return true;
}

// Parameterizes the chart of seam-mesh border halfedge `bhd` into `uv`.
SMP::Error_code parameterizeComponent(SeamMesh& mesh, SeamMesh::halfedge_descriptor bhd, UvMap uv,
                                      ChartMethod method) {
    if (method == ChartMethod::Lscm) return SMP::parameterize(mesh, SMP::LSCM_parameterizer_3<SeamMesh>(), bhd, uv);
    return SMP::parameterize(mesh, SMP::ARAP_parameterizer_3<SeamMesh>(), bhd, uv);
}

// Cuts `sm` along the edges between charts (a CGAL::Seam_mesh), parameterizes each chart of
// `charts` from one of its border halfedges and writes the corner UVs of its faces.
void parameterizeOnSeamMesh(const ChartedMesh& mesh, SurfaceMesh& sm, const Built& built,
                            const std::vector<int>& charts, ChartMethod method, ChartUVs& out) {
    const std::vector<size_t>& triangleOfFace = built.triangleOfFace;
    SeamEdgeMap seamEdges = sm.add_property_map<SmEdge, bool>("e:seam", false).first;
    SeamVertexMap seamVertices = sm.add_property_map<SmVertex, bool>("v:seam", false).first;
    UvMap uv = sm.add_property_map<SmHalfedge, Kernel::Point_2>("h:uv").first;
    SeamMesh seam(sm, seamEdges, seamVertices);
    auto chartOfFace = [&](SmFace f) { return mesh.chartOf[triangleOfFace[size_t(f)]]; };
    for (SmEdge e : sm.edges()) {
        const SmHalfedge h = sm.halfedge(e);
        if (sm.is_border(e)) continue;
        if (chartOfFace(sm.face(h)) != chartOfFace(sm.face(sm.opposite(h))))
            seam.add_seam(sm.source(h), sm.target(h));
    }
    // One border halfedge of the cut mesh per chart: the outside of a chart edge on a seam or on
    // the mesh's own border.
    std::map<int, SeamMesh::halfedge_descriptor> border;
    for (SmHalfedge h : sm.halfedges()) {
        if (sm.is_border(h)) continue;
        const int c = chartOfFace(sm.face(h));
        if (border.count(c)) continue;
        const SmHalfedge o = sm.opposite(h);
        if (sm.is_border(o) || chartOfFace(sm.face(o)) != c)
            border[c] = opposite(SeamMesh::halfedge_descriptor(h), seam);
    }
    for (size_t k = 0; k < charts.size(); ++k) {
        auto it = border.find(charts[k]);
        if (it == border.end()) {
            out.message[k] = "the chart has no border (a closed surface is not a disk)";
            continue;
        }
        const SMP::Error_code err = parameterizeComponent(seam, it->second, uv, method);
        out.ok[k] = err == SMP::OK;
        if (!out.ok[k]) out.message[k] = SMP::get_error_message(err);
    }
    for (SmFace f : sm.faces()) {
        const size_t t = triangleOfFace[size_t(f)];
        // The face's corners in the cut mesh: the target of each of its halfedges, in the order
        // of the triangle's own corners.
        SmHalfedge h = sm.halfedge(f);
        for (int step = 0; step < 3; ++step, h = sm.next(h)) {
            const SeamMesh::vertex_descriptor v = target(SeamMesh::halfedge_descriptor(h), seam);
            const Kernel::Point_2 p = get(uv, v);
            const uint32_t original = built.vertexOf[size_t(sm.target(h))];
            for (int c = 0; c < 3; ++c)
                if (mesh.triangles[t][c] == original) out.cornerUV[3 * t + c] = glm::dvec2(p.x(), p.y());
        }
    }
}

}  // namespace

ChartUVs parameterizeCharts(const ChartedMesh& mesh, const std::vector<int>& charts,
                            ChartMethod method) {
    ChartUVs out;
    out.ok.assign(charts.size(), false);
    out.message.assign(charts.size(), "");
    out.cornerUV.assign(mesh.triangles.size() * 3, glm::dvec2(0.0));
    int maxChart = 0;
    for (int c : mesh.chartOf) maxChart = std::max(maxChart, c);
    std::vector<char> asked(size_t(maxChart) + 1, 0);
    for (int c : charts)
        if (c >= 0 && c <= maxChart) asked[size_t(c)] = 1;
    std::vector<size_t> all;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (mesh.chartOf[t] >= 0 && asked[size_t(mesh.chartOf[t])]) all.push_back(t);
    // All asked-for charts on one Seam_mesh of their triangles ...
    {
        SurfaceMesh sm;
        Built built;
        if (buildSurfaceMesh(mesh, all, sm, built)) {
            out.seamMesh = true;
            parameterizeOnSeamMesh(mesh, sm, built, charts, method, out);
            return out;
        }
    }
    // ... or, where CGAL cannot hold them as one manifold surface, each chart as its own mesh
    // (a disk, so manifold), cut by no seam.
    std::map<int, std::vector<size_t>> facesOf;
    for (size_t t : all) facesOf[mesh.chartOf[t]].push_back(t);
    for (size_t k = 0; k < charts.size(); ++k) {
        const std::vector<size_t>& faces = facesOf[charts[k]];
        SurfaceMesh sm;
        Built built;
        if (!buildSurfaceMesh(mesh, faces, sm, built)) {
            out.message[k] = "CGAL cannot build the chart as a manifold surface";
            continue;
        }
        ChartUVs one;
        one.ok.assign(1, false);
        one.message.assign(1, "");
        one.cornerUV.swap(out.cornerUV);
        parameterizeOnSeamMesh(mesh, sm, built, {charts[k]}, method, one);
        one.cornerUV.swap(out.cornerUV);
        out.ok[k] = one.ok[0];
        out.message[k] = one.message[0];
    }
    return out;
}

}  // namespace shrefract
