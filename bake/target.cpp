#include "bake/target.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>

#include <Eigen/Core>

#include "bake/fit.h"
#include "bake/joining_layout.h"
#include "common/decompress.h"
#include "common/error.h"
#include "common/frame.h"
#include "common/limits.h"
#include "common/sh.h"

namespace shrefract {
namespace {

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
    if (!(la > 0) || !std::isfinite(la)) return 180.0;  // no direction predicted: the worst
    return std::acos(std::clamp(double(glm::dot(a / la, b)), -1.0, 1.0)) * 180.0 / M_PI;
}

// An SH candidate of `order`, or with `basis` Grid the grid basis (order 0).
TargetCandidate candidate(Basis basis, int order, int rate, const DirectionGrid& grid, Precision p, size_t samples) {
    TargetCandidate c;
    c.basis = basis;
    c.order = basis == Basis::Grid ? 0 : order;
    c.rate = rate, c.grid = grid, c.precision = p, c.samples = samples;
    c.weightBytes = samples * weightsTexelBytes(basisCoefficients(basis, c.order, grid), p);
    c.bakeCost = double(samples) * grid.count();
    return c;
}

bool isPaperModel(const TargetCandidate& c, int baseRate) {
    return c.basis == Basis::Sh && c.order == 8 && c.rate == baseRate &&
           c.grid == DirectionGrid{32, 64} && c.precision == Precision::F32;
}

std::string describe(const TargetCandidate& c) {
    const std::string model = c.basis == Basis::Grid ? "grid basis " + c.grid.ToString() : str("order ", c.order);
    return str(model, ", rate ", c.rate, ", ", nameOf(c.precision), ": ", c.weightBytes / 1e6, " MB");
}

// The angles (degrees, sorted) between each pair's truth and the prediction interpolated from
// the triangle's samples; value(id, omega): sample id's decompressed value toward omega.
template <class Value>
std::vector<double> errorsDeg(const SurfaceLayout& L, const std::vector<HeldOutPair>& pairs, Value value) {
    std::vector<glm::vec4> values(L.position.size());
    std::vector<double> err;
    err.reserve(pairs.size());
    for (const HeldOutPair& h : pairs) {
        for (int j = 0; j <= L.rate; ++j)
            for (int i = 0; i + j <= L.rate; ++i) {
                const uint32_t id = L.sampleAt(h.triangle, i, j);
                values[id] = value(id, h.omega);
            }
        err.push_back(angleDeg(glm::vec3(interpolateRho(L, values.data(), h.triangle, h.u, h.v)), h.truth));
    }
    std::sort(err.begin(), err.end());
    return err;
}

}  // namespace

nlohmann::json TargetSearchResult::ToJson() const {
    auto cj = [](const TargetCandidate& c) {
        return nlohmann::json{{"basis", nameOf(c.basis)}, {"order", c.order}, {"rate", c.rate}, {"grid", c.grid.ToString()},
                              {"precision", nameOf(c.precision)}, {"medianDeg", c.medianDeg},
                              {"p95Deg", c.p95Deg}, {"meanDeg", c.meanDeg}, {"samples", c.samples},
                              {"weightMB", c.weightBytes / 1e6}, {"paths", c.bakeCost}};
    };
    nlohmann::json a = nlohmann::json::array();
    for (const auto& c : all) a.push_back(cj(c));
    return {{"reached", reached}, {"chosen", cj(chosen)}, {"paper", cj(reference)}, {"candidates", a},
            {"memorySaving", double(reference.weightBytes) / std::max<size_t>(1, chosen.weightBytes)},
            {"bakeSaving", reference.bakeCost / std::max(1.0, chosen.bakeCost)}};
}

std::vector<HeldOutPair> heldOutPairs(const Scene& scene, const TraceOptions& trace,
                                      const TargetSearchOptions& opt) {
    // Area-weighted triangles, uniform barycentrics, uniform hemisphere directions about the
    // interpolated normal.
    const std::vector<TriangleRef> tris = triangles(scene);
    Tracer tracer(scene, trace);
    std::vector<double> area(tris.size());
    for (size_t t = 0; t < tris.size(); ++t) {
        const auto& P = tris[t].mesh->positions;
        area[t] = glm::length(glm::cross(P[tris[t].tri[1]] - P[tris[t].tri[0]], P[tris[t].tri[2]] - P[tris[t].tri[0]]));
    }
    std::mt19937_64 rng(opt.seed);
    std::discrete_distribution<int> pickTriangle(area.begin(), area.end());
    std::uniform_real_distribution<float> U(0, 1);
    std::vector<HeldOutPair> pairs;
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
    return pairs;
}

std::vector<double> heldOutErrorsDeg(const BakeData& bake, const std::vector<HeldOutPair>& pairs) {
    return errorsDeg(bake.layout, pairs, [&](uint32_t id, glm::vec3 omega) {
        return decompressSample(bake, int(id), localViewDirection(bake.layout, int(id), omega));
    });
}

