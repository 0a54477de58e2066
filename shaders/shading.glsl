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
