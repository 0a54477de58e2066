#version 330 core
// Wyman pass 1: the nearest back face per pixel: its world normal (outward) and view depth.
uniform mat4 uView;
in vec3 vPosition;
in vec3 vNormal;
in float vNormalDistance;
layout(location = 0) out vec4 oBack;
void main() {
    if (gl_FrontFacing) discard;
    oBack = vec4(normalize(vNormal), -(uView * vec4(vPosition, 1.0)).z);
}
