// Is a bake consistent? inconsistency() checks a BakeData as a whole (layout, atlas, neighbours,
// weights) for the writer and the reader alike; manifestProblem() the manifest's descriptive keys
// as the bake checks its options.
#include <cmath>

#include "common/direction_grid.h"
#include "common/format_internal.h"
#include "common/limits.h"
#include "common/scene.h"

namespace shrefract::format_internal {

namespace {

// The chart atlas of an isolated or uv layout: rho is the atlas, every sample shown by exactly
// one Sample texel, which is its sampleTexel; the unfolded mesh and the seam sources in range.
std::string chartInconsistency(const SurfaceLayout& L) {
    const ChartAtlas& A = L.atlas;
    const size_t N = L.position.size(), texels = size_t(L.muWidth) * L.muHeight;
    if (L.rhoWidth != L.muWidth || L.rhoHeight != L.muHeight)
        return str("chart layout with rho ", L.rhoWidth, " x ", L.rhoHeight, " unlike its atlas ",
                   L.muWidth, " x ", L.muHeight);
    if (A.sampleTexel.size() != N)
        return str(A.sampleTexel.size(), " sample texels for ", N, " samples");
    std::vector<char> seen(N, 0);
    size_t shown = 0;
    for (size_t t = 0; t < L.rho.size() && t < texels; ++t) {
        const RhoTexel& r = L.rho[t];
        if (r.kind == RhoTexel::Empty) continue;
        if (r.kind != RhoTexel::Sample || r.a >= N || seen[r.a] || A.sampleTexel[r.a] != t)
            return str("atlas texel (", t % size_t(L.muWidth), ", ", t / size_t(L.muWidth),
                       ") is not one sample's own texel (kind ", r.kind, ", sample ", r.a, ")");
        seen[r.a] = 1;
        ++shown;
    }
    if (shown != N) return str("the atlas shows ", shown, " of ", N, " samples");
    const size_t V = A.vertexPosition.size();
    if (A.vertexNormal.size() != V || A.vertexUV.size() != V || A.vertexChart.size() != V)
        return str("chart vertex arrays differ in size: ", V, " positions, ", A.vertexNormal.size(),
                   " normals, ", A.vertexUV.size(), " uvs, ", A.vertexChart.size(), " charts");
    if (A.gutter < 0) return str("gutter ", A.gutter, " is negative");
    if (size_t(L.triangleCount) != A.triangles.size())
        return str("triangle count ", L.triangleCount, " but ", A.triangles.size(), " chart triangles");
    if (A.chartCount < 1) return str(A.chartCount, " charts");
    for (size_t v = 0; v < V; ++v) {
        const glm::vec2 uv = A.vertexUV[v];
        if (!(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f))
            return str("chart vertex ", v, " has uv (", uv.x, ", ", uv.y, ") outside [0, 1]");
        if (A.vertexChart[v] >= uint32_t(A.chartCount))
            return str("chart vertex ", v, " is in chart ", A.vertexChart[v], " of ", A.chartCount);
    }
    for (size_t t = 0; t < A.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (A.triangles[t][k] >= V)
                return str("chart triangle ", t, " refers to vertex ", A.triangles[t][k],
                           " but there are only ", V);
    for (size_t e = 0; e < A.seam.size(); ++e) {
        const SeamSource& s = A.seam[e];
        if (s.texel >= texels) return str("seam source ", e, " fills texel ", s.texel, " outside the atlas");
        for (int k = 0; k < 4; ++k)
            if (s.weight[k] != 0.0f && (s.sample[k] >= N || !std::isfinite(s.weight[k])))
                return str("seam source ", e, " takes sample ", s.sample[k], " with weight ",
                           s.weight[k], " (", N, " samples)");
    }
    return "";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Consistency of a BakeData, shared by writer (a caller bug: std::invalid_argument) and reader
// (a bad file: InputError). Returns what is wrong, or "" when consistent.
std::string inconsistency(const BakeData& d) {
    const SurfaceLayout& L = d.layout;
    if (d.order < 0 || d.order > limits::kMaxOrder)
        return str("SH order ", d.order, " is not in [0, ", limits::kMaxOrder, "]");
    if (const std::string problem = gridProblem(d.grid.nTheta, d.grid.nPhi); !problem.empty())
        return "grid: " + problem;
    if (d.basis == Basis::Grid && d.grid.count() > limits::kMaxGridBasis)
        return str("a grid-basis bake of ", d.grid.ToString(), " has more than ",
                   limits::kMaxGridBasis, " directions");
    if (d.basis == Basis::Grid && d.order != 0)
        return str("a grid-basis bake has SH order 0, not ", d.order);
    const size_t K = size_t(d.coefficientCount());
    const size_t N = L.position.size();
    if (L.normal.size() != N || L.part.size() != N)
        return str("per-sample arrays differ in size: position ", N, ", normal ", L.normal.size(),
                   ", part ", L.part.size());
    if (d.errorOrder < -1 || d.errorOrder > limits::kMaxErrorOrder)
        return str("error model order ", d.errorOrder, " is not in [-1, ", limits::kMaxErrorOrder, "]");
    if (d.errors.size() != size_t(d.errorCoefficientCount()) * N)
        return str(d.errors.size(), " error model values, expected ", d.errorCoefficientCount(),
                   " coefficients x ", N, " samples");
    if (L.muWidth < 1 || L.muHeight < 1)
        return str("mu layout is ", L.muWidth, " x ", L.muHeight, " texels");
    if (N > size_t(L.muWidth) * size_t(L.muHeight))
        return str(N, " samples do not fit the ", L.muWidth, " x ", L.muHeight, " mu layout");
    if (L.rhoWidth < 1 || L.rhoHeight < 1)
        return str("rho layout is ", L.rhoWidth, " x ", L.rhoHeight, " texels");
    if (L.rho.size() != size_t(L.rhoWidth) * size_t(L.rhoHeight))
        return str("rho has ", L.rho.size(), " texels, expected ", L.rhoWidth, " x ", L.rhoHeight);
    if (L.isChartLayout()) {
        const std::string chart = chartInconsistency(L);
        if (!chart.empty()) return chart;
    } else if (L.rate < 1 || L.rate > limits::kMaxRate) {
        return str("rate ", L.rate, " is not in [1, ", limits::kMaxRate, "]");
    }
    for (int side : {L.muWidth, L.muHeight, L.rhoWidth, L.rhoHeight})
        if (side > limits::kMaxTextureSize)
            return str("a layout side of ", side, " texels is above ", limits::kMaxTextureSize);
    if (L.triangleCount < 0) return str("triangle count ", L.triangleCount, " is negative");
    if (L.triangleCount > 0 && !L.isChartLayout()) {
        if (L.blockWidth < 1 || L.blockHeight < 1 || L.blocksPerRow < 1)
            return str("rho blocks are ", L.blockWidth, " x ", L.blockHeight, ", ", L.blocksPerRow,
                       " per row");
        const int64_t blocks = (int64_t(L.triangleCount) + 1) / 2;
        const int64_t blockRows = (blocks + L.blocksPerRow - 1) / L.blocksPerRow;
        if (int64_t(L.blocksPerRow) * L.blockWidth > L.rhoWidth ||
            blockRows * L.blockHeight > L.rhoHeight)
            return str(L.triangleCount, " triangles in ", L.blockWidth, " x ", L.blockHeight,
                       " blocks, ", L.blocksPerRow, " per row, do not fit the ", L.rhoWidth, " x ",
                       L.rhoHeight, " rho layout");
        // A block holds an upright triangle's samples (i + j <= r) and corrections (r + 1), and
        // its rotated partner's, without the two meeting (docs/format.md "rho").
        const int r = L.rate;
        if (L.blockWidth < r + 1 || L.blockHeight < r + 1 || L.blockWidth + L.blockHeight < 2 * r + 5)
            return str("rho blocks of ", L.blockWidth, " x ", L.blockHeight,
                       " texels cannot hold two triangles at rate ", r);
        if (N == 0) return str(L.triangleCount, " triangles but no samples");
    }
    for (size_t t = 0; t < L.rho.size(); ++t) {
        const RhoTexel& r = L.rho[t];
        const int x = int(t % size_t(L.rhoWidth)), y = int(t / size_t(L.rhoWidth));
        if (r.kind > RhoTexel::Correction)
            return str("rho texel (", x, ", ", y, ") has unknown kind ", r.kind);
        const bool bad = (r.kind == RhoTexel::Sample && r.a >= N) ||
                         (r.kind == RhoTexel::Correction && (r.a >= N || r.b >= N || r.c >= N));
        if (bad)
            return str("rho texel (", x, ", ", y, ") refers to samples (", r.a, ", ", r.b, ", ",
                       r.c, ") but there are only ", N);
    }
    // Every triangle's grid positions hold its samples, and the texels past its hypotenuse its
    // corrections: what the runtime and queryBake look up (SurfaceLayout::sampleAt). Chart
    // layouts have no triangle blocks (chartInconsistency checks their atlas).
    for (int t = 0; t < (L.isChartLayout() ? 0 : L.triangleCount); ++t) {
        for (int j = 0; j <= L.rate + 1; ++j)
            for (int i = 0; i + j <= L.rate + 1; ++i) {
                const bool correction = i + j == L.rate + 1;
                if (correction && (i == 0 || j == 0)) continue;
                const glm::ivec2 x = L.rhoTexel(t, i, j);
                const uint32_t kind = L.rho[size_t(x.y) * size_t(L.rhoWidth) + size_t(x.x)].kind;
                if (kind != (correction ? RhoTexel::Correction : RhoTexel::Sample))
                    return str("triangle ", t, "'s ", correction ? "correction" : "sample",
                               " texel (", i, ", ", j, ") at rho (", x.x, ", ", x.y,
                               ") has kind ", kind);
            }
    }
    for (size_t i = 0; i < N; ++i) {
        const glm::vec3 p = L.position[i], n = L.normal[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return str("sample ", i, " has a non-finite position");
        const float len = glm::length(n);
        if (!(std::fabs(len - 1.0f) < 1e-3f))
            return str("sample ", i, " has a normal of length ", len, ", not a unit vector");
    }
    if (L.neighbourOffset.size() != N || L.neighbourCount.size() != N)
        return str("neighbour offsets (", L.neighbourOffset.size(), ") and counts (",
                   L.neighbourCount.size(), ") are not one per sample (", N, ")");
    const size_t E = L.neighbourIndex.size();
    if (L.neighbourWeight.size() != E)
        return str(E, " neighbour indices but ", L.neighbourWeight.size(), " weights");
    for (size_t i = 0; i < N; ++i) {
        if (uint64_t(L.neighbourOffset[i]) + L.neighbourCount[i] > E)
            return str("neighbours of sample ", i, " (offset ", L.neighbourOffset[i], ", count ",
                       L.neighbourCount[i], ") run past the list of ", E);
    }
    for (size_t e = 0; e < E; ++e) {
        if (L.neighbourIndex[e] >= N)
            return str("neighbour list entry ", e, " refers to sample ", L.neighbourIndex[e],
                       " but there are only ", N);
        if (!std::isfinite(L.neighbourWeight[e]))
            return str("neighbour list entry ", e, " has a non-finite weight");
    }
    // Smoothing averages a sample with its neighbours: itself first, weights summing to 1.
    for (size_t i = 0; i < N; ++i) {
        if (L.neighbourCount[i] == 0) continue;
        if (L.neighbourIndex[L.neighbourOffset[i]] != i)
            return str("the neighbour list of sample ", i, " does not start with the sample itself");
        double sum = 0;
        for (uint32_t k = 0; k < L.neighbourCount[i]; ++k)
            sum += L.neighbourWeight[L.neighbourOffset[i] + k];
        if (!(std::fabs(sum - 1.0) < 1e-3))
            return str("the neighbour weights of sample ", i, " sum to ", sum, ", not 1");
    }
    if (d.weights.size() != K * N * 4)
        return str(d.weights.size(), " weights, expected ", K, " coefficients x ", N,
                   " samples x 4");
    for (size_t v = 0; v < d.weights.size(); ++v)
        if (!std::isfinite(d.weights[v]))
            return str("weight ", v / (4 * N), " of sample ", (v / 4) % N, " channel ",
                       kWeightSuffix[v % 4], " is not finite");
    return "";
}

// The descriptive keys that tools act on (evaluation re-traces with the media, grid, branch and
// bounce cap; the runtime shades with media[0]), checked as shrefract-bake checks its options and
// a scene its media (common/limits.h, mediumProblem): a manifest that says IOR 0 is refused, not
// rendered as a mirror. Keys a bake may lack are checked only when present. Returns what is
// wrong, or "".
std::string manifestProblem(const json& m) {
    if (auto it = m.find("media"); it != m.end()) {
        if (!it->is_array()) return "\"media\" is not an array";
        for (size_t i = 0; i < it->size(); ++i) {
            const json& md = (*it)[i];
            const std::string where = str("media[", i, "]");
            if (!md.is_object()) return where + " is not an object";
            Medium medium;
            if (md.contains("ior")) {
                if (!md["ior"].is_number()) return where + ": 'ior' is not a number";
                medium.ior = md["ior"].get<double>();
            }
            if (md.contains("absorption")) {
                const json& a = md["absorption"];
                if (!a.is_array() || a.size() != 3) return where + ": 'absorption' is not 3 numbers";
                for (int c = 0; c < 3; ++c) {
                    if (!a[c].is_number()) return where + ": 'absorption' is not 3 numbers";
                    medium.absorption[c] = a[c].get<double>();
                }
            }
            if (md.contains("priority") && !md["priority"].is_number_integer())
                return where + ": 'priority' is not an integer";
            for (const char* key : {"name", "mesh", "meshChecksum"})
                if (md.contains(key) && !md[key].is_string())
                    return str(where, ": '", key, "' is not a string");
            const std::string problem = mediumProblem(medium);
            if (!problem.empty()) return where + ": " + problem;
        }
    }
    if (auto it = m.find("grid"); it != m.end() && it->is_array()) {
        if (it->size() != 2 || !(*it)[0].is_number_integer() || !(*it)[1].is_number_integer())
            return "\"grid\" is not [nTheta, nPhi]";
        const std::string problem = gridProblem((*it)[0].get<int>(), (*it)[1].get<int>());
        if (!problem.empty()) return "\"grid\": " + problem;
    }
    if (auto it = m.find("filterWidth"); it != m.end()) {
        if (!it->is_number() || !(it->get<double>() >= 0.0) ||
            it->get<double>() > limits::kMaxFilterWidth)
            return str("\"filterWidth\" ", it->dump(), " is not in [0, ", limits::kMaxFilterWidth, "]");
    }
    if (auto it = m.find("maxBounces"); it != m.end()) {
        if (!it->is_number_integer() || it->get<int64_t>() < 1 ||
            it->get<int64_t>() > limits::kMaxBounces)
            return str("\"maxBounces\" ", it->dump(), " is not in [1, ", limits::kMaxBounces, "]");
    }
    if (auto it = m.find("branch"); it != m.end()) {
        if (*it != "fresnel" && *it != "transmit")
            return str("\"branch\" ", it->dump(), " is not \"fresnel\" or \"transmit\"");
    }
    if (auto it = m.find("input"); it != m.end() && !it->is_string())
        return "\"input\" is not a string";
    return "";
}

}  // namespace shrefract::format_internal
