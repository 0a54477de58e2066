#include "bake/target.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <Eigen/Core>

#include "bake/joining_layout.h"
#include "common/decompress.h"
#include "common/frame.h"
#include "common/sh.h"

namespace shrefract {
namespace {

struct HeldOut {
    int triangle;
    float u, v;         // barycentrics of corners 1, 2
    glm::vec3 omega;    // object space, toward the viewer
    glm::vec3 truth;    // exit direction of the fresh trace
};

// Triangle t of the scene in layout order (parts in order, their triangles in order).
struct TriangleRef {
    const Mesh* mesh;
    glm::uvec3 tri;
    uint32_t part;
};

std::vector<TriangleRef> triangles(const Scene& s) {
    std::vector<TriangleRef> out;
    for (size_t p = 0; p < s.parts.size(); ++p)
        for (const glm::uvec3& t : s.parts[p].mesh.triangles) out.push_back({&s.parts[p].mesh, t, uint32_t(p)});
    return out;
}

double angleDeg(glm::vec3 a, glm::vec3 b) {
    float la = glm::length(a);
    if (la <= 0) return 180.0;
    return std::acos(std::clamp(double(glm::dot(a / la, b)), -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

nlohmann::json TargetSearchResult::ToJson() const {
    auto cj = [](const TargetCandidate& c) {
        return nlohmann::json{{"order", c.order}, {"rate", c.rate}, {"grid", c.grid.ToString()},
                              {"medianDeg", c.medianDeg}, {"p95Deg", c.p95Deg}, {"meanDeg", c.meanDeg},
                              {"samples", c.samples}, {"weightMB", c.weightBytes / 1e6}, {"paths", c.bakeCost}};
    };
    nlohmann::json a = nlohmann::json::array();
    for (const auto& c : all) a.push_back(cj(c));
    return {{"reached", reached}, {"chosen", cj(chosen)}, {"paper", cj(reference)}, {"candidates", a},
            {"memorySaving", double(reference.weightBytes) / std::max<size_t>(1, chosen.weightBytes)},
            {"bakeSaving", reference.bakeCost / std::max(1.0, chosen.bakeCost)}};
}

TargetSearchResult searchTarget(const Scene& scene, const BakeOptions& base,
                                const TargetSearchOptions& opt) {
    const std::vector<TriangleRef> tris = triangles(scene);
    Tracer tracer(scene, base.trace);

    // Held-out pairs: area-weighted triangles, uniform barycentrics, uniform hemisphere
    // directions about the interpolated normal; truth traced once, shared by all candidates.
    std::vector<double> area(tris.size());
    for (size_t t = 0; t < tris.size(); ++t) {
        const auto& P = tris[t].mesh->positions;
        area[t] = glm::length(glm::cross(P[tris[t].tri[1]] - P[tris[t].tri[0]], P[tris[t].tri[2]] - P[tris[t].tri[0]]));
    }
    std::mt19937_64 rng(opt.seed);
    std::discrete_distribution<int> pickTriangle(area.begin(), area.end());
    std::uniform_real_distribution<float> U(0, 1);
    std::vector<HeldOut> pairs;
    for (int k = 0; k < opt.points; ++k) {
        int t = pickTriangle(rng);
        float u = U(rng), v = U(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        const TriangleRef& T = tris[t];
        const auto& P = T.mesh->positions;
        const auto& N = T.mesh->normals;
        glm::vec3 p = (1 - u - v) * P[T.tri[0]] + u * P[T.tri[1]] + v * P[T.tri[2]];
        glm::vec3 n = glm::normalize((1 - u - v) * N[T.tri[0]] + u * N[T.tri[1]] + v * N[T.tri[2]]);
        Frame f = Frame::fromNormal(n);
        for (int d = 0; d < opt.directionsPerPoint; ++d) {
            float z = U(rng), phi = float(2 * M_PI) * U(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
            glm::vec3 omega = f.fromLocal({s * std::cos(phi), s * std::sin(phi), z});
            PathResult r = tracer.trace(p, n, omega, T.part);
            pairs.push_back({t, u, v, omega, r.exit});
        }
    }

    const int Lmax = *std::max_element(opt.orders.begin(), opt.orders.end());
    const int Kmax = shEvenCount(Lmax);
    std::vector<int> rates = opt.rates.empty() ? std::vector<int>{1, 2, 3} : opt.rates;
    const int baseRate = base.rate > 0 ? base.rate : rateForSampleCount(scene, base.samples);
    if (std::find(rates.begin(), rates.end(), baseRate) == rates.end()) rates.push_back(baseRate);

    TargetSearchResult result;
    for (int r : rates) {
        SurfaceLayout L = buildJoiningLayout(scene, r);
        const size_t total = L.position.size();
        // Only the samples the held-out triangles touch are traced.
        std::map<uint32_t, int> local;
        for (const HeldOut& h : pairs)
            for (int j = 0; j <= r; ++j)
                for (int i = 0; i + j <= r; ++i) local.emplace(L.sampleAt(h.triangle, i, j), 0);
        std::vector<uint32_t> ids;
        for (auto& [id, slot] : local) slot = int(ids.size()), ids.push_back(id);

        for (const DirectionGrid& grid : opt.grids) {
            const int J = grid.count();
            Eigen::MatrixXf Mt = compressionMatrixCached(grid, Lmax, base.cacheDir).transpose().cast<float>();
            std::vector<glm::vec3> dirs(J);
            for (int j = 0; j < J; ++j) dirs[j] = glm::vec3(grid.direction(j));
            // W for every traced sample at Lmax: (K x 4) per sample, same layout as a bake.
            BakeData partial;
            partial.order = Lmax;
            partial.layout.position.resize(ids.size());
            partial.layout.normal.resize(ids.size());
            partial.weights.assign(size_t(Kmax) * ids.size() * 4, 0.0f);
            tbb::parallel_for(size_t(0), ids.size(), [&](size_t s) {
                enableFlushToZero();
                uint32_t i = ids[s];
                partial.layout.position[s] = L.position[i];
                partial.layout.normal[s] = L.normal[i];
                Frame f = Frame::fromNormal(L.normal[i]);
                Eigen::MatrixXf R(J, 4);
                for (int j = 0; j < J; ++j) {
                    PathResult p = tracer.trace(L.position[i], L.normal[i], f.fromLocal(dirs[j]), L.part[i]);
                    R.row(j) << p.exit.x, p.exit.y, p.exit.z, p.length;
                }
                Eigen::MatrixXf Wt = R.transpose() * Mt;  // 4 x K
                for (int k = 0; k < Kmax; ++k)
                    for (int c = 0; c < 4; ++c) partial.weights[(size_t(k) * ids.size() + s) * 4 + c] = Wt(c, k);
            });
            for (int order : opt.orders) {
                std::vector<double> err;
                std::vector<glm::vec4> values(total);
                for (const HeldOut& h : pairs) {
                    for (int j = 0; j <= r; ++j)
                        for (int i = 0; i + j <= r; ++i) {
                            uint32_t id = L.sampleAt(h.triangle, i, j);
                            int s = local[id];
                            values[id] = decompressSample(partial, s, localViewDirection(partial.layout, s, h.omega), order);
                        }
                    glm::vec4 d = interpolateRho(L, values.data(), h.triangle, h.u, h.v);
                    err.push_back(angleDeg(glm::vec3(d), h.truth));
                }
                std::sort(err.begin(), err.end());
                TargetCandidate c;
                c.order = order, c.rate = r, c.grid = grid, c.samples = total;
                c.medianDeg = err[err.size() / 2];
                c.p95Deg = err[size_t(0.95 * (err.size() - 1))];
                double sum = 0;
                for (double e : err) sum += e;
                c.meanDeg = sum / err.size();
                c.weightBytes = total * size_t(shEvenCount(order)) * 16;
                c.bakeCost = double(total) * J;
                result.all.push_back(c);
                if (r == baseRate && order == 8 && grid.nTheta == 32 && grid.nPhi == 64) result.reference = c;
            }
        }
    }
    // The cheapest in memory that meets the target (then the cheapest to bake); else the most
    // accurate candidate.
    const TargetCandidate* best = nullptr;
    for (const auto& c : result.all) {
        if (c.medianDeg > opt.targetDeg) continue;
        if (!best || c.weightBytes < best->weightBytes ||
            (c.weightBytes == best->weightBytes && c.bakeCost < best->bakeCost))
            best = &c;
    }
    result.reached = best != nullptr;
    if (!best)
        for (const auto& c : result.all)
            if (!best || c.medianDeg < best->medianDeg) best = &c;
    result.chosen = *best;
    return result;
}

}  // namespace shrefract
