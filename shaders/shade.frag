#version 330 core
// Shading on the rho path: refraction map lookup (bilinear), normalize, rotate to world,
// environment; Fresnel reflection at the front surface; absorption exp(-kappa * length); optional
// tone map (shading.glsl).
#include "shading.glsl"
uniform sampler2D uRho;
uniform samplerCube uEnvironment;
uniform mat3 uModelRotation;
uniform vec3 uEye;         // world space
uniform float uEta;        // n_glass / n_air
uniform vec3 uKappa;       // absorption per object-space unit, RGB
uniform bool uToneMap;
uniform float uExposure;
in vec3 vPosition;
in vec3 vNormal;
in vec2 vUV;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;

void main() {
    vec4 r = texture(uRho, vUV);
    vec3 v = normalize(uEye - vPosition);
    // A (near) zero interpolated direction has no direction: go straight through, never NaN.
    float len2 = dot(r.xyz, r.xyz);
    vec3 exitWorld = len2 > 1e-20 ? normalize(uModelRotation * (r.xyz * inversesqrt(len2))) : -v;
    vec3 c = shadeGlass(uEnvironment, exitWorld, r.w, normalize(vNormal), v, uEta, uKappa);
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
    oDirection = vec4(exitWorld, 1.0);
}
