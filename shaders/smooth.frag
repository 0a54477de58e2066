#version 330 core
// Spatial smoothing in mu through the bake's neighbour lists (paper §4.3, §5.3.2): weights sum
// to 1, the sample itself listed first.
uniform sampler2D uD;
uniform usampler2D uRange;       // (offset, count) per mu sample
uniform usampler2D uNbrIndex;    // neighbour list entries
uniform sampler2D uNbrWeight;
uniform int uMuWidth;
uniform int uListWidth;
layout(location = 0) out vec4 oD;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uvec2 r = texelFetch(uRange, p, 0).xy;
    vec4 s = vec4(0.0);
    for (uint j = 0u; j < r.y; ++j) {
        int e = int(r.x + j);
        ivec2 q = ivec2(e % uListWidth, e / uListWidth);
        int i = int(texelFetch(uNbrIndex, q, 0).x);
        s += texelFetch(uNbrWeight, q, 0).x * texelFetch(uD, ivec2(i % uMuWidth, i / uMuWidth), 0);
    }
    oD = r.y > 0u ? s : texelFetch(uD, p, 0);
}
