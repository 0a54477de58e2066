// Chart parameterization through CGAL's Surface_mesh_parameterization (paper §5.2), behind plain
// types: this header and bake/parameterize.cpp are the only places that see CGAL, so its slow
// headers compile in one translation unit. CGAL's package is GPL-3.0-or-later: it stays in the
// bake (README "Licence"); the runtime never links it.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shrefract/enum_names.h"

namespace shrefract {

enum class ChartMethod { Lscm, Arap };
template <> struct EnumNames<ChartMethod> {
    static constexpr const char* what = "chart method";
    static constexpr NamedValue<ChartMethod> table[] = {{ChartMethod::Lscm, "lscm"},
                                                        {ChartMethod::Arap, "arap"}};
};

// One closed or open triangle mesh with vertices welded by position, and the chart of every
// triangle. Every chart must be a topological disk (bake/chart_unfold.cpp checks that first).
struct ChartedMesh {
    std::vector<glm::dvec3> positions;
    std::vector<glm::uvec3> triangles;  // counter-clockwise seen from outside
    std::vector<int> chartOf;           // per triangle
};

struct ChartUVs {
    // Per chart asked for: whether CGAL reported success, and its message otherwise.
    std::vector<bool> ok;
    std::vector<std::string> message;
    // Per triangle corner (3 t + k), for the triangles of the charts asked for; (0, 0) elsewhere.
    std::vector<glm::dvec2> cornerUV;
    bool seamMesh = false;  // cut on one CGAL::Seam_mesh (else: per-chart meshes, see .cpp)
};

// Parameterizes the charts `charts` of `mesh` with `method`, each on its own, free border (LSCM:
// CGAL's two-vertex border; ARAP: CGAL's default initialization). The cut is a CGAL::Seam_mesh
// whose seam edges are the edges between two charts; a mesh CGAL cannot hold as one
// Surface_mesh (non-manifold) is parameterized chart by chart instead.
ChartUVs parameterizeCharts(const ChartedMesh& mesh, const std::vector<int>& charts,
                            ChartMethod method);

}  // namespace shrefract
