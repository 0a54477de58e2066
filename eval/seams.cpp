#include "eval/seams.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <glm/gtc/matrix_transform.hpp>

#include "common/decompress.h"

namespace shrefract {

namespace {

// Closest points of segments p0-p1 and q0-q1: parameters s, t in [0, 1] and their distance.
double segmentDistance(glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 q0, glm::dvec3 q1, double* s,
                       double* t) {
    const glm::dvec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    const double c = glm::dot(d1, r), b = glm::dot(d1, d2), denom = a * e - b * b;
    *s = denom > 1e-300 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    *t = e > 0 ? (b * *s + f) / e : 0.0;
    if (*t < 0) *t = 0, *s = a > 0 ? std::clamp(-c / a, 0.0, 1.0) : 0.0;
    if (*t > 1) *t = 1, *s = a > 0 ? std::clamp((b - c) / a, 0.0, 1.0) : 0.0;
    return glm::length((p0 + *s * d1) - (q0 + *t * d2));
}

}  // namespace

std::vector<PixelPair> seamPixelPairs(const Tracer& tracer, const SurfaceLayout& layout,
                                      const ReferenceView& view) {
    const int W = view.width, H = view.height;
    const glm::mat4 viewProjection =
        glm::perspective(glm::radians(view.fovDegrees), float(W) / float(H), 0.01f, 100.0f) *
        glm::lookAt(view.eye, view.target, view.up);
    // Window coordinates with row 0 at the top, pixel (x, y) covering [x, x+1] x [y, y+1].
    auto project = [&](glm::vec3 p, glm::dvec2* out) {
        const glm::vec4 c = viewProjection * glm::vec4(p, 1.0f);
        if (c.w <= 0) return false;
        *out = glm::dvec2((c.x / c.w * 0.5 + 0.5) * W, (0.5 - c.y / c.w * 0.5) * H);
        return true;
    };
    std::vector<int> tried(size_t(W) * H, 0);  // 0 not yet, 1 hit, -1 miss
    std::vector<glm::dvec3> hitPoint(size_t(W) * H);
    auto hit = [&](int x, int y, glm::dvec3* p) {
        const size_t i = size_t(y) * W + x;
        if (tried[i] == 0) {
            SurfaceHit h;
            tried[i] = tracer.hit(view.eye, primaryRay(view, x, y), &h) ? 1 : -1;
            hitPoint[i] = glm::dvec3(h.p);
        }
        *p = hitPoint[i];
        return tried[i] > 0;
    };
    std::set<std::pair<int, int>> pairs;
    for (const SeamEdge& e : smoothSeams(layout)) {
        glm::dvec2 s0, s1;
        if (!project(e.p0, &s0) || !project(e.p1, &s1)) continue;
        const int steps = std::max(1, int(std::ceil(glm::length(s1 - s0) * 4)));
        for (int k = 0; k <= steps; ++k) {
            const glm::dvec2 q = glm::mix(s0, s1, double(k) / steps);
            const int x = int(std::floor(q.x)), y = int(std::floor(q.y));
            // The pixel under the seam point and its neighbours across it, both ways.
            const int candidates[4][4] = {{x, y, x + 1, y}, {x - 1, y, x, y}, {x, y, x, y + 1}, {x, y - 1, x, y}};
            for (const auto& c : candidates) {
                if (std::min(c[0], c[2]) < 0 || std::max(c[0], c[2]) >= W || std::min(c[1], c[3]) < 0 ||
                    std::max(c[1], c[3]) >= H)
                    continue;
                glm::dvec3 ha, hb;
                if (!hit(c[0], c[1], &ha) || !hit(c[2], c[3], &hb)) continue;
                double s, t;
                const double d = segmentDistance(ha, hb, glm::dvec3(e.p0), glm::dvec3(e.p1), &s, &t);
                // The pair's chord crosses the seam edge inside, not at an end of it.
                if (d <= 0.25 * glm::length(hb - ha) && s > 0 && s < 1 && t > 0 && t < 1)
                    pairs.insert({c[1] * W + c[0], c[3] * W + c[2]});
            }
        }
    }
    std::vector<PixelPair> out;
    for (const auto& [a, b] : pairs) out.push_back({a, b});
    return out;
}

std::vector<double> pairJumps(const std::vector<float>& directions,
                              const std::vector<PixelPair>& pairs) {
    std::vector<double> jumps;
    for (const PixelPair& p : pairs) {
        const float* a = &directions[size_t(p.a) * 4];
        const float* b = &directions[size_t(p.b) * 4];
        if (!(a[3] > 0.5f) || !(b[3] > 0.5f)) continue;
        const glm::dvec3 u(a[0], a[1], a[2]), v(b[0], b[1], b[2]);
        const double lu = glm::length(u), lv = glm::length(v);
        if (!(lu > 0) || !(lv > 0)) continue;
        jumps.push_back(std::acos(std::clamp(glm::dot(u, v) / (lu * lv), -1.0, 1.0)) * 180.0 / M_PI);
    }
    return jumps;
}

nlohmann::json jumpStats(const std::vector<PixelPair>& pairs, std::vector<double> jumps) {
    nlohmann::json r = {{"pairs", pairs.size()}, {"count", jumps.size()}};
    if (jumps.empty()) return r;
    std::sort(jumps.begin(), jumps.end());
    double sum = 0;
    for (double j : jumps) sum += j;
    r["mean"] = sum / double(jumps.size());
    r["median"] = jumps[jumps.size() / 2];
    r["p95"] = jumps[std::min(jumps.size() - 1, jumps.size() * 95 / 100)];
    r["max"] = jumps.back();
    return r;
}

}  // namespace shrefract
