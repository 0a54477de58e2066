#version 330 core
// The glass mesh for the baselines (docs/evaluation.md), with Wyman's per-vertex d_N.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in float aNormalDistance;  // d_N, object units
uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
out vec3 vPosition;
out vec3 vNormal;
out float vNormalDistance;
void main() {
    vec4 p = uModel * vec4(aPosition, 1.0);
    vPosition = p.xyz;
    vNormal = uNormalMatrix * aNormal;
    vNormalDistance = aNormalDistance;
    gl_Position = uViewProjection * p;
}
