#include "bake/tracer.h"

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/frame.h"
#include "common/optics.h"

namespace shrefract {

void enableFlushToZero() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

// A triangle as a hit needs it: corners and vertex normals in one 72-byte record, so that a hit
// costs one or two cache lines instead of an index and six scattered vertex loads.
struct TriangleRecord {
    glm::vec3 p[3];
    glm::vec3 n[3];
};

struct Tracer::Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<std::vector<TriangleRecord>> triangles;  // [part][triangle]
    ~Embree() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

namespace {

void embreeError(void*, RTCError code, const char* str) {
    std::fprintf(stderr, "shrefract: Embree error %d: %s\n", int(code), str ? str : "");
}

// The media a ray is inside, by part index. Nested dielectrics: the medium in effect is the one
// of highest priority (ties: the most recently entered), as in production renderers.
struct MediaStack {
    static constexpr int kMax = 16;
    uint32_t part[kMax];
    int n = 0;

    bool contains(uint32_t p) const {
        for (int i = 0; i < n; ++i)
            if (part[i] == p) return true;
        return false;
    }
    void add(uint32_t p) {
        if (!contains(p) && n < kMax) part[n++] = p;
    }
    void remove(uint32_t p) {  // keeps the order of the others (ties: most recently entered)
        int kept = 0;
        for (int i = 0; i < n; ++i)
            if (part[i] != p) part[kept++] = part[i];
        n = kept;
    }
    // Index of the part in effect, or -1 for air.
    int top(const Scene& s) const {
        int best = -1;
        for (int i = 0; i < n; ++i)
            if (best < 0 || s.parts[part[i]].medium.priority >= s.parts[best].medium.priority)
                best = static_cast<int>(part[i]);
        return best;
    }
};

float iorOf(const Scene& s, int part) { return part < 0 ? 1.0f : float(s.parts[part].medium.ior); }

// A ray from org along dir, t in [0, inf), not yet traced.
RTCRayHit ray(glm::vec3 org, glm::vec3 dir) {
    RTCRayHit rh;
    rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
    rh.ray.dir_x = dir.x, rh.ray.dir_y = dir.y, rh.ray.dir_z = dir.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFF;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

// One closest-hit query from org along dir.
RTCRayHit closestHit(RTCScene scene, RTCIntersectContext* ctx, glm::vec3 org, glm::vec3 dir) {
    RTCRayHit rh = ray(org, dir);
    rtcIntersect1(scene, ctx, &rh);
    return rh;
}

// rays[0 .. count) in packets of 16 (rtcIntersect16), the answers written back.
void intersect16(RTCScene scene, RTCIntersectContext* ctx, RTCRayHit* rays, size_t count) {
    for (size_t first = 0; first < count; first += 16) {
        RTCRayHit16 packet;
        alignas(64) int valid[16];  // Embree reads the mask with aligned vector loads
        const size_t lanes = std::min<size_t>(16, count - first);
        for (size_t l = 0; l < 16; ++l) {
            const RTCRay& r = rays[first + (l < lanes ? l : 0)].ray;
            valid[l] = l < lanes ? -1 : 0;
            packet.ray.org_x[l] = r.org_x, packet.ray.org_y[l] = r.org_y, packet.ray.org_z[l] = r.org_z;
            packet.ray.dir_x[l] = r.dir_x, packet.ray.dir_y[l] = r.dir_y, packet.ray.dir_z[l] = r.dir_z;
            packet.ray.tnear[l] = r.tnear, packet.ray.tfar[l] = r.tfar, packet.ray.time[l] = r.time;
            packet.ray.mask[l] = r.mask, packet.ray.id[l] = r.id, packet.ray.flags[l] = r.flags;
            packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, scene, ctx, &packet);
        for (size_t l = 0; l < lanes; ++l) {
            RTCRayHit& rh = rays[first + l];
            rh.ray.tfar = packet.ray.tfar[l];
            rh.hit.geomID = packet.hit.geomID[l], rh.hit.primID = packet.hit.primID[l];
            rh.hit.u = packet.hit.u[l], rh.hit.v = packet.hit.v[l];
            rh.hit.Ng_x = packet.hit.Ng_x[l], rh.hit.Ng_y = packet.hit.Ng_y[l], rh.hit.Ng_z = packet.hit.Ng_z[l];
        }
    }
}

}  // namespace

Tracer::Tracer(const Scene& scene, TraceOptions options)
    : scene_(scene), options_(options), rtc_(std::make_unique<Embree>()) {
    rtc_->device = rtcNewDevice(nullptr);
    if (!rtc_->device) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtcSetDeviceErrorFunction(rtc_->device, embreeError, nullptr);
    rtc_->scene = rtcNewScene(rtc_->device);
    rtcSetSceneBuildQuality(rtc_->scene, RTC_BUILD_QUALITY_HIGH);
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const Part& p : scene.parts) {
        RTCGeometry g = rtcNewGeometry(rtc_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree reads 16 bytes at the last vertex: its buffers are padded by one float.
        float* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), p.mesh.positions.size() + 1));
        for (size_t i = 0; i < p.mesh.positions.size(); ++i) {
            glm::vec3 x = p.mesh.positions[i];
            v[3 * i] = x.x, v[3 * i + 1] = x.y, v[3 * i + 2] = x.z;
            lo = glm::min(lo, x), hi = glm::max(hi, x);
        }
        unsigned* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), p.mesh.triangles.size()));
        for (size_t t = 0; t < p.mesh.triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) idx[3 * t + k] = p.mesh.triangles[t][k];
        rtcCommitGeometry(g);
        rtcAttachGeometry(rtc_->scene, g);  // ids 0, 1, ... = part index
        std::vector<TriangleRecord>& records = rtc_->triangles.emplace_back(p.mesh.triangles.size());
        for (size_t t = 0; t < p.mesh.triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) {
                records[t].p[k] = p.mesh.positions[p.mesh.triangles[t][k]];
                records[t].n[k] = p.mesh.normals[p.mesh.triangles[t][k]];
            }
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(rtc_->scene);
    // Offsets scale with the scene: float spacing at the largest coordinate is ~6e-8 of it, so
    // 1e-5 of the extent clears self-intersection yet stays far below any feature we sample.
    float extent = std::max(glm::length(hi - lo), std::max(glm::length(hi), glm::length(lo)));
    epsilon_ = 1e-5f * std::max(extent, 1e-20f);
}

