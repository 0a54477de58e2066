#version 330 core
// The glass: exit direction and length D at this fragment, normalized, rotated to world,
// environment; Fresnel reflection at the front surface; absorption exp(-kappa * length);
// optional tone map (shading.glsl). D comes from the rho refraction map (paper §5.3, bilinear
// lookup with correction texels) or, with SHREFRACT_DIRECT, from the vertices (the rasterizer
// interpolates barycentrically: docs/runtime.md "Interpolation paths").
//
// Spread shading (uSpread, docs/runtime.md): where the SH reconstruction is shorter than a unit
// vector the mapping scatters, and the lookup averages the environment over a vMF lobe of the
// width whose mean resultant length that is, widened by the pixel's screen-space footprint. With
// the bake's error model the length carries its predicted error (shaders/error_fold.frag). Blend
// shading (uBlendSigma > 0) mixes that lobe with the sharp lookup.
#include "shading.glsl"
#ifdef SHREFRACT_DIRECT
in vec4 vD;
#else
uniform sampler2D uRho;
in vec2 vUV;
#endif
uniform mat3 uModelRotation;
uniform vec3 uEye;            // world space
uniform float uEta;           // n_glass / n_air
uniform vec3 uKappa;          // absorption per object-space unit, RGB
uniform bool uToneMap;
uniform float uExposure;
uniform bool uSpread;
uniform float uSpreadScale;     // lobe width factor on spreadSigma()
uniform float uBlendSigma;      // > 0 (blend shading): the sharp lookup and the lobe mixed, the
                                // lobe's share spread / (spread + uBlendSigma)
uniform float uJitterCell;      // > 0 (jitter shading): one direction drawn within the lobe per
                                // cell of this size (object units), instead of the lobe's mean;
                                // oDirection keeps the bake's exit (what the metrics measure)
uniform float uJitterGate;      // jitter: the lobe width (radians) where the lookup turns from a
                                // sure fragment's to an unsure one's (0: ungated)
uniform float uFootprintScale;  // factor on the screen-space turn of a direction per pixel
uniform int uTaps;              // 1: one lookup at the pixel's centre; 4: four inside it, averaged
in vec3 vPosition;
in vec3 vObjectPosition;
in vec3 vNormal;
layout(location = 0) out vec4 oColor;
#ifndef SHREFRACT_COLOR_ONLY  // WebGL's default framebuffer has one colour buffer
layout(location = 1) out vec4 oDirection;
#endif

// The world-space exit of an interpolated D seen along v. A (near) zero D has no direction: go
// straight through, never NaN.
vec3 exitOf(vec4 r, vec3 v) {
    float resultant = length(r.xyz);
    return resultant > 1e-10 ? normalize(uModelRotation * (r.xyz / resultant)) : -v;
}

// The colour of one lookup: the interpolated D (xyz its direction, w the path length) at an
// object-space point, shaded as the uniforms ask.
vec3 shadeOne(vec4 r, vec3 objectPosition, vec3 n, vec3 v) {
    float resultant = length(r.xyz);
    vec3 exitWorld = exitOf(r, v);
    vec4 lookup = vec4(exitWorld, 0.0);
    float reflectSigma = 0.0, spread = 0.0;
    if (uSpread) {
        spread = spreadSigma(resultant, uSpreadScale);
        lookup = transmissionLookup(exitWorld, spread, uFootprintScale, uJitterCell, uJitterGate,
                                    objectPosition);
        reflectSigma = footprintSigma(reflect(-v, n), uFootprintScale);
    }
    vec3 c = shadeGlass(lookup.xyz, lookup.w, r.w, n, v, uEta, uKappa, reflectSigma);
    if (uSpread && uBlendSigma > 0.0) {
        // Keep the sharp lookup's contrast where the lobe is narrow, and most of it where it is
        // not: the mean of a wide lobe is a grey the truth never shows.
        float sharpSigma = footprintSigma(exitWorld, uFootprintScale);
        vec3 sharp = shadeGlass(exitWorld, sharpSigma, r.w, n, v, uEta, uKappa, reflectSigma);
        c = mix(sharp, c, spread / (spread + uBlendSigma));
    }
    return c;
}

void main() {
#ifdef SHREFRACT_DIRECT
    vec4 r = vD;
#else
    vec4 r = texture(uRho, vUV);
#endif
    vec3 v = normalize(uEye - vPosition);
    vec3 c;
    if (uTaps == 4) {
        // Four lookups at (+-1/4, +-1/4) pixel, all that is interpolated (D, the point, the
        // normal) carried there along its screen derivatives, averaged: the exit's pattern
        // antialiased inside the pixel. uTaps is uniform: the derivatives are taken in uniform
        // control flow.
        vec4 rx = 0.25 * dFdx(r), ry = 0.25 * dFdy(r);
        vec3 px = 0.25 * dFdx(vPosition), py = 0.25 * dFdy(vPosition);
        vec3 ox = 0.25 * dFdx(vObjectPosition), oy = 0.25 * dFdy(vObjectPosition);
        vec3 nx = 0.25 * dFdx(vNormal), ny = 0.25 * dFdy(vNormal);
        c = vec3(0.0);
        for (int i = 0; i < 4; ++i) {
            float sx = (i & 1) == 0 ? -1.0 : 1.0, sy = i < 2 ? -1.0 : 1.0;
            c += 0.25 * shadeOne(r + sx * rx + sy * ry, vObjectPosition + sx * ox + sy * oy,
                                 normalize(vNormal + sx * nx + sy * ny),
                                 normalize(uEye - (vPosition + sx * px + sy * py)));
        }
    } else {
        c = shadeOne(r, vObjectPosition, normalize(vNormal), v);
    }
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
#ifndef SHREFRACT_COLOR_ONLY
    oDirection = vec4(exitOf(r, v), 1.0);
#endif
}
