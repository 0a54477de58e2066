#include "eval/directions.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>

#include "bake/tracer.h"
#include "common/decompress.h"
#include "common/error.h"
#include "common/direction_grid.h"
#include "common/frame.h"

namespace shrefract {

namespace {
// Angle in degrees between the unnormalized a and the unit b (180 if a vanishes).
double angleDegrees(glm::vec3 a, glm::vec3 b) {
    const float len = glm::length(a);
    const double c = len > 0 ? glm::dot(a / len, b) : -1.0;
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}
}  // namespace

Scene sceneOfBake(const BakeData& bake, const std::string& bakePath, const std::string& overridePath) {
    const nlohmann::json& m = bake.manifest;
    std::string input = overridePath.empty() ? m.value("input", std::string()) : overridePath;
    if (input.empty()) throw inputError(bakePath, "manifest names no input scene; pass --scene");
    if (!std::filesystem::exists(input))
        throw inputError(bakePath, "its input scene " + input + " is not there; pass --scene");
    Medium medium;
    if (m.contains("media") && !m["media"].empty()) {
        const auto& md = m["media"][0];
        medium.ior = md.value("ior", 1.5);
        medium.priority = md.value("priority", 0);
    }
    Scene scene = loadScene(input, medium);
    if (m.contains("media") && m["media"].size() == scene.parts.size()) {
        for (size_t i = 0; i < scene.parts.size(); ++i) {
            std::string want = m["media"][i].value("meshChecksum", std::string());
            if (!want.empty() && want != scene.parts[i].mesh.checksum())
                throw inputError(input, "mesh differs from the one baked into " + bakePath +
                                            " (checksum " + scene.parts[i].mesh.checksum() + ", baked " + want + ")");
        }
    }
    return scene;
}

nlohmann::json errorStats(std::vector<double> e) {
    if (e.empty()) return {{"count", 0}};
    std::sort(e.begin(), e.end());
    auto pct = [&](double q) { return e[std::min(e.size() - 1, static_cast<size_t>(q * (e.size() - 1) + 0.5))]; };
    double mean = std::accumulate(e.begin(), e.end(), 0.0) / e.size();
    return {{"count", e.size()}, {"mean", mean}, {"median", pct(0.5)}, {"p95", pct(0.95)},
            {"p99", pct(0.99)}, {"max", e.back()}};
}

nlohmann::json evaluateDirections(const BakeData& bake, const Scene& scene, size_t pairs,
                                  uint64_t seed, int order, float zMin, float zMax,
                                  const std::vector<int>* sampleOrder) {
    const SurfaceLayout& L = bake.layout;
    TraceOptions topt;
    const auto& m = bake.manifest;
    topt.branch = m.value("branch", std::string("fresnel")) == "transmit" ? Branch::Transmit : Branch::Fresnel;
    topt.maxBounces = m.value("maxBounces", 32);
    Tracer tracer(scene, topt);

    struct Pair {
        uint32_t sample;
        glm::vec3 omegaLocal;
    };
    // Draw all pairs up front from one generator so results do not depend on thread count.
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    std::uniform_int_distribution<uint32_t> S(0, static_cast<uint32_t>(L.sampleCount() - 1));
    std::vector<Pair> draws(pairs);
    for (Pair& p : draws) {
        p.sample = S(rng);
        // Uniform over the hemisphere: z = cos(theta) uniform in [0, 1) (Archimedes).
        float z = zMin + (zMax - zMin) * U(rng), phi = 6.28318530718f * U(rng), sxy = std::sqrt(std::max(0.0f, 1 - z * z));
        p.omegaLocal = glm::vec3(sxy * std::cos(phi), sxy * std::sin(phi), z);
    }
    // The data ceiling: the raw grid of traced exits at the same sample, interpolated by the B_j
    // of the compression (bilinear in theta, phi) at the same omega. What any representation
    // fitted to this grid could reach (docs/evaluation.md).
    DirectionGrid grid;
    const bool haveGrid = m.contains("grid") && m["grid"].is_array() && m["grid"].size() == 2;
    if (haveGrid) grid.nTheta = m["grid"][0].get<int>(), grid.nPhi = m["grid"][1].get<int>();
    std::vector<double> angle(pairs), lenErr(pairs), ceilAngle(pairs), ceilLen(pairs);
    std::vector<double> predicted(pairs), shortness(pairs);
    std::vector<uint32_t> flags(pairs);
    tbb::parallel_for(size_t(0), pairs, [&](size_t k) {
        enableFlushToZero();
        const Pair& p = draws[k];
        const Frame f = Frame::fromNormal(L.normal[p.sample]);
        const glm::vec3 P = L.position[p.sample], N = L.normal[p.sample];
        const uint32_t part = L.part[p.sample];
        PathResult truth = tracer.trace(P, N, f.fromLocal(p.omegaLocal), part);
        const int o = sampleOrder ? (*sampleOrder)[p.sample] : order;
        glm::vec4 d = decompressSample(bake, static_cast<int>(p.sample), p.omegaLocal, o);
        angle[k] = angleDegrees(glm::vec3(d), truth.exit);
        lenErr[k] = std::abs(double(d.w) - truth.length);
        predicted[k] = predictedError(bake, int(p.sample), p.omegaLocal) * 180.0 / M_PI;
        shortness[k] = 1.0 - glm::length(glm::vec3(d));
        flags[k] = truth.flags;
        if (haveGrid) {
            int index[4];
            double weight[4];
            const int n = grid.interpolate(glm::dvec3(p.omegaLocal), index, weight);
            glm::vec3 e(0.0f);
            float len = 0.0f;
            for (int j = 0; j < n; ++j) {
                const PathResult g = tracer.trace(P, N, f.fromLocal(glm::vec3(grid.direction(index[j]))), part);
                e += float(weight[j]) * g.exit;
                len += float(weight[j]) * g.length;
            }
            ceilAngle[k] = angleDegrees(e, truth.exit);
            ceilLen[k] = std::abs(double(len) - truth.length);
        }
    });
    // The pairs whose traced path has any of `mask`'s flags (mask 0: none of TIR, capped and
    // re-entered, the "plain" paths; ~0u: every pair).
    auto subset = [&](uint32_t mask) {
        std::vector<double> a, l, ca, cl;
        for (size_t k = 0; k < pairs; ++k) {
            const bool in = mask == 0 ? (flags[k] & (kPathTIR | kPathCapped | kPathReentered)) == 0
                                      : mask == ~0u || (flags[k] & mask) != 0;
            if (!in) continue;
            a.push_back(angle[k]), l.push_back(lenErr[k]);
            ca.push_back(ceilAngle[k]), cl.push_back(ceilLen[k]);
        }
        nlohmann::json j{{"share", double(a.size()) / std::max<size_t>(1, pairs)},
                         {"angleDeg", errorStats(a)},
                         {"lengthError", errorStats(l)}};
        if (haveGrid) j["ceiling"] = {{"angleDeg", errorStats(ca)}, {"lengthError", errorStats(cl)}};
        return j;
    };
    const nlohmann::json all = subset(~0u);
    nlohmann::json prediction = {{"spearmanShortness", spearman(shortness, angle)}};
    if (bake.errorOrder >= 0) {
        prediction["spearman"] = spearman(predicted, angle);
        // Deciles of the prediction: its median and the measured median in each.
        std::vector<size_t> byPrediction(pairs);
        std::iota(byPrediction.begin(), byPrediction.end(), size_t(0));
        std::sort(byPrediction.begin(), byPrediction.end(),
                  [&](size_t a, size_t b) { return predicted[a] < predicted[b]; });
        nlohmann::json bins = nlohmann::json::array();
        for (int q = 0; q < 10 && pairs >= 10; ++q) {
            std::vector<double> p, a;
            for (size_t k = q * pairs / 10; k < (q + 1) * pairs / 10; ++k)
                p.push_back(predicted[byPrediction[k]]), a.push_back(angle[byPrediction[k]]);
            bins.push_back({{"predictedDeg", errorStats(p)["median"]}, {"measuredDeg", errorStats(a)["median"]}});
        }
        prediction["deciles"] = bins;
    }
    return {{"pairs", pairs},
            {"seed", seed},
            {"order", order < 0 ? bake.order : std::min(order, bake.order)},
            {"model", order < 0 || order >= bake.order ? bake.modelName() : "order " + std::to_string(order)},
            {"angleDeg", all["angleDeg"]},
            {"lengthError", all["lengthError"]},
            {"all", all},
            {"tir", subset(kPathTIR)},
            {"capped", subset(kPathCapped)},
            {"reentered", subset(kPathReentered)},
            {"plain", subset(0)},
            {"prediction", prediction}};
}

double spearman(const std::vector<double>& a, const std::vector<double>& b) {
    SHREFRACT_CHECK(a.size() == b.size());
    const size_t n = a.size();
    auto ranks = [n](const std::vector<double>& x) {
        std::vector<size_t> idx(n);
        std::iota(idx.begin(), idx.end(), size_t(0));
        std::sort(idx.begin(), idx.end(), [&](size_t p, size_t q) { return x[p] < x[q]; });
        std::vector<double> r(n);
        for (size_t s = 0; s < n;) {
            size_t e = s;
            while (e + 1 < n && x[idx[e + 1]] == x[idx[s]]) ++e;
            for (size_t k = s; k <= e; ++k) r[idx[k]] = 0.5 * double(s + e);  // mean rank of the tie
            s = e + 1;
        }
        return r;
    };
    const std::vector<double> ra = ranks(a), rb = ranks(b);
    const double mean = 0.5 * double(n - 1);
    double sab = 0, saa = 0, sbb = 0;
    for (size_t k = 0; k < n; ++k) {
        sab += (ra[k] - mean) * (rb[k] - mean);
        saa += (ra[k] - mean) * (ra[k] - mean), sbb += (rb[k] - mean) * (rb[k] - mean);
    }
    return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

namespace {

// Closest point to p on triangle (a, b, c), as barycentric weights (u, v) of b and c.
glm::vec2 closestBarycentric(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c, float* dist2) {
    glm::vec3 e1 = b - a, e2 = c - a, ap = p - a;
    float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    float p1 = glm::dot(ap, e1), p2 = glm::dot(ap, e2);
    float det = d11 * d22 - d12 * d12;
    glm::vec2 best(0.0f);
    float bestD = std::numeric_limits<float>::max();
    auto consider = [&](float u, float v) {
        glm::vec3 q = a + u * e1 + v * e2;
        float d = glm::dot(p - q, p - q);
        if (d < bestD) bestD = d, best = {u, v};
    };
    if (det > 0) {
        float u = (d22 * p1 - d12 * p2) / det, v = (d11 * p2 - d12 * p1) / det;
        if (u >= 0 && v >= 0 && u + v <= 1) consider(u, v);
    }
    if (bestD == std::numeric_limits<float>::max()) {
        // Outside: the closest point is on an edge.
        auto seg = [&](glm::vec3 s0, glm::vec3 s1, auto toUV) {
            glm::vec3 s = s1 - s0;
            float t = std::clamp(glm::dot(p - s0, s) / std::max(glm::dot(s, s), 1e-30f), 0.0f, 1.0f);
            glm::vec2 uv = toUV(t);
            consider(uv.x, uv.y);
        };
        seg(a, b, [](float t) { return glm::vec2(t, 0); });
        seg(a, c, [](float t) { return glm::vec2(0, t); });
        seg(b, c, [](float t) { return glm::vec2(1 - t, t); });
    }
    *dist2 = bestD;
    return best;
}

// Refuses query q unless its point lies within maxDistance of the surface (distance: to the
// nearest triangle, corners a, b, c, counter-clockwise seen from outside, their shading normals
// summing to ns) and its view direction w does not point into the surface there.
void refuseOffSurface(size_t q, glm::vec3 p, glm::vec3 w, float distance, float maxDistance,
                      glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 ns) {
    if (!(distance <= maxDistance)) {
        std::ostringstream os;
        os << "point (" << p.x << ", " << p.y << ", " << p.z << ") is " << distance
           << " from the surface (at most " << maxDistance << ")";
        throw QueryRefused(q, os.str());
    }
    // The outward geometric normal, turned to agree with the corners' shading normals.
    glm::vec3 n = glm::cross(b - a, c - a);
    if (glm::dot(n, ns) < 0.0f) n = -n;
    n = glm::normalize(n);
    if (glm::dot(glm::normalize(w), n) < -1e-4f) {
        std::ostringstream os;
        os << "view direction (" << w.x << ", " << w.y << ", " << w.z
           << ") points into the surface (its normal there is (" << n.x << ", " << n.y << ", "
           << n.z << "))";
        throw QueryRefused(q, os.str());
    }
}

// A chart bake: the nearest triangle of the unfolded mesh gives the point's atlas UV, the map
// there is the runtime's (the bake's gutter, seam-aware), built by the CPU twin from the samples
// that can reach the bilinear lookup (a window of gutter + 2 texels and its seam sources).
// Refuses as refuseOffSurface does.
glm::vec4 queryChart(const BakeData& bake, size_t q, glm::vec3 p, glm::vec3 w, float maxDistance) {
    const SurfaceLayout& L = bake.layout;
    const ChartAtlas& A = L.atlas;
    float bestD = std::numeric_limits<float>::max();
    glm::vec2 uv(0.0f);
    const glm::uvec3* best = nullptr;
    for (const glm::uvec3& t : A.triangles) {
        float d2;
        const glm::vec2 b = closestBarycentric(p, A.vertexPosition[t[0]], A.vertexPosition[t[1]],
                                               A.vertexPosition[t[2]], &d2);
        if (d2 >= bestD) continue;
        bestD = d2, best = &t;
        uv = (1 - b.x - b.y) * A.vertexUV[t[0]] + b.x * A.vertexUV[t[1]] + b.y * A.vertexUV[t[2]];
    }
    if (!best) throw QueryRefused(q, "the bake has no triangles");
    const glm::uvec3& t = *best;
    refuseOffSurface(q, p, w, std::sqrt(bestD), maxDistance, A.vertexPosition[t[0]],
                     A.vertexPosition[t[1]], A.vertexPosition[t[2]],
                     A.vertexNormal[t[0]] + A.vertexNormal[t[1]] + A.vertexNormal[t[2]]);
    const glm::vec3 omega = glm::normalize(w);
    const int W = L.muWidth, reach = A.gutter + 2;
    const glm::ivec2 c(int(uv.x * W), int(uv.y * L.muHeight));
    std::vector<int> sampleAt(size_t(W) * L.muHeight, -1);
    for (int i = 0; i < L.sampleCount(); ++i) {
        const glm::ivec2 t = L.muTexel(i);
        sampleAt[size_t(t.y) * W + t.x] = i;
    }
    std::vector<glm::vec4> values(L.sampleCount(), glm::vec4(0.0f));
    auto need = [&](int i) {
        if (values[i] == glm::vec4(0.0f))
            values[i] = foldedSample(bake, i, localViewDirection(L, i, omega));
    };
    std::vector<char> inWindow(size_t(W) * L.muHeight, 0);
    for (int y = std::max(0, c.y - reach); y <= std::min(L.muHeight - 1, c.y + reach); ++y)
        for (int x = std::max(0, c.x - reach); x <= std::min(W - 1, c.x + reach); ++x) {
            inWindow[size_t(y) * W + x] = 1;
            if (sampleAt[size_t(y) * W + x] >= 0) need(sampleAt[size_t(y) * W + x]);
        }
    for (const SeamSource& s : A.seam)
        if (inWindow[s.texel])
            for (int k = 0; k < 4; ++k)
                if (s.weight[k] != 0.0f) need(int(s.sample[k]));
    ChartMapOptions o;
    o.dilation = A.gutter;
    return sampleBilinear(chartRefractionMap(L, values.data(), o), W, L.muHeight, uv);
}

}  // namespace

std::vector<glm::vec4> queryBake(const BakeData& bake, const std::vector<glm::vec3>& p,
                                 const std::vector<glm::vec3>& w, float maxDistance) {
    SHREFRACT_CHECK_EQ(p.size(), w.size());
    const SurfaceLayout& L = bake.layout;
    if (maxDistance < 0.0f && !L.position.empty()) {
        glm::vec3 lo = L.position[0], hi = L.position[0];
        for (const glm::vec3& x : L.position) lo = glm::min(lo, x), hi = glm::max(hi, x);
        maxDistance = kQueryDistance * glm::length(hi - lo);
    }
    if (L.isChartLayout()) {
        std::vector<glm::vec4> out(p.size());
        for (size_t q = 0; q < p.size(); ++q) {
            const glm::vec4 d = queryChart(bake, q, p[q], w[q], maxDistance);
            const glm::vec3 e(d);
            out[q] = glm::vec4(glm::length(e) > 0 ? e / glm::length(e) : e, d.w);
        }
        return out;
    }
    const int r = L.rate;
    std::vector<glm::vec4> values(L.sampleCount(), glm::vec4(0.0f));
    std::vector<glm::vec4> out(p.size());
    for (size_t q = 0; q < p.size(); ++q) {
        int bestT = -1;
        glm::vec2 bestUV(0.0f);
        float bestD = std::numeric_limits<float>::max();
        for (int t = 0; t < L.triangleCount; ++t) {
            glm::vec3 a = L.position[L.sampleAt(t, 0, 0)], b = L.position[L.sampleAt(t, r, 0)],
                      c = L.position[L.sampleAt(t, 0, r)];
            float d2;
            glm::vec2 uv = closestBarycentric(p[q], a, b, c, &d2);
            if (d2 < bestD) bestD = d2, bestT = t, bestUV = uv;
        }
        if (bestT < 0) throw QueryRefused(q, "the bake has no triangles");
        const uint32_t s0 = L.sampleAt(bestT, 0, 0), s1 = L.sampleAt(bestT, r, 0),
                       s2 = L.sampleAt(bestT, 0, r);
        refuseOffSurface(q, p[q], w[q], std::sqrt(bestD), maxDistance, L.position[s0], L.position[s1],
                         L.position[s2], L.normal[s0] + L.normal[s1] + L.normal[s2]);
        const glm::vec3 omega = glm::normalize(w[q]);
        for (int j = 0; j <= r; ++j)
            for (int i = 0; i + j <= r; ++i) {
                uint32_t s = L.sampleAt(bestT, i, j);
                values[s] = foldedSample(bake, static_cast<int>(s), localViewDirection(L, s, omega));
            }
        glm::vec4 d = interpolateRho(L, values.data(), bestT, bestUV.x, bestUV.y);
        glm::vec3 e(d);
        float len = glm::length(e);
        out[q] = glm::vec4(len > 0 ? e / len : e, d.w);
    }
    return out;
}

}  // namespace shrefract
