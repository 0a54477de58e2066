// The ground-truth renderer (docs/design.md#evaluation): per pixel, the path the bake would trace,
// on the CPU with Embree, shaded exactly as the runtime shades (docs/evaluation.md "raytrace").
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "bake/tracer.h"
#include "common/bakefile.h"
#include "common/evalbuffer.h"
#include "common/latlong.h"

namespace shrefract {

// A pinhole camera, the runtime's Camera (runtime/include/shrefract/render.h) and projection:
// glm::lookAt(eye, target, up) and glm::perspective(fov, width / height), vertical fov.
struct ReferenceView {
    glm::vec3 eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
    float fovDegrees = 45.0f;
    int width = 0, height = 0;
    // Samples per pixel for the colour: 1 traces the pixel centre (as GL rasterizes); N > 1 takes
    // a stratified jittered pattern of ceil(sqrt N)^2 cells, N of them used (docs/evaluation.md).
    int spp = 1;
};

// The unit world direction through the centre of pixel (x, y), row 0 at the top: GL samples
// pixel centres (x + 0.5, y + 0.5) in window space with y up, and the runtime flips rows.
glm::vec3 primaryRay(const ReferenceView& view, int x, int y);
// The direction through the point (px, py) of the image plane in pixel units, (0, 0) the top-left
// corner of pixel (0, 0): primaryRay(v, x, y) is primaryRay(v, x + 0.5, y + 0.5).
glm::vec3 primaryRay(const ReferenceView& view, float px, float py);

// Sample s (0 <= s < spp) of pixel (x, y) as an offset in [0, 1)^2 inside the pixel: the cells of
// an n x n grid (n = ceil(sqrt spp)) in a fixed scrambled order, each jittered by a hash of
// (x, y, s). Deterministic, so references are reproducible.
glm::vec2 pixelSample(int x, int y, int s, int spp);

// The bake's path rules as recorded in its manifest (branch, maxBounces).
TraceOptions traceOptionsOfBake(const BakeData& bake);

// The environment as the reference looks it up: by default through the runtime's own cube map
// (the same faces, GL_LINEAR inside a face), else bilinearly in the lat-long image.
struct ReferenceEnvironment {
    LatLongImage latLong;
    CubeMapImage cube;
    bool viaCubeMap = true;
    explicit ReferenceEnvironment(LatLongImage image, bool viaCubeMap = true, int faceSize = 0);
    glm::vec3 operator()(glm::vec3 d) const {
        return viaCubeMap ? sampleCube(cube, d) : sampleLatLong(latLong, glm::normalize(d));
    }
};

struct ReferenceStats {
    double milliseconds = 0;  // wall time of the whole frame
    size_t covered = 0;       // pixels whose primary ray hit the object
    size_t tir = 0, capped = 0, reentered = 0, geometricNormal = 0, backFacing = 0;
};

// Where the renderer takes the exit of the path that enters at p (entry normal n, omega toward
// the viewer, into part `part`): by default the traced path itself. Another source may return what
// a direction representation fitted at that very point says instead (eval/pixel_fit.h).
class ExitSource {
public:
    virtual ~ExitSource() = default;
    virtual PathResult exit(const Tracer& tracer, glm::vec3 p, glm::vec3 n, glm::vec3 omega,
                            int part) const = 0;
};

// Renders one frame, object at the origin (identity model, as shrefract-render). With spp > 1
// the colour is the mean over the pixel's samples (background samples included: anti-aliased
// silhouettes); the direction buffer and coverage stay those of the pixel centre, so angular
// error is always measured against the 1-sample truth. Per sample:
//   primary ray -> first hit (part q, exact mesh) -> n = interpolated shading normal
//   colour = F * env(reflect) + (1 - F) * env(exit) * exp(-kappa_q * length)
// with F = FresnelDielectric(n . omega, ior_q), exit and length from tracer.trace(hit, n, omega,
// q) (omega = -ray direction; if n faces away from the viewer the geometric normal enters
// instead, as rule 3 does later on the path), env = ReferenceEnvironment. Background pixels
// show env(ray), coverage 0. Tiles of 16x16 pixels in parallel (TBB). `exits`: where exit and
// length come from instead of tracer.trace (null: the trace; the flags stay the traced path's).
EvalBuffer renderReference(const Tracer& tracer, const ReferenceEnvironment& environment,
                           const ReferenceView& view, ReferenceStats* stats = nullptr,
                           const ExitSource* exits = nullptr);

// Dispersion: colour channel c of buffer c, the coverage and direction buffer of `green` (the
// middle channel). How the reference renders one index per RGB channel (three renders, each
// with the scene at that channel's index), and how three grey renders become one dispersive one.
EvalBuffer composeChannels(const EvalBuffer& red, const EvalBuffer& green, const EvalBuffer& blue);

// The dispersion reference: the scene's first part (the object of a bare mesh) at `ior[c]` for
// colour channel c, one render per distinct index, composed by composeChannels. `stats`: the
// green channel's render.
EvalBuffer renderDispersed(const Scene& scene, const TraceOptions& options,
                           const ReferenceEnvironment& environment, const ReferenceView& view,
                           glm::vec3 ior, ReferenceStats* stats = nullptr);

// d_N of Wyman 2005 per point: the distance from p along the inward normal -n to the next
// surface of the scene (0 if none), measured between true surface points. Parallel.
std::vector<float> normalDistances(const Tracer& tracer, const std::vector<glm::vec3>& p,
                                   const std::vector<glm::vec3>& n);
// d_N at the points a renderer draws the layout's mesh with (common/bakefile.h drawPoints): what
// shrefract::Baseline takes.
std::vector<float> normalDistances(const Tracer& tracer, const SurfaceLayout& layout);

}  // namespace shrefract
