#version 330 core
// Shading at an index of refraction the bake was not made for (paper §5.4; docs/runtime.md
// "Variable IOR and dispersion"), one index per RGB channel (dispersion when they differ).
// Each channel c looks the environment up along its own exit direction
//   e_c = normalize(mix(a, b, uBlend[c]))
// where, for uMode 1 (the paper's §5.4, no physical basis), a = the straight path (-v: the ray
// that an index of 1 would not bend) and b = the baked exit; for uMode 2, a and b are the exits
// of two bakes at bracketing indices (length and spread interpolated too). Fresnel per channel
// with its own index; the spread lobe (shade.frag) per channel. Draw buffer 1 gets the green
// channel's exit. D comes from the rho maps or, with SHREFRACT_DIRECT, from the vertices
// (shade_direct.vert with SHREFRACT_IOR_BRACKET), as in shade.frag.
#include "shading.glsl"
#ifdef SHREFRACT_DIRECT
in vec4 vD;
in vec4 vDB;                // mode 2: the bracketing bake's D
#else
uniform sampler2D uRho;     // the bake (mode 1) or the first of two (mode 2)
uniform sampler2D uRhoB;    // mode 2: the bracketing bake, same layout
in vec2 vUV;
#endif
uniform mat3 uModelRotation;
uniform vec3 uEye;          // world space
uniform vec3 uEtaRGB;       // n_object / n_air per channel
uniform vec3 uBlend;        // interpolation weight per channel
uniform int uMode;          // 1: straight <-> baked, 2: bake <-> bake
uniform vec3 uKappa;        // absorption per object-space unit, RGB
uniform bool uToneMap;
uniform float uExposure;
uniform bool uSpread;
uniform float uSpreadScale;
uniform float uFootprintScale;
uniform float uJitterCell;  // as shade.frag's (blend shading is shaded as spread here)
uniform float uJitterGate;
in vec3 vPosition;
in vec3 vObjectPosition;
in vec3 vNormal;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;

// A reconstruction's direction in world space; `fallback` where it has none.
vec3 exitOf(vec4 r, vec3 fallback) {
    float resultant = length(r.xyz);
    return resultant > 1e-10 ? normalize(uModelRotation * (r.xyz / resultant)) : fallback;
}

// Normalized interpolation of two unit directions; b where they cancel.
vec3 blendDirections(vec3 a, vec3 b, float t) {
    vec3 m = mix(a, b, t);
    float len2 = dot(m, m);
    return len2 > 1e-12 ? m * inversesqrt(len2) : b;
}

void main() {
    vec3 v = normalize(uEye - vPosition);
    vec3 n = normalize(vNormal);
#ifdef SHREFRACT_DIRECT
    vec4 ra = vD, rb = vDB;
#else
    vec4 ra = texture(uRho, vUV), rb = texture(uRhoB, vUV);
#endif
    vec3 a, b;
    float lenA, lenB, resA, resB;
    if (uMode == 2) {
        a = exitOf(ra, -v);
        b = exitOf(rb, -v);
        lenA = ra.w, lenB = rb.w;
        resA = length(ra.xyz), resB = length(rb.xyz);
    } else {
        // The straight path: certain (no spread); its length is not known, keep the baked one.
        a = -v;
        b = exitOf(ra, -v);
        lenA = lenB = ra.w;
        resA = 1.0, resB = length(ra.xyz);
    }
    float reflectSigma = uSpread ? footprintSigma(reflect(-v, n), uFootprintScale) : 0.0;
    vec3 c, exitG;
    for (int k = 0; k < 3; ++k) {
        vec3 e = blendDirections(a, b, uBlend[k]);
        vec4 lookup = vec4(e, 0.0);
        if (uSpread)
            lookup = transmissionLookup(e, spreadSigma(mix(resA, resB, uBlend[k]), uSpreadScale),
                                        uFootprintScale, uJitterCell, uJitterGate, vObjectPosition);
        c[k] = shadeGlass(lookup.xyz, lookup.w, mix(lenA, lenB, uBlend[k]), n, v, uEtaRGB[k], uKappa,
                          reflectSigma)[k];
        if (k == 1) exitG = e;
    }
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
    oDirection = vec4(exitG, 1.0);
}
