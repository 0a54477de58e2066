#version 330 core
// Front surfaces of the baselines: T1 = refract(-V, N1); single looks T1 up; Wyman 2005 finds
// the second interface: d~ = (thetaT/thetaI) d_V + (1 - thetaT/thetaI) d_N, P2 = P1 + d~ T1,
// projected into the back-face buffer for N2, then T2 = refract(T1, -N2) (TIR: uTir). Fresnel,
// absorption and the environment lookup are the SH shading's (shading.glsl), so the methods
// differ only in the exit direction and length.
#include "shading.glsl"
uniform sampler2D uBack;       // Wyman pass 1 (nearest), viewport-sized
uniform mat4 uView;
uniform mat4 uViewProjection;
uniform vec3 uEye;             // world space
uniform float uEta;            // n_glass / n_air
uniform vec3 uKappa;           // absorption per object-space unit, RGB
uniform float uScale;          // world units per object unit (for d_N and the length)
uniform int uMethod;           // 0 single, 1 Wyman
uniform int uTir;              // 0 reflect, 1 straight, 2 grazing
uniform vec2 uViewportOrigin;
uniform bool uToneMap;
uniform float uExposure;
in vec3 vPosition;
in vec3 vNormal;
in float vNormalDistance;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;

void main() {
    if (!gl_FrontFacing) discard;
    vec3 P1 = vPosition;
    vec3 V = normalize(uEye - P1);
    vec3 N1 = normalize(vNormal);
    float cosI = dot(N1, V);
    // The entry normal must face the viewer (the bake's rule 3 falls back to the geometric one).
    vec3 Ne = cosI > 0.0 ? N1 : normalize(cross(dFdx(P1), dFdy(P1)));
    if (dot(Ne, V) < 0.0) Ne = -Ne;
    vec3 T1 = refract(-V, Ne, 1.0 / uEta);
    vec3 exitDir = T1;
    float len = 0.0;  // single: no second interface, no absorption
    if (uMethod == 1) {
        float cI = clamp(dot(Ne, V), 0.0, 1.0), cT = clamp(dot(-Ne, T1), 0.0, 1.0);
        float thetaI = acos(cI), thetaT = acos(cT);
        // thetaT / thetaI -> 1 / eta at normal incidence (Snell, small angles).
        float ratio = thetaI > 1e-4 ? thetaT / thetaI : 1.0 / uEta;
        // d_V: from P1 along the view ray to the back face seen through this pixel.
        vec4 back0 = texelFetch(uBack, ivec2(gl_FragCoord.xy - uViewportOrigin), 0);
        float zFront = -(uView * vec4(P1, 1.0)).z;
        float dN = vNormalDistance * uScale;
        float dV = back0.w > 0.0 ? max(back0.w - zFront, 0.0) * length(P1 - uEye) / zFront : dN;
        float d = ratio * dV + (1.0 - ratio) * dN;
        vec3 P2 = P1 + d * T1;
        vec4 clip = uViewProjection * vec4(P2, 1.0);
        vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
        vec4 back = texture(uBack, uv);
        len = d / uScale;
        if (clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))) &&
            back.w > 0.0) {
            vec3 N2 = normalize(back.xyz);
            vec3 T2 = refract(T1, -N2, uEta);
            if (dot(T2, T2) == 0.0) {  // total internal reflection
                if (uTir == 0) T2 = reflect(T1, -N2);
                else if (uTir == 1) T2 = T1;
                else {
                    vec3 t = T1 - dot(T1, N2) * N2;
                    T2 = dot(t, t) > 1e-12 ? normalize(t) : T1;
                }
            }
            exitDir = T2;
        }
        // P2 projected outside the back-face buffer: no second normal; T1 continues.
    }
    exitDir = normalize(exitDir);
    vec3 c = shadeGlass(exitDir, 0.0, len, N1, V, uEta, uKappa, 0.0);  // the published methods: sharp lookups
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
    oDirection = vec4(exitDir, 1.0);
}
