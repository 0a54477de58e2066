#include "eval/reference.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>

#include "common/optics.h"

namespace shrefract {

glm::vec3 primaryRay(const ReferenceView& view, int x, int y) {
    // glm::lookAt's basis: f forward, s right, u up (right-handed, camera looks down -z).
    const glm::vec3 f = glm::normalize(view.target - view.eye);
    const glm::vec3 s = glm::normalize(glm::cross(f, view.up));
    const glm::vec3 u = glm::cross(s, f);
    // glm::perspective: ndc = (x_cam / (aspect tan(fov/2)), y_cam / tan(fov/2)) / -z_cam.
    const float tanHalf = std::tan(glm::radians(view.fovDegrees) * 0.5f);
    const float aspect = float(view.width) / float(view.height);
    const float ndcX = (x + 0.5f) / view.width * 2.0f - 1.0f;
    const float ndcY = 1.0f - (y + 0.5f) / view.height * 2.0f;  // row 0 = top
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

EvalBuffer renderReference(const Tracer& tracer, const ReferenceEnvironment& env,
                           const ReferenceView& view, ReferenceStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    EvalBuffer out;
    out.width = view.width;
    out.height = view.height;
    out.color.assign(out.pixelCount(), glm::vec4(0.0f));
    out.direction.assign(out.pixelCount(), glm::vec3(0.0f));
    std::atomic<size_t> covered{0}, tir{0}, capped{0}, reentered{0}, geometric{0}, back{0};
    const Scene& scene = tracer.scene();

    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, view.height, 16, 0, view.width, 16),
        [&](const tbb::blocked_range2d<int>& tile) {
            enableFlushToZero();
            size_t nCovered = 0, nTir = 0, nCapped = 0, nRe = 0, nGeo = 0, nBack = 0;
            for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                    const size_t i = static_cast<size_t>(y) * view.width + x;
                    const glm::vec3 d = primaryRay(view, x, y);
                    SurfaceHit h;
                    if (!tracer.hit(view.eye, d, &h)) {
                        out.color[i] = glm::vec4(env(d), 0.0f);
                        continue;
                    }
                    ++nCovered;
                    const glm::vec3 omega = -d;
                    const Medium& medium = scene.parts[h.part].medium;
                    // A back face first (open mesh, camera inside): trace as if entering it.
                    glm::vec3 ng = h.ng, ns = h.ns;
                    if (glm::dot(ng, omega) < 0.0f) ng = -ng, ns = -ns, ++nBack;
                    // Entry normal: the shading normal unless it faces away (then rule 3).
                    glm::vec3 n = ns;
                    if (glm::dot(n, omega) <= 0.0f) n = ng, ++nGeo;
                    const PathResult r = tracer.trace(h.p, n, omega, h.part);
                    nTir += (r.flags & kPathTIR) != 0;
                    nCapped += (r.flags & kPathCapped) != 0;
                    nRe += (r.flags & kPathReentered) != 0;
                    nGeo += (r.flags & kPathGeometricNormal) != 0;
                    // The runtime's shading (shaders/shade.frag), with its
                    // interpolated normal for the Fresnel term and the reflection.
                    const float eta = static_cast<float>(medium.ior);
                    const float F = FresnelDielectric(glm::dot(ns, omega), eta);
                    const glm::vec3 kappa(medium.absorption);
                    const glm::vec3 transmitted =
                        env(r.exit) * glm::exp(-kappa * std::max(r.length, 0.0f));
                    const glm::vec3 reflected = env(Reflect(omega, ns));
                    out.color[i] = glm::vec4(F * reflected + (1.0f - F) * transmitted, 1.0f);
                    out.direction[i] = r.exit;
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

}  // namespace shrefract
