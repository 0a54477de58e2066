#version 330 core
// The environment behind everything, looked up along each pixel's view ray.
#include "shading.glsl"
uniform mat4 uInverseViewProjection;  // rotation-only view
uniform vec2 uViewport;
uniform vec2 uViewportOrigin;
uniform bool uToneMap;
uniform float uExposure;
layout(location = 0) out vec4 oColor;
#ifndef SHREFRACT_COLOR_ONLY  // WebGL's default framebuffer has one colour buffer
layout(location = 1) out vec4 oDirection;
#endif

void main() {
    vec2 ndc = (gl_FragCoord.xy - uViewportOrigin) / uViewport * 2.0 - 1.0;
    vec4 d = uInverseViewProjection * vec4(ndc, 1.0, 1.0);
    vec3 c = environment(normalize(d.xyz / d.w), 0.0);
    oColor = vec4(uToneMap ? toneMap(c, uExposure) : c, 1.0);
#ifndef SHREFRACT_COLOR_ONLY
    oDirection = vec4(0.0);
#endif
}
