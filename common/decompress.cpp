#include "common/decompress.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "common/error.h"
#include "common/frame.h"
#include "common/limits.h"
#include "common/prefilter.h"
#include "common/sh.h"

namespace shrefract {

glm::vec3 localViewDirection(const SurfaceLayout& layout, int i, glm::vec3 omega) {
    return Frame::fromNormal(layout.normal[i]).toLocal(omega);
}

glm::vec3 localViewFromEye(const SurfaceLayout& layout, int i, glm::vec3 eye) {
    return localViewDirection(layout, i, glm::normalize(eye - layout.position[i]));
}

glm::vec4 decompressSample(const BakeData& bake, int i, glm::vec3 wLocal, int order) {
    const size_t n = bake.layout.position.size();
    if (bake.basis == Basis::Grid) {
        int index[4];
        double weight[4];
        const int count = bake.grid.interpolate(glm::dvec3(glm::normalize(wLocal)), index, weight);
        glm::vec4 d(0.0f);
        for (int c = 0; c < count; ++c) {
            const float* w = &bake.weights[(index[c] * n + i) * 4];
            d += float(weight[c]) * glm::vec4(w[0], w[1], w[2], w[3]);
        }
        return d;
    }
    int L = (order < 0 || order > bake.order) ? bake.order : order;
    int K = shEvenCount(L);
    float basis[512];
    SHREFRACT_CHECK(K <= 512);
    // Below the tangent plane the mirrored function is meant: the stored functions are all
    // even in z, so evaluating at (x, y, z) or (x, y, -z) is the same.
    shEvalEven(L, glm::normalize(wLocal), basis);
    glm::vec4 d(0.0f);
    for (int k = 0; k < K; ++k) {
        const float* w = &bake.weights[(k * n + i) * 4];
        d += basis[k] * glm::vec4(w[0], w[1], w[2], w[3]);
    }
    return d;
}

float predictedError(const BakeData& bake, int i, glm::vec3 wLocal) {
    if (bake.errorOrder < 0) return -1.0f;
    const int Ke = bake.errorCoefficientCount();
    float basis[shEvenCount(limits::kMaxErrorOrder)];
    SHREFRACT_CHECK(Ke <= shEvenCount(limits::kMaxErrorOrder));
    shEvalEven(bake.errorOrder, glm::normalize(wLocal), basis);
    const size_t n = bake.layout.position.size();
    float e = 0.0f;
    for (int k = 0; k < Ke; ++k) e += basis[k] * bake.errors[k * n + i];
    return std::max(std::exp(e) - kErrorOffset, 0.0f);
}

glm::vec4 foldedSample(const BakeData& bake, int i, glm::vec3 wLocal) {
    glm::vec4 d = decompressSample(bake, i, wLocal);
    if (bake.errorOrder < 0) return d;
    const float len = glm::length(glm::vec3(d));
    const glm::vec3 dir = len > 1e-10f ? glm::vec3(d) / len : glm::vec3(0.0f);
    return glm::vec4(dir * resultantOfSigma(predictedError(bake, i, wLocal)), d.w);
}

glm::vec4 interpolateRho(const SurfaceLayout& layout, const glm::vec4* values, int t, float u,
                         float v) {
    const int r = layout.rate;
    float s = u * r, q = v * r;
    int i = std::clamp(static_cast<int>(std::floor(s)), 0, r - 1);
    int j = std::clamp(static_cast<int>(std::floor(q)), 0, r - 1 - i);
    float a = s - i, b = q - j;
    glm::vec4 v00 = values[layout.sampleAt(t, i, j)];
    glm::vec4 v10 = values[layout.sampleAt(t, i + 1, j)];
    glm::vec4 v01 = values[layout.sampleAt(t, i, j + 1)];
    // v11 = v01 + v10 - v00 past the hypotenuse: bilinear equals barycentric on this half-cell.
    glm::vec4 v11 = (i + j + 2 <= r) ? values[layout.sampleAt(t, i + 1, j + 1)] : v10 + v01 - v00;
    return (1 - a) * (1 - b) * v00 + a * (1 - b) * v10 + (1 - a) * b * v01 + a * b * v11;
}

std::vector<uint8_t> gutterRings(const SurfaceLayout& layout, int width) {
    const int W = layout.muWidth, H = layout.muHeight;
    std::vector<uint8_t> ring(size_t(W) * H, kNoRing);
    std::vector<size_t> front;
    for (int i = 0; i < layout.sampleCount(); ++i) {
        const glm::ivec2 t = layout.muTexel(i);
        ring[size_t(t.y) * W + t.x] = 0;
        front.push_back(size_t(t.y) * W + t.x);
    }
    for (int k = 1; k <= std::min(width, int(kNoRing) - 1); ++k) {
        std::vector<size_t> next;
        for (size_t x : front) {
            const int tx = int(x % size_t(W)), ty = int(x / size_t(W));
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = tx + dx, ny = ty + dy;
                    if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                    uint8_t& r = ring[size_t(ny) * W + nx];
                    if (r != kNoRing) continue;
                    r = uint8_t(k);
                    next.push_back(size_t(ny) * W + nx);
                }
        }
        front.swap(next);
    }
    return ring;
}