Tracer::~Tracer() = default;

bool Tracer::intersect(glm::vec3 org, glm::vec3 dir, float* t) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = closestHit(rtc_->scene, &ctx, org, dir);
    *t = rh.ray.tfar;
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

// The surface point and normals at an Embree hit, as trace() uses them.
SurfaceHit Tracer::surfaceAt(const ::RTCRayHit& rh) const {
    const TriangleRecord& tri = rtc_->triangles[rh.hit.geomID][rh.hit.primID];
    const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    SurfaceHit out;
    out.t = rh.ray.tfar;
    out.part = rh.hit.geomID;
    out.triangle = rh.hit.primID;
    // Barycentric, not org + t dir: the point lies on the triangle to float precision.
    out.p = w * tri.p[0] + u * tri.p[1] + v * tri.p[2];
    // Embree's Ng is the counter-clockwise (outward) normal, unnormalized.
    out.ng = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    glm::vec3 ns = w * tri.n[0] + u * tri.n[1] + v * tri.n[2];
    float len = glm::length(ns);
    out.ns = len > 0 ? ns / len : out.ng;
    return out;
}

bool Tracer::hit(glm::vec3 org, glm::vec3 dir, SurfaceHit* out) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = closestHit(rtc_->scene, &ctx, org, dir);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    *out = surfaceAt(rh);
    return true;
}

// One path in flight: where its next segment starts and what it has met so far.
struct Tracer::Path {
    glm::vec3 org, d;  // the next segment: origin (offset off the surface) and unit direction
    glm::vec3 from;    // the surface point that segment leaves: lengths are measured between
                       // true surface points, not from offset origins
    MediaStack media;
    PathResult res;
};

