#version 330 core
// Local view direction per mu sample (paper §5.3.2): the direction toward the eye expressed in
// the sample's frame (frame.glsl), as common/decompress.cpp localViewFromEye does.
#include "frame.glsl"
uniform sampler2D uPosition;
uniform sampler2D uNormal;
uniform vec3 uEye;  // object space
layout(location = 0) out vec4 oLocal;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 P = texelFetch(uPosition, p, 0).xyz;
    vec3 n = texelFetch(uNormal, p, 0).xyz;
    vec3 omega = normalize(uEye - P);
    vec3 w = toLocalFrame(omega, n);
    oLocal = vec4(normalize(w), 0.0);
}
