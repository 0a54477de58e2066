// The Embree tracer of refracted paths (docs/design.md#path-rules, docs/bake.md "Path rules").
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/bakefile.h"
#include "common/direction_grid.h"
#include "common/scene.h"

struct RTCRayHit;  // embree3/rtcore_ray.h

namespace shrefract {

enum class Branch { Fresnel, Transmit };

struct TraceOptions {
    Branch branch = Branch::Fresnel;  // the larger Fresnel branch, or refract unless TIR
    int maxBounces = 32;              // hard cap; past half of it the transmitted branch wins
};

// What happened along one path; flags are OR-ed over its events.
enum PathFlags : uint32_t {
    kPathTIR = 1,               // total internal reflection at least once
    kPathCapped = 2,            // reached maxBounces: ended deterministically
    kPathReentered = 4,         // left the object and hit it again (ears, handles, knots)
    kPathGeometricNormal = 8,   // the shading normal put a ray on the wrong side: Ng used
    kPathLeaked = 16,           // escaped while still inside a medium (open mesh)
    kPathSoftCapped = 32,       // passed half the cap and was forced to transmit
};

struct PathResult {
    glm::vec3 exit{0.0f};  // direction that finally escapes, object space, unit
    float length = 0.0f;   // distance travelled inside non-air media
    uint32_t flags = 0;
    uint16_t bounces = 0;  // interfaces that deflected the ray after the first
    uint16_t rays = 0;     // Embree queries
};

// A ray as the tracer shot it, for the bare-Embree ceiling in the benchmark.
struct LoggedRay {
    glm::vec3 org, dir;
};

// The first surface a ray meets (Tracer::hit): the exact mesh, as the tracer sees it.
struct SurfaceHit {
    float t = 0.0f;        // ray parameter (distance for a unit direction)
    uint32_t part = 0;     // scene part = Embree geometry id
    uint32_t triangle = 0;
    glm::vec3 p{0.0f};     // barycentric point on the triangle (not org + t * dir)
    glm::vec3 ng{0.0f};    // unit geometric normal, outward (counter-clockwise winding)
    glm::vec3 ns{0.0f};    // interpolated vertex normal, normalized (ng if it vanishes)
};

class Tracer {
public:
    // Builds one Embree scene over all parts. Throws std::runtime_error on Embree errors.
    Tracer(const Scene& scene, TraceOptions options = {});
    ~Tracer();
    Tracer(const Tracer&) = delete;
    Tracer& operator=(const Tracer&) = delete;

    // The path entering part `part` at surface point `p` with outward shading normal `n`, along
    // the object-space direction `-omega` (omega points toward the viewer, n . omega > 0).
    // Rule 1: the first interface always transmits.
    // The scalar tracer: one rtcIntersect1 per segment. The reference traceCoherent is tested
    // against.
    PathResult trace(glm::vec3 p, glm::vec3 n, glm::vec3 omega, uint32_t part,
                     std::vector<LoggedRay>* log = nullptr) const;
    // The paths of one sample for `count` directions omegas[j] (object space), by the same rules
    // as trace(), traced path step by path step: segment k of every path still active goes to
    // Embree as one stream, the first (shared origin) as coherent packets of 16 consecutive
    // directions (give them in packetOrder), the later ones ray by ray, their triangles fetched
    // ahead. out[j] is omegas[j]'s path. The same exits as trace() to float tolerance.
    void traceCoherent(glm::vec3 p, glm::vec3 n, const glm::vec3* omegas, size_t count,
                       uint32_t part, PathResult* out) const;

    // A bare closest-hit query, nothing else: the ceiling the benchmark compares against.
    bool intersect(glm::vec3 org, glm::vec3 dir, float* t) const;
    // Closest hit with its surface: what a primary ray of the reference renderer sees.
    bool hit(glm::vec3 org, glm::vec3 dir, SurfaceHit* out) const;

    // Ray offsets scale with the scene: this times its bounding-box extent.
    float epsilon() const { return epsilon_; }
    const Scene& scene() const { return scene_; }

private:
    struct Embree;
    struct Path;  // one path in flight
    bool start(glm::vec3 p, glm::vec3 n, glm::vec3 omega, uint32_t part, Path* path) const;
    bool advance(Path* path, const ::RTCRayHit& rh) const;
    SurfaceHit surfaceAt(const ::RTCRayHit& rh) const;
    const Scene& scene_;
    TraceOptions options_;
    std::unique_ptr<Embree> rtc_;
    float epsilon_ = 1e-5f;
};

// The grid directions (index i * nPhi + k) in 4 x 4 tiles of (theta, phi): the order in which
// traceCoherent's 16-ray packets are compact cones.
std::vector<uint32_t> packetOrder(int nTheta, int nPhi);

// The paths of sample i of `layout` at every direction of `grid` in the sample's frame, in grid
// order (paths[j]: direction j's). Coherent: traceCoherent in packetOrder, as the bake traces a
// sample; otherwise trace(), one path at a time.
void traceSampleGrid(const Tracer& tracer, const SurfaceLayout& layout, size_t i,
                     const DirectionGrid& grid, bool coherent, PathResult* paths);

// Sets flush-to-zero and denormals-are-zero on the calling thread (every tracing thread).
void enableFlushToZero();

}  // namespace shrefract
