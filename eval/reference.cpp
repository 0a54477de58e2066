#include "eval/reference.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "common/optics.h"

namespace shrefract {

glm::vec3 primaryRay(const ReferenceView& view, int x, int y) {
    return primaryRay(view, x + 0.5f, y + 0.5f);
}

glm::vec3 primaryRay(const ReferenceView& view, float px, float py) {
    // glm::lookAt's basis: f forward, s right, u up (right-handed, camera looks down -z).
    const glm::vec3 f = glm::normalize(view.target - view.eye);
    const glm::vec3 s = glm::normalize(glm::cross(f, view.up));
    const glm::vec3 u = glm::cross(s, f);
    // glm::perspective: ndc = (x_cam / (aspect tan(fov/2)), y_cam / tan(fov/2)) / -z_cam.
    const float tanHalf = std::tan(glm::radians(view.fovDegrees) * 0.5f);
    const float aspect = float(view.width) / float(view.height);
    const float ndcX = px / view.width * 2.0f - 1.0f;
    const float ndcY = 1.0f - py / view.height * 2.0f;  // row 0 = top
    return glm::normalize(f + (ndcX * tanHalf * aspect) * s + (ndcY * tanHalf) * u);
}

TraceOptions traceOptionsOfBake(const BakeData& bake) {
    TraceOptions t;
    const auto& m = bake.manifest;
    if (m.is_object()) {
        t.branch = m.value("branch", std::string("fresnel")) == "transmit" ? Branch::Transmit
                                                                           : Branch::Fresnel;
        t.maxBounces = m.value("maxBounces", 32);
    }
    return t;
}

ReferenceEnvironment::ReferenceEnvironment(LatLongImage image, bool cubeMap, int faceSize)
    : latLong(std::move(image)), viaCubeMap(cubeMap) {
    if (viaCubeMap) cube = cubeFromLatLong(latLong, faceSize);
}

namespace {

// splitmix64: a well-mixed 64-bit hash for the jitter (not a source of randomness to rely on).
uint64_t mix(uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
float unitFloat(uint64_t h) { return float(h >> 40) * (1.0f / 16777216.0f); }  // [0, 1)

// What one primary ray sees.
struct RaySample {
    glm::vec3 color{0.0f};
    glm::vec3 exit{0.0f};
    bool covered = false;
    uint32_t flags = 0;
    bool geometricEntry = false, backFacing = false;
};

RaySample traceRay(const Tracer& tracer, const ReferenceEnvironment& env, glm::vec3 eye, glm::vec3 d,
                   const ExitSource* exits) {
    RaySample out;
    SurfaceHit h;
    if (!tracer.hit(eye, d, &h)) {
        out.color = env(d);
        return out;
    }
    out.covered = true;
    const glm::vec3 omega = -d;
    const Medium& medium = tracer.scene().parts[h.part].medium;
    // A back face first (open mesh, camera inside): trace as if entering it.
    glm::vec3 ng = h.ng, ns = h.ns;
    if (glm::dot(ng, omega) < 0.0f) ng = -ng, ns = -ns, out.backFacing = true;
    // Entry normal: the shading normal unless it faces away (then rule 3).
    glm::vec3 n = ns;
    if (glm::dot(n, omega) <= 0.0f) n = ng, out.geometricEntry = true;
    PathResult r = tracer.trace(h.p, n, omega, h.part);
    out.flags = r.flags;
    if (exits) r = exits->exit(tracer, h.p, n, omega, h.part);
    // The runtime's shading (shaders/shade.frag), with its interpolated normal for the Fresnel
    // term and the reflection.
    const float eta = static_cast<float>(medium.ior);
    const float F = FresnelDielectric(glm::dot(ns, omega), eta);
    const glm::vec3 kappa(medium.absorption);
    const glm::vec3 transmitted = env(r.exit) * glm::exp(-kappa * std::max(r.length, 0.0f));
    const glm::vec3 reflected = env(Reflect(omega, ns));
    out.color = F * reflected + (1.0f - F) * transmitted;
    out.exit = r.exit;
    return out;
}

}  // namespace

glm::vec2 pixelSample(int x, int y, int s, int spp) {
    int n = 1;
    while (n * n < spp) ++n;
    // The cells in a scrambled order, so that spp < n^2 still spreads over the pixel.
    const uint64_t seed = mix((uint64_t(uint32_t(x)) << 32) ^ uint32_t(y));
    const int cells = n * n;
    const int cell = int((uint64_t(s) * 7919u + (seed % uint64_t(cells))) % uint64_t(cells));
    const uint64_t h = mix(seed ^ (uint64_t(s) * 0x632be59bd9b4e019ull));
    const float jx = unitFloat(h), jy = unitFloat(mix(h));
    return {(cell % n + jx) / n, (cell / n + jy) / n};
}

EvalBuffer renderReference(const Tracer& tracer, const ReferenceEnvironment& env,
                           const ReferenceView& view, ReferenceStats* stats, const ExitSource* exits) {
    const auto start = std::chrono::steady_clock::now();
    EvalBuffer out;
    out.width = view.width;
    out.height = view.height;
    out.color.assign(out.pixelCount(), glm::vec4(0.0f));
    out.direction.assign(out.pixelCount(), glm::vec3(0.0f));
    std::atomic<size_t> covered{0}, tir{0}, capped{0}, reentered{0}, geometric{0}, back{0};
    const int spp = std::max(1, view.spp);

    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, view.height, 16, 0, view.width, 16),
        [&](const tbb::blocked_range2d<int>& tile) {
            enableFlushToZero();
            size_t nCovered = 0, nTir = 0, nCapped = 0, nRe = 0, nGeo = 0, nBack = 0;
            for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                    const size_t i = static_cast<size_t>(y) * view.width + x;
                    // The pixel centre: direction buffer, coverage and the path statistics.
                    const RaySample c = traceRay(tracer, env, view.eye, primaryRay(view, x, y), exits);
                    glm::vec3 color = c.color;
                    if (spp > 1) {
                        color = glm::vec3(0.0f);
                        for (int s = 0; s < spp; ++s) {
                            const glm::vec2 o = pixelSample(x, y, s, spp);
                            color += traceRay(tracer, env, view.eye,
                                              primaryRay(view, x + o.x, y + o.y), exits).color;
                        }
                        color /= float(spp);
                    }
                    out.color[i] = glm::vec4(color, c.covered ? 1.0f : 0.0f);
                    out.direction[i] = c.exit;
                    if (!c.covered) continue;
                    ++nCovered;
                    nBack += c.backFacing;
                    nGeo += c.geometricEntry;
                    nTir += (c.flags & kPathTIR) != 0;
                    nCapped += (c.flags & kPathCapped) != 0;
                    nRe += (c.flags & kPathReentered) != 0;
                    nGeo += (c.flags & kPathGeometricNormal) != 0;
                }
            covered += nCovered, tir += nTir, capped += nCapped, reentered += nRe;
            geometric += nGeo, back += nBack;
        });
    if (stats) {
        stats->milliseconds = std::chrono::duration<double, std::milli>(
                                  std::chrono::steady_clock::now() - start)
                                  .count();
        stats->covered = covered, stats->tir = tir, stats->capped = capped;
        stats->reentered = reentered, stats->geometricNormal = geometric, stats->backFacing = back;
    }
    return out;
}

