#version 330 core
// Seam-aware gutters (beyond the paper, docs/runtime.md): a gutter texel near a smooth seam takes
// the mix of the samples on the other side of the cut, where the surface it continues lies, in
// place of the mean of its own chart's edge. The bake lists the sources (format "seam_sources");
// gutter texels beyond the dilation width stay unfilled.
uniform sampler2D uD;             // D+ (dilated): covered texels hold D
uniform usampler2D uRings;
uniform usampler2D uSeamIndex;    // per atlas texel: 0, or entry + 1
uniform usampler2D uSeamSample;   // per entry: four atlas texel indices y * width + x
uniform sampler2D uSeamWeight;    // per entry: their weights (0 for unused slots)
uniform int uListWidth;
layout(location = 0) out vec4 oD;
vec4 D(uint i) {
    int w = textureSize(uD, 0).x;
    return texelFetch(uD, ivec2(int(i) % w, int(i) / w), 0);
}
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uint e = texelFetch(uSeamIndex, p, 0).x;
    uint r = texelFetch(uRings, p, 0).x;
    if (e == 0u || r == 0u || r == 255u) {
        oD = texelFetch(uD, p, 0);
        return;
    }
    ivec2 q = ivec2(int(e - 1u) % uListWidth, int(e - 1u) / uListWidth);
    uvec4 s = texelFetch(uSeamSample, q, 0);
    vec4 w = texelFetch(uSeamWeight, q, 0);
    vec4 v = vec4(0.0);
    for (int k = 0; k < 4; ++k)
        if (w[k] != 0.0) v += w[k] * D(s[k]);
    oD = v;
}