// Rule 1: the first interface transmits (the primary reflection is the runtime's). Returns false
// when the path has already ended (an "optically thinner than air" medium reflects at once).
bool Tracer::start(glm::vec3 p, glm::vec3 n, glm::vec3 omega, uint32_t part, Path* path) const {
    const Scene& s = scene_;
    path->res = PathResult{};
    path->media = MediaStack{};
    path->media.add(part);
    glm::vec3 d;
    if (!Refract(omega, n, iorOf(s, path->media.top(s)) / 1.0f, &d)) {
        path->res.exit = Reflect(omega, n);
        path->res.flags |= kPathTIR;
        return false;
    }
    path->org = p - n * epsilon_;
    path->d = d;
    path->from = p;
    return true;
}

// What the segment from path->org along path->d met (Embree's answer in `rh`): the interface
// event of rules 2-6. Returns false when the path has ended (path->res is then final).
bool Tracer::advance(Path* path, const ::RTCRayHit& rh) const {
    const Scene& s = scene_;
    const float eps = epsilon_;
    const int cap = options_.maxBounces;
    PathResult& res = path->res;
    MediaStack& media = path->media;
    glm::vec3& d = path->d;
    ++res.rays;

    const int before = media.top(s);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        // Rule 4: the direction that finally escapes to infinity.
        if (media.n > 0) res.flags |= kPathLeaked;
        res.exit = d;
        return false;
    }
    const SurfaceHit h = surfaceAt(rh);
    const uint32_t q = h.part;
    const glm::vec3 hitP = h.p, ng = h.ng, ns = h.ns;
    // Rule 6: length inside non-air media.
    if (before >= 0) res.length += glm::length(hitP - path->from);
    path->from = hitP;

    const bool entering = glm::dot(d, ng) < 0.0f;
    if (entering && media.n == 0) res.flags |= kPathReentered;  // it had left: rule 4
    MediaStack next = media;
    if (entering) next.add(q); else next.remove(q);
    const int after = next.top(s);

    if (after == before) {
        // A boundary inside a medium of higher priority: not an interface, go straight on.
        media = next;
        path->org = hitP + d * eps;
        return true;
    }
    // Normals facing the side the ray comes from.
    const glm::vec3 ngf = entering ? ng : -ng;
    glm::vec3 nf = entering ? ns : -ns;
    const glm::vec3 wi = -d;
    // Rule 3: a shading normal that faces away from the incoming ray cannot be used.
    if (glm::dot(nf, wi) <= 0.0f) {
        nf = ngf;
        res.flags |= kPathGeometricNormal;
    }
    const float eta = iorOf(s, after) / iorOf(s, before);
    glm::vec3 wt;
    bool canTransmit = Refract(wi, nf, eta, &wt);
    if (canTransmit && glm::dot(wt, ngf) >= 0.0f) {
        // Rule 3: refracted onto the wrong side of the true surface: redo about Ng.
        res.flags |= kPathGeometricNormal;
        nf = ngf;
        canTransmit = Refract(wi, nf, eta, &wt);
    }
    bool reflect;
    if (!canTransmit) {
        reflect = true;  // Rule 2: total internal reflection
        res.flags |= kPathTIR;
    } else if (options_.branch == Branch::Transmit) {
        reflect = false;
    } else {
        const bool larger = FresnelDielectric(glm::dot(wi, nf), eta) > 0.5f;
        // Rule 5: past half the cap, take the transmitted branch whenever it exists, so
        // every path ends deterministically.
        reflect = larger && res.bounces < cap / 2;  // else the larger branch
        if (larger && !reflect) res.flags |= kPathSoftCapped;
    }
    if (reflect) {
        d = Reflect(wi, nf);
        if (glm::dot(d, ngf) <= 0.0f) {
            res.flags |= kPathGeometricNormal;
            d = Reflect(wi, ngf);
        }
        path->org = hitP + ngf * eps;
    } else {
        d = wt;
        media = next;
        path->org = hitP - ngf * eps;
    }
    d = glm::normalize(d);
    ++res.bounces;
    if (res.bounces >= cap) {
        // Rule 5: the hard cap. The path ends here, along its current direction.
        res.flags |= kPathCapped;
        res.exit = d;
        return false;
    }
    return true;
}

PathResult Tracer::trace(glm::vec3 p, glm::vec3 n, glm::vec3 omega, uint32_t part,
                         std::vector<LoggedRay>* log) const {
    Path path;
    if (!start(p, n, omega, part, &path)) return path.res;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
        const RTCRayHit rh = closestHit(rtc_->scene, &ctx, path.org, path.d);
        if (log) log->push_back({path.org, path.d});
        if (!advance(&path, rh)) return path.res;
    }
}

