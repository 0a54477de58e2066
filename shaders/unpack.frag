#version 330 core
// mu -> rho (paper §5.3.1): sample texels copy their mu sample; correction texels just outside a
// hypotenuse get v11 = v01 + v10 - v00, so that bilinear filtering equals barycentric
// interpolation on the half-cell (common/decompress.cpp interpolateRho).
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
