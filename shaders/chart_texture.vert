#version 330 core
// The unfolded mesh of a chart layout drawn in texture space (paper §5.2, Figure 6): every
// triangle at its atlas UVs, so that exactly the texels the charts cover are rasterized. The
// object-space position and normal ride along, interpolated to the texel centres: the sample
// points of the bake.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
out vec3 vPosition;
out vec3 vNormal;
void main() {
    vPosition = aPosition;
    vNormal = aNormal;
    gl_Position = vec4(aUV * 2.0 - 1.0, 0.0, 1.0);
}
