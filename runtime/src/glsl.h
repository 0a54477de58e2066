// GLSL sources of the fixed passes (the decompression passes are generated: shadergen.h).
// Each is a twin of CPU code in common/ and must stay in step with it.
#pragma once

#include <string>

namespace shrefract::glsl {

// Full-screen triangle; shared by every texture-space pass.
inline const char* kFullscreenVertex = R"(#version 330 core
void main() {
    vec2 c = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);
}
)";

// Local view direction per mu sample: common/decompress.cpp localViewFromEye with the frame of
// common/frame.h (Duff et al. 2017), ported operation for operation.
inline const char* kLocalViewFragment = R"(#version 330 core
uniform sampler2D uPosition;
uniform sampler2D uNormal;
uniform vec3 uEye;  // object space
layout(location = 0) out vec4 oLocal;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 P = texelFetch(uPosition, p, 0).xyz;
    vec3 n = texelFetch(uNormal, p, 0).xyz;
    vec3 omega = normalize(uEye - P);
    // std::copysign(1, n.z): the sign bit decides, so -0.0 gives -1 as on the CPU.
    float sgn = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
    float a = -1.0 / (sgn + n.z);
    float bb = n.x * n.y * a;
    vec3 t = vec3(1.0 + sgn * n.x * n.x * a, sgn * bb, -sgn * n.x);
    vec3 b = vec3(bb, sgn + n.y * n.y * a, -n.y);
    vec3 w = vec3(dot(omega, t), dot(omega, b), dot(omega, n));
    oLocal = vec4(normalize(w), 0.0);
}
)";

// Spatial smoothing in mu through the bake's neighbour lists (paper §5.3.2): weights sum to 1,
// the sample itself listed first.
inline const char* kSmoothFragment = R"(#version 330 core
uniform sampler2D uD;
uniform usampler2D uRange;       // (offset, count) per mu sample
uniform usampler2D uNbrIndex;    // neighbour list entries
uniform sampler2D uNbrWeight;
uniform int uMuWidth;
uniform int uListWidth;
layout(location = 0) out vec4 oD;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uvec2 r = texelFetch(uRange, p, 0).xy;
    vec4 s = vec4(0.0);
    for (uint j = 0u; j < r.y; ++j) {
        int e = int(r.x + j);
        ivec2 q = ivec2(e % uListWidth, e / uListWidth);
        int i = int(texelFetch(uNbrIndex, q, 0).x);
        s += texelFetch(uNbrWeight, q, 0).x * texelFetch(uD, ivec2(i % uMuWidth, i / uMuWidth), 0);
    }
    oD = r.y > 0u ? s : texelFetch(uD, p, 0);
}
)";

// mu -> rho (paper §5.3.1): sample texels copy their mu sample; correction texels just outside
// a hypotenuse get v11 = v01 + v10 - v00, so that bilinear filtering equals barycentric
// interpolation on the half-cell (common/decompress.cpp interpolateRho).
inline const char* kUnpackFragment = R"(#version 330 core
uniform usampler2D uRhoIndex;  // (kind, a, b, c): common/bakefile.h RhoTexel
uniform sampler2D uD;
uniform int uMuWidth;
uniform bool uCorrection;
layout(location = 0) out vec4 oRho;
vec4 D(uint i) { return texelFetch(uD, ivec2(int(i) % uMuWidth, int(i) / uMuWidth), 0); }
void main() {
    uvec4 t = texelFetch(uRhoIndex, ivec2(gl_FragCoord.xy), 0);
    vec4 v = vec4(0.0);
    if (t.x == 1u) v = D(t.y);
    else if (t.x == 2u && uCorrection) v = D(t.y) + D(t.z) - D(t.w);
    oRho = v;
}
)";

// The shading every method shares, spliced after the #version line of the shaders that use it
// (withShadingLibrary): so SH, the baselines and the background differ only in the exit
// direction and length they pass in.
inline const char* kShadingLibrary = R"(
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
// attenuated by exp(-kappa * length). n: unit normal, v: unit direction toward the viewer.
vec3 shadeGlass(samplerCube env, vec3 exitDir, float len, vec3 n, vec3 v, float eta, vec3 kappa) {
    float F = fresnelDielectric(dot(n, v), eta);
    vec3 transmitted = texture(env, exitDir).rgb * exp(-kappa * max(len, 0.0));
    vec3 reflected = texture(env, reflect(-v, n)).rgb;
    return F * reflected + (1.0 - F) * transmitted;
}
)";

// `source` with kShadingLibrary inserted after its first line (the #version directive).
inline std::string withShadingLibrary(const char* source) {
    std::string s(source);
    const size_t eol = s.find('\n') + 1;
    return s.substr(0, eol) + kShadingLibrary + s.substr(eol);
}

inline const char* kShadeVertex = R"(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
out vec3 vPosition;
out vec3 vNormal;
out vec2 vUV;
void main() {
    vec4 p = uModel * vec4(aPosition, 1.0);
    vPosition = p.xyz;
    vNormal = uNormalMatrix * aNormal;
    vUV = aUV;
    gl_Position = uViewProjection * p;
}
)";

// Shading: refraction map lookup (bilinear), normalize, rotate to world, environment; Fresnel
// reflection at the front surface (common/optics.h FresnelDielectric); absorption
// exp(-kappa * length); optional tone map (runtime.h toneMap).
inline const char* kShadeFragment = R"(#version 330 core
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
)";

inline const char* kBackgroundFragment = R"(#version 330 core
uniform samplerCube uEnvironment;
uniform mat4 uInverseViewProjection;  // rotation-only view
uniform vec2 uViewport;
uniform vec2 uViewportOrigin;
uniform bool uToneMap;
uniform float uExposure;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;

void main() {
    vec2 ndc = (gl_FragCoord.xy - uViewportOrigin) / uViewport * 2.0 - 1.0;
    vec4 d = uInverseViewProjection * vec4(ndc, 1.0, 1.0);
    vec3 c = texture(uEnvironment, normalize(d.xyz / d.w)).rgb;
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
    oDirection = vec4(0.0);
}
)";

}  // namespace shrefract::glsl