void Tracer::traceCoherent(glm::vec3 p, glm::vec3 n, const glm::vec3* omegas, size_t count,
                           uint32_t part, PathResult* out) const {
    // Scratch per thread: the paths in flight and one Embree ray per active path.
    thread_local std::vector<Path> paths;
    thread_local std::vector<uint32_t> active;
    thread_local std::vector<RTCRayHit> rays;
    paths.resize(count);
    active.clear();
    for (size_t j = 0; j < count; ++j)
        if (start(p, n, omegas[j], part, &paths[j])) active.push_back(uint32_t(j));
        else out[j] = paths[j].res;

    RTCIntersectContext coherent, incoherent;
    rtcInitIntersectContext(&coherent);
    rtcInitIntersectContext(&incoherent);
    coherent.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    // Step by step: segment k of every path still active, as one stream.
    for (int step = 0; !active.empty(); ++step) {
        rays.resize(active.size());
        for (size_t a = 0; a < active.size(); ++a) rays[a] = ray(paths[active[a]].org, paths[active[a]].d);
        if (step == 0) {
            // The first segments share their origin: packets of 16 neighbouring directions, the
            // one step where Embree's coherent packet traversal beats single rays (measured
            // 1.3x on bunny00 with 4 x 4 tiles of the grid; after a bounce the packets diverge
            // and it is 0.4x single rays: docs/bake.md "Coherent tracing").
            intersect16(rtc_->scene, &coherent, rays.data(), rays.size());
        } else {
            for (RTCRayHit& r : rays) rtcIntersect1(rtc_->scene, &incoherent, &r);
        }
        size_t kept = 0;
        for (size_t a = 0; a < active.size(); ++a) {
            // The triangle record of a hit a few rays ahead, fetched while this event computes.
            constexpr size_t kAhead = 8;
            if (a + kAhead < rays.size() && rays[a + kAhead].hit.geomID != RTC_INVALID_GEOMETRY_ID) {
                const RTCRayHit& r = rays[a + kAhead];
                const char* record = reinterpret_cast<const char*>(&rtc_->triangles[r.hit.geomID][r.hit.primID]);
                __builtin_prefetch(record);
                __builtin_prefetch(record + 64);
            }
            const uint32_t j = active[a];
            if (advance(&paths[j], rays[a])) active[kept++] = j;
            else out[j] = paths[j].res;
        }
        active.resize(kept);
    }
}

std::vector<uint32_t> packetOrder(int nTheta, int nPhi) {
    std::vector<uint32_t> order;
    order.reserve(size_t(nTheta) * nPhi);
    for (int ti = 0; ti < nTheta; ti += 4)
        for (int tk = 0; tk < nPhi; tk += 4)
            for (int i = ti; i < std::min(ti + 4, nTheta); ++i)
                for (int k = tk; k < std::min(tk + 4, nPhi); ++k) order.push_back(uint32_t(i * nPhi + k));
    return order;
}

void traceSampleGrid(const Tracer& tracer, const SurfaceLayout& layout, size_t i,
                     const DirectionGrid& grid, bool coherent, PathResult* paths) {
    const Frame frame = Frame::fromNormal(layout.normal[i]);
    const glm::vec3 p = layout.position[i], n = layout.normal[i];
    const uint32_t part = layout.part[i];
    const int J = grid.count();
    if (!coherent) {
        for (int j = 0; j < J; ++j) paths[j] = tracer.trace(p, n, frame.fromLocal(glm::vec3(grid.direction(j))), part);
        return;
    }
    const std::vector<uint32_t> packet = packetOrder(grid.nTheta, grid.nPhi);
    std::vector<glm::vec3> omegas(J);
    std::vector<PathResult> traced(J);
    for (int q = 0; q < J; ++q) omegas[q] = frame.fromLocal(glm::vec3(grid.direction(int(packet[q]))));
    tracer.traceCoherent(p, n, omegas.data(), J, part, traced.data());
    for (int q = 0; q < J; ++q) paths[packet[q]] = traced[q];
}

}  // namespace shrefract
