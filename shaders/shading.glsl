// The shading every method shares (included by shade.frag, baseline.frag, background.frag), so
// SH, the baselines and the background differ only in the exit direction, its spread and the
// length they pass in. Twins: common/optics.h (Fresnel), common/tonemap.h (tone map),
// common/prefilter.h (lobe widths and levels).

// The environment: a cube map whose mip level l >= 1 is the sharp level 0 convolved with a vMF
// lobe sigma_l = (pi / faceSize) 2^(l - 1) radians wide (common/prefilter.h, uploaded by
// runtime/src/environment.cpp; every program using this library sets these three).
uniform samplerCube uEnvironment;
uniform float uEnvironmentFaceSize;  // of level 0
uniform float uEnvironmentLevels;    // mip levels present (1: sharp only)

// common/prefilter.h lodForSigma: the level whose lobe is sigma wide.
float environmentLod(float sigma) {
    float s1 = 3.14159265 / uEnvironmentFaceSize;
    float lod = sigma <= s1 ? sigma / s1 : 1.0 + log2(sigma / s1);
    return clamp(lod, 0.0, uEnvironmentLevels - 1.0);
}

// The environment along d, averaged over a lobe of width sigma (0: the sharp lookup).
vec3 environment(vec3 d, float sigma) {
    return textureLod(uEnvironment, d, environmentLod(sigma)).rgb;
}

// common/prefilter.h spreadSigma: the width (radians) of the vMF lobe whose mean resultant
// length is r (the length of the SH reconstruction of a unit exit direction), times scale.
float spreadSigma(float r, float scale) {
    r = clamp(r, 1e-4, 1.0);
    if (r >= 1.0) return 0.0;
    float kappa = r * (3.0 - r * r) / (1.0 - r * r);
    return scale * inversesqrt(kappa);
}

// How far (radians) the unit direction d turns across one pixel, times scale: the part of the
// pixel's footprint a single lookup would alias.
float footprintSigma(vec3 d, float scale) {
    return scale * max(length(dFdx(d)), length(dFdy(d)));
}

// A direction drawn from the lobe of width sigma (radians) around the unit d: a 2D Gaussian
// offset in d's tangent plane, its two numbers hashed from the integer cell (PCG-style integer
// hash; the same cell gives the same direction in every frame).
uvec3 pcg3(uvec3 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    return v;
}
vec3 lobeDirection(vec3 d, float sigma, vec3 cell) {
    if (sigma <= 0.0) return d;
    vec3 h = vec3(pcg3(uvec3(ivec3(cell)))) / 4294967296.0;
    float radius = sigma * sqrt(-2.0 * log(max(h.x, 1e-7)));
    float angle = 6.28318531 * h.y;
    vec3 t = normalize(abs(d.z) < 0.9 ? cross(d, vec3(0, 0, 1)) : cross(d, vec3(1, 0, 0)));
    vec3 b = cross(d, t);
    return normalize(d + radius * (cos(angle) * t + sin(angle) * b));
}

// Where the transmitted light is looked up (docs/runtime.md "Shading where the bake is unsure"):
// the exit e and the lobe the bake leaves around it, `spread` radians wide. Jitter (jitterCell >
// 0): one direction drawn from the lobe, seeded by the object-space cell of objectPosition, looked
// up over the pixel's footprint; otherwise the lobe's mean, the lobe widened by the footprint in
// quadrature. .xyz the direction, .w the width of its lookup.
//
// Jitter is gated by the lobe's width (jitterGate > 0, docs/runtime.md "The gate"): where the bake
// is sure (spread below kGateOpens x jitterGate, g = 0) the draw is kSureDraw of the lobe and the
// lookup the drawn direction's footprint; where it is unsure (spread >= jitterGate, g = 1) the draw
// is kUnsureDraw of the lobe and the lookup at least kExitFootprint of a pixel's turn of the exit,
// which antialiases a chaotic mapping as the reference's pixel does; g rises linearly between.
// jitterGate 0: the ungated jitter (the draw is the lobe).
const float kGateOpens = 0.6;
const float kSureDraw = 0.333;      // at spread scale 0.15: 0.05 of the predicted error where g = 0
const float kUnsureDraw = 2.0;      // and 0.3 of it where g = 1
const float kExitFootprint = 0.4;   // a pixel box's standard deviation is 0.29 of its width
vec4 transmissionLookup(vec3 e, float spread, float footprintScale, float jitterCell,
                        float jitterGate, vec3 objectPosition) {
    if (jitterCell > 0.0) {
        float g = 0.0, draw = 1.0;  // ungated: the lobe itself, the drawn direction's footprint
        if (jitterGate > 0.0) {
            g = clamp((spread / jitterGate - kGateOpens) / (1.0 - kGateOpens), 0.0, 1.0);
            draw = mix(kSureDraw, kUnsureDraw, g);
        }
        vec3 d = lobeDirection(e, spread * draw, floor(objectPosition / jitterCell));
        return vec4(d, max(footprintSigma(d, footprintScale),
                           footprintSigma(e, kExitFootprint * g)));
    }
    float footprint = footprintSigma(e, footprintScale);
    return vec4(e, sqrt(spread * spread + footprint * footprint));
}

// common/optics.h FresnelDielectric: unpolarized, eta = n_t / n_i, 1 on TIR.
float fresnelDielectric(float cosI, float eta) {
    cosI = clamp(cosI, 0.0, 1.0);
    float sin2T = (1.0 - cosI * cosI) / (eta * eta);
    if (sin2T >= 1.0) return 1.0;
    float cosT = sqrt(1.0 - sin2T);
    float rParl = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5 * (rParl * rParl + rPerp * rPerp);
}

// common/tonemap.h: exposure, the ACES fit of Narkowicz 2015, sRGB encoding.
vec3 toneMap(vec3 c, float exposure) {
    c *= exposure;
    c = clamp((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// Front-surface Fresnel reflection plus the transmitted environment along the exit direction,
// attenuated by exp(-kappa * length). n: unit normal, v: unit direction toward the viewer;
// exitSigma, reflectSigma: lobe widths of the two lookups (0: sharp).
vec3 shadeGlass(vec3 exitDir, float exitSigma, float len, vec3 n, vec3 v, float eta, vec3 kappa,
                float reflectSigma) {
    float F = fresnelDielectric(dot(n, v), eta);
    vec3 transmitted = environment(exitDir, exitSigma) * exp(-kappa * max(len, 0.0));
    vec3 reflected = environment(reflect(-v, n), reflectSigma);
    return F * reflected + (1.0 - F) * transmitted;
}