EvalBuffer composeChannels(const EvalBuffer& red, const EvalBuffer& green, const EvalBuffer& blue) {
    if (red.width != green.width || red.height != green.height || blue.width != green.width ||
        blue.height != green.height)
        throw std::invalid_argument("composeChannels: the three buffers differ in size");
    EvalBuffer out = green;
    for (size_t i = 0; i < out.pixelCount(); ++i) {
        out.color[i].r = red.color[i].r;
        out.color[i].b = blue.color[i].b;
    }
    return out;
}

EvalBuffer renderDispersed(const Scene& scene, const TraceOptions& options,
                           const ReferenceEnvironment& environment, const ReferenceView& view,
                           glm::vec3 ior, ReferenceStats* stats) {
    if (scene.parts.empty()) throw std::invalid_argument("renderDispersed: the scene has no part");
    EvalBuffer channel[3];
    for (int c = 0; c < 3; ++c) {
        if (c > 0 && ior[c] == ior[c - 1]) {
            channel[c] = channel[c - 1];
            continue;
        }
        Scene atIndex = scene;
        atIndex.parts[0].medium.ior = ior[c];
        const Tracer tracer(atIndex, options);
        ReferenceStats st;
        channel[c] = renderReference(tracer, environment, view, &st);
        if (stats && (c == 1 || stats->covered == 0)) *stats = st;
    }
    return composeChannels(channel[0], channel[1], channel[2]);
}

std::vector<float> normalDistances(const Tracer& tracer, const std::vector<glm::vec3>& p,
                                   const std::vector<glm::vec3>& n) {
    std::vector<float> d(p.size(), 0.0f);
    const float eps = tracer.epsilon();
    tbb::parallel_for(size_t(0), p.size(), [&](size_t i) {
        enableFlushToZero();
        const glm::vec3 dir = -glm::normalize(n[i]);
        SurfaceHit h;
        if (tracer.hit(p[i] + dir * eps, dir, &h)) d[i] = glm::length(h.p - p[i]);
    });
    return d;
}

std::vector<float> normalDistances(const Tracer& tracer, const SurfaceLayout& layout) {
    std::vector<glm::vec3> p, n;
    drawPoints(layout, &p, &n);
    return normalDistances(tracer, p, n);
}

}  // namespace shrefract
