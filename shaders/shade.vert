#version 330 core
// The glass mesh as the rho path draws it: corners of every triangle with their rho texel
// centres as UVs (docs/format.md "rho").
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
out vec3 vPosition;
out vec3 vObjectPosition;  // where on the object: a seed that moves with it (jitter shading)
out vec3 vNormal;
out vec2 vUV;
void main() {
    vec4 p = uModel * vec4(aPosition, 1.0);
    vPosition = p.xyz;
    vObjectPosition = aPosition;
    vNormal = uNormalMatrix * aNormal;
    vUV = aUV;
    gl_Position = uViewProjection * p;
}