TargetSearchResult searchTarget(const Scene& scene, const BakeOptions& base,
                                const TargetSearchOptions& opt) {
    const bool budget = opt.goal == TargetGoal::Budget;
    std::vector<int> rates = opt.rates.empty() ? std::vector<int>{1, 2, 3} : opt.rates;
    const int baseRate = base.rate > 0 ? base.rate : rateForSampleCount(scene, base.samples);
    if (std::find(rates.begin(), rates.end(), baseRate) == rates.end()) rates.push_back(baseRate);
    std::map<int, size_t> samplesAt;
    for (int r : rates) samplesAt[r] = joiningSampleCount(scene, r);

    // What gets fitted: the candidates searched (in a budget search only those that fit in it),
    // and the paper's model, the comparison printed beside the choice, whatever the search is
    // restricted to (--basis grid, --precision u8).
    auto in = [](const auto& list, const auto& x) { return std::find(list.begin(), list.end(), x) != list.end(); };
    auto fits = [&](const TargetCandidate& c) { return !budget || c.weightBytes <= opt.budgetBytes; };
    // Searched: the options' SH orders the fit can solve at the grid, the grid basis at grids it can hold.
    auto searched = [&](const TargetCandidate& c) {
        if (!in(opt.bases, c.basis) || !in(opt.grids, c.grid) || !in(opt.precisions, c.precision)) return false;
        return c.basis == Basis::Grid ? c.grid.count() <= limits::kMaxGridBasis
                                      : in(opt.orders, c.order) && fitCanSolve(base.fit, c.order, c.grid);
    };
    auto kept = [&](const TargetCandidate& c) { return searched(c) && fits(c); };
    auto wanted = [&](const TargetCandidate& c) {
        return kept(c) || (isPaperModel(c, baseRate) && fitCanSolve(base.fit, c.order, c.grid));
    };
    // The loops' lists: the options' own, with the paper's model added.
    auto with = [&](auto list, auto x) {
        if (!in(list, x)) list.push_back(x);
        return list;
    };
    const std::vector<int> everyOrder = with(opt.orders, 8);
    const std::vector<DirectionGrid> everyGrid = with(opt.grids, DirectionGrid{32, 64});
    const std::vector<Precision> everyPrecision = with(opt.precisions, Precision::F32);
    if (budget) {
        const TargetCandidate* cheapest = nullptr;
        std::vector<TargetCandidate> each;
        for (int r : rates)
            for (Precision p : opt.precisions)
                for (const DirectionGrid& g : opt.grids) {
                    for (int L : opt.orders)
                        if (TargetCandidate c = candidate(Basis::Sh, L, r, g, p, samplesAt[r]); searched(c))
                            each.push_back(c);
                    if (TargetCandidate c = candidate(Basis::Grid, 0, r, g, p, samplesAt[r]); searched(c))
                        each.push_back(c);
                }
        for (const TargetCandidate& c : each)
            if (!cheapest || c.weightBytes < cheapest->weightBytes) cheapest = &c;
        if (!cheapest || cheapest->weightBytes > opt.budgetBytes)
            throw InputError(str("--budget ", opt.budgetBytes / 1e6, " MB: the smallest model searched (",
                                 cheapest ? describe(*cheapest) : std::string("none"),
                                 " of weights) does not fit; raise the budget"));
    }

    const std::vector<HeldOutPair> pairs = heldOutPairs(scene, base.trace, opt);
    Tracer tracer(scene, base.trace);
    TargetSearchResult result;
    for (int r : rates) {
        std::unique_ptr<SurfaceLayout> layout;  // built when a grid of this rate is traced
        for (const DirectionGrid& grid : everyGrid) {
            // The orders with some precision wanted at this (rate, grid).
            std::vector<int> orders;
            for (int L : everyOrder)
                for (Precision p : everyPrecision)
                    if (wanted(candidate(Basis::Sh, L, r, grid, p, samplesAt[r]))) {
                        orders.push_back(L);
                        break;
                    }
            // And the grid basis, at some precision.
            const bool gridBasis = std::any_of(everyPrecision.begin(), everyPrecision.end(), [&](Precision p) {
                return wanted(candidate(Basis::Grid, 0, r, grid, p, samplesAt[r]));
            });
            if (orders.empty() && !gridBasis) continue;
            if (!layout) layout = std::make_unique<SurfaceLayout>(buildJoiningLayout(scene, r));
            const SurfaceLayout& L = *layout;
            // Only the samples the held-out triangles touch are traced: `local` numbers them.
            std::map<uint32_t, int> local;
            for (const HeldOutPair& h : pairs)
                for (int j = 0; j <= r; ++j)
                    for (int i = 0; i + j <= r; ++i) local.emplace(L.sampleAt(h.triangle, i, j), 0);
            std::vector<uint32_t> ids;
            for (auto& [id, slot] : local) slot = int(ids.size()), ids.push_back(id);

            if (opt.log)
                opt.log(str("rate ", r, ", grid ", grid.ToString(), ": tracing ", ids.size(), " of ",
                            samplesAt[r], " samples, fitting ", orders.size(), " orders",
                            gridBasis ? " and the grid basis" : ""));
            // Each order fitted as the bake fits it (bake/fit.h), one sample at a time.
            std::vector<std::unique_ptr<SampleFit>> fitters;
            for (int order : orders)
                fitters.push_back(std::make_unique<SampleFit>(grid, order, base.fit, base.weighting,
                                                              base.filterWidth, base.cacheDir));
            // weights[o]: the traced samples' weights at orders[o], laid out as a bake's.
            std::vector<std::vector<float>> weights(orders.size());
            for (size_t o = 0; o < orders.size(); ++o)
                weights[o].assign(size_t(fitters[o]->coefficients()) * ids.size() * 4, 0.0f);
            const int J = grid.count();
            // The grid basis's weights: the traced values themselves, as a bake stores them.
            std::vector<float> traced(gridBasis ? size_t(J) * ids.size() * 4 : 0);
            tbb::parallel_for(size_t(0), ids.size(), [&](size_t s) {
                enableFlushToZero();
                const uint32_t i = ids[s];
                Eigen::MatrixXf R(J, 4), Wt;
                std::vector<PathResult> paths(J);
                traceSampleGrid(tracer, L, i, grid, false, paths.data());
                for (int j = 0; j < J; ++j) {
                    R.row(j) << paths[j].exit.x, paths[j].exit.y, paths[j].exit.z, paths[j].length;
                    if (gridBasis)
                        for (int c = 0; c < 4; ++c) traced[(size_t(j) * ids.size() + s) * 4 + c] = R(j, c);
                }
                for (size_t o = 0; o < orders.size(); ++o) {
                    Wt.resize(4, fitters[o]->coefficients());
                    fitters[o]->fit(R, paths.data(), 1, Wt);
                    for (int k = 0; k < Wt.cols(); ++k)
                        for (int c = 0; c < 4; ++c) weights[o][(size_t(k) * ids.size() + s) * 4 + c] = Wt(c, k);
                }
            });
            // Each wanted candidate, measured on the pairs through a bake that holds the traced
            // samples only (the others are never looked up).
            BakeData partial;
            partial.layout.position.resize(ids.size());
            partial.layout.normal.resize(ids.size());
            for (size_t s = 0; s < ids.size(); ++s)
                partial.layout.position[s] = L.position[ids[s]], partial.layout.normal[s] = L.normal[ids[s]];
            // Candidate c with weights w, measured and kept.
            auto measure = [&](TargetCandidate c, const std::vector<float>& w) {
                partial.basis = c.basis;
                partial.order = c.order;
                partial.grid = grid;
                partial.precision = c.precision;
                partial.weights = w;
                partial.u8Scale.clear(), partial.u8Offset.clear();  // set again for u8 below
                // A fit that still came out non-finite (the bake would refuse it, BakePlan::data)
                // predicts nothing (180 deg).
                const bool finite = std::all_of(partial.weights.begin(), partial.weights.end(),
                                                [](float x) { return std::isfinite(x); });
                if (finite) quantizeWeights(partial);
                const std::vector<double> err =
                    finite ? errorsDeg(L, pairs, [&](uint32_t id, glm::vec3 omega) {
                        const int s = local.at(id);
                        return decompressSample(partial, s, localViewDirection(partial.layout, s, omega));
                    })
                           : std::vector<double>(pairs.size(), 180.0);
                c.medianDeg = err[err.size() / 2];
                c.p95Deg = err[size_t(0.95 * (err.size() - 1))];
                double sum = 0;
                for (double e : err) sum += e;
                c.meanDeg = sum / err.size();
                if (isPaperModel(c, baseRate)) result.reference = c;
                if (kept(c)) result.all.push_back(c);
            };
            for (Precision p : everyPrecision) {
                for (size_t o = 0; o < orders.size(); ++o)
                    if (TargetCandidate c = candidate(Basis::Sh, orders[o], r, grid, p, samplesAt[r]); wanted(c))
                        measure(c, weights[o]);
                if (TargetCandidate c = candidate(Basis::Grid, 0, r, grid, p, samplesAt[r]); gridBasis && wanted(c))
                    measure(c, traced);
            }
        }
    }

    auto cheaper = [](const TargetCandidate& a, const TargetCandidate& b) {
        return a.weightBytes != b.weightBytes ? a.weightBytes < b.weightBytes : a.bakeCost < b.bakeCost;
    };
    const TargetCandidate* best = nullptr;
    for (const auto& c : result.all) {
        if (budget) {  // the most accurate within the budget, then the cheapest
            if (!best || c.medianDeg < best->medianDeg || (c.medianDeg == best->medianDeg && cheaper(c, *best)))
                best = &c;
        } else if (c.medianDeg <= opt.targetDeg && (!best || cheaper(c, *best))) {
            best = &c;  // the cheapest meeting the target
        }
    }
    result.reached = best != nullptr;
    if (!best)  // no candidate meets the target: the most accurate
        for (const auto& c : result.all)
            if (!best || c.medianDeg < best->medianDeg) best = &c;
    result.chosen = *best;
    return result;
}

}  // namespace shrefract
