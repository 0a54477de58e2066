#version 330 core
// The direct path (docs/runtime.md "Interpolation paths"): the joining layout's sample grid drawn
// as a refined mesh, one vertex per mu sample, so gl_VertexID is the sample and the rasterizer
// interpolates D barycentrically (no rho, no correction texels, no unpack pass). The sample's
// position and normal come from the mu textures; D either from D_mu (the decompression passes
// ran in texture space) or, with SHREFRACT_VERTEX_SH, from the SH evaluated right here at the
// vertex's local view direction (one draw does decompression and shading; the generator puts
// the weight samplers and shPass() in place of the marker line).
uniform sampler2D uPosition;
uniform sampler2D uNormal;
uniform int uMuWidth;
uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
#ifdef SHREFRACT_VERTEX_SH
#include "frame.glsl"
uniform vec3 uEyeObject;
#pragma shrefract_generated
#else
uniform sampler2D uD;
#endif
#ifdef SHREFRACT_IOR_BRACKET
uniform sampler2D uDB;  // shade_ior.frag's second bake (runtime/src/ior.h), same mu layout
out vec4 vDB;
#endif
out vec3 vPosition;
out vec3 vObjectPosition;  // where on the object: a seed that moves with it (jitter shading)
out vec3 vNormal;
out vec4 vD;

void main() {
    ivec2 p = ivec2(gl_VertexID % uMuWidth, gl_VertexID / uMuWidth);
    vec3 P = texelFetch(uPosition, p, 0).xyz;
    vec3 N = texelFetch(uNormal, p, 0).xyz;
#ifdef SHREFRACT_VERTEX_SH
    vD = shPass(p, normalize(toLocalFrame(normalize(uEyeObject - P), N)), vec4(0.0));
#else
    vD = texelFetch(uD, p, 0);
#endif
#ifdef SHREFRACT_IOR_BRACKET
    vDB = texelFetch(uDB, p, 0);
#endif
    vec4 world = uModel * vec4(P, 1.0);
    vPosition = world.xyz;
    vObjectPosition = P;
    vNormal = uNormalMatrix * N;
    gl_Position = uViewProjection * world;
}