std::vector<glm::vec4> chartRefractionMap(const SurfaceLayout& layout, const glm::vec4* values,
                                          const ChartMapOptions& options) {
    SHREFRACT_CHECK(layout.isChartLayout());
    const int W = layout.muWidth, H = layout.muHeight;
    const std::vector<uint8_t> ring = gutterRings(layout, options.dilation);
    std::vector<glm::vec4> map(size_t(W) * H, glm::vec4(0.0f));
    for (int i = 0; i < layout.sampleCount(); ++i) {
        const glm::ivec2 t = layout.muTexel(i);
        map[size_t(t.y) * W + t.x] = values[i];
    }
    // Ring k: the mean of the 8-neighbours of rings below k, which are final already.
    for (int k = 1; k <= options.dilation; ++k)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (ring[size_t(y) * W + x] != k) continue;
                glm::vec4 sum(0.0f);
                float n = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                        if (ring[size_t(ny) * W + nx] >= k) continue;
                        sum += map[size_t(ny) * W + nx];
                        n += 1;
                    }
                map[size_t(y) * W + x] = sum / n;
            }
    if (options.seamAware) {
        for (const SeamSource& s : layout.atlas.seam) {
            const uint8_t r = ring[s.texel];
            if (r == 0 || r == kNoRing) continue;
            glm::vec4 v(0.0f);
            for (int k = 0; k < 4; ++k)
                if (s.weight[k] != 0.0f) v += s.weight[k] * values[s.sample[k]];
            map[s.texel] = v;
        }
    }
    if (!options.smoothing) return map;
    // 3 x 3 binomial (1 2 1) x (1 2 1) over the filled texels, normalized.
    std::vector<glm::vec4> smooth(map.size(), glm::vec4(0.0f));
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (ring[size_t(y) * W + x] == kNoRing) continue;
            glm::vec4 sum(0.0f);
            float weight = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= W || ny >= H || ring[size_t(ny) * W + nx] == kNoRing)
                        continue;
                    const float w = float((2 - std::abs(dx)) * (2 - std::abs(dy)));
                    sum += w * map[size_t(ny) * W + nx];
                    weight += w;
                }
            smooth[size_t(y) * W + x] = sum / weight;
        }
    return smooth;
}

glm::vec4 sampleBilinear(const std::vector<glm::vec4>& image, int width, int height, glm::vec2 uv) {
    const float fx = uv.x * width - 0.5f, fy = uv.y * height - 0.5f;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    const float a = fx - x0, b = fy - y0;
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, width - 1), y = std::clamp(y, 0, height - 1);
        return image[size_t(y) * width + x];
    };
    return (1 - a) * (1 - b) * at(x0, y0) + a * (1 - b) * at(x0 + 1, y0) +
           (1 - a) * b * at(x0, y0 + 1) + a * b * at(x0 + 1, y0 + 1);
}

std::vector<SeamEdge> smoothSeams(const SurfaceLayout& layout) {
    const ChartAtlas& A = layout.atlas;
    // Edges of the unfolded mesh by their vertices: those used once are on a chart's outline.
    std::map<std::pair<uint32_t, uint32_t>, int> use;
    for (const glm::uvec3& t : A.triangles)
        for (int k = 0; k < 3; ++k) use[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}]++;
    // Outline edges by their surface points, to find the other side of each.
    using Key = std::tuple<float, float, float, float, float, float>;
    std::map<Key, std::pair<uint32_t, uint32_t>> outline;
    auto key = [&](uint32_t a, uint32_t b) {
        const glm::vec3 p = A.vertexPosition[a], q = A.vertexPosition[b];
        return Key{p.x, p.y, p.z, q.x, q.y, q.z};
    };
    for (const glm::uvec3& t : A.triangles)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = t[k], b = t[(k + 1) % 3];
            if (use[{std::min(a, b), std::max(a, b)}] == 1) outline[key(a, b)] = {a, b};
        }
    std::vector<SeamEdge> seams;
    for (const auto& [k, e] : outline) {
        auto other = outline.find(key(e.second, e.first));  // the other side runs the other way
        if (other == outline.end() || !(k < other->first)) continue;
        const uint32_t a0 = e.first, a1 = e.second, b0 = other->second.second, b1 = other->second.first;
        const bool smooth = glm::dot(A.vertexNormal[a0], A.vertexNormal[b0]) > 0.9999f &&
                            glm::dot(A.vertexNormal[a1], A.vertexNormal[b1]) > 0.9999f;
        if (!smooth) continue;
        seams.push_back({A.vertexUV[a0], A.vertexUV[a1], A.vertexUV[b0], A.vertexUV[b1],
                         A.vertexPosition[a0], A.vertexPosition[a1]});
    }
    return seams;
}

std::vector<double> seamJumps(const SurfaceLayout& layout, const std::vector<glm::vec4>& map,
                              int steps) {
    std::vector<double> jumps;
    for (const SeamEdge& e : smoothSeams(layout))
        for (int s = 0; s < steps; ++s) {
            const float t = (float(s) + 0.5f) / float(steps);
            const glm::vec3 a(sampleBilinear(map, layout.muWidth, layout.muHeight, glm::mix(e.a0, e.a1, t)));
            const glm::vec3 b(sampleBilinear(map, layout.muWidth, layout.muHeight, glm::mix(e.b0, e.b1, t)));
            const double la = glm::length(a), lb = glm::length(b);
            if (!(la > 0) || !(lb > 0)) {
                jumps.push_back(180.0);  // one side has no direction at all
                continue;
            }
            const double c = std::clamp(double(glm::dot(a, b)) / (la * lb), -1.0, 1.0);
            jumps.push_back(std::acos(c) * 180.0 / M_PI);
        }
    return jumps;
}

}  // namespace shrefract
