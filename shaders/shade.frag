#version 330 core
// The glass: exit direction and length D at this fragment, normalized, rotated to world,
// environment; Fresnel reflection at the front surface; absorption exp(-kappa * length);
// optional tone map (shading.glsl). D comes from the rho refraction map (paper §5.3, bilinear
// lookup with correction texels) or, with SHREFRACT_DIRECT, from the vertices (the rasterizer
// interpolates barycentrically: docs/runtime.md "Interpolation paths").
//
// Spread shading (uSpread, docs/runtime.md): where the SH reconstruction is shorter than a unit
// vector the mapping scatters, and the lookup averages the environment over a vMF lobe of the
// width whose mean resultant length that is, widened by the pixel's screen-space footprint.
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
uniform float uFootprintScale;  // factor on the screen-space turn of a direction per pixel
in vec3 vPosition;
in vec3 vNormal;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;

void main() {
#ifdef SHREFRACT_DIRECT
    vec4 r = vD;
#else
    vec4 r = texture(uRho, vUV);
#endif
    vec3 v = normalize(uEye - vPosition);
    vec3 n = normalize(vNormal);
    // A (near) zero interpolated direction has no direction: go straight through, never NaN.
    float resultant = length(r.xyz);
    vec3 exitWorld = resultant > 1e-10 ? normalize(uModelRotation * (r.xyz / resultant)) : -v;
    float exitSigma = 0.0, reflectSigma = 0.0;
    if (uSpread) {
        float spread = spreadSigma(resultant, uSpreadScale);
        float footprint = footprintSigma(exitWorld, uFootprintScale);
        exitSigma = sqrt(spread * spread + footprint * footprint);
        reflectSigma = footprintSigma(reflect(-v, n), uFootprintScale);
    }
    vec3 c = shadeGlass(exitWorld, exitSigma, r.w, n, v, uEta, uKappa, reflectSigma);
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
    oDirection = vec4(exitWorld, 1.0);
}
