#version 330 core
// One ring of the dynamic gutters (paper §5.2, D_mu -> D+_mu): a texel of ring uRing takes the
// mean of its 8-neighbours of lower rings, already filled; every other texel is copied. Rings:
// 0 covered, 1..width gutter, 255 beyond (common/decompress.h gutterRings).
uniform sampler2D uD;
uniform usampler2D uRings;
uniform int uRing;
layout(location = 0) out vec4 oD;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    int r = int(texelFetch(uRings, p, 0).x);
    if (r != uRing || uRing == 0) {
        oD = texelFetch(uD, p, 0);
        return;
    }
    ivec2 size = textureSize(uD, 0);
    vec4 sum = vec4(0.0);
    float n = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            if (int(texelFetch(uRings, q, 0).x) >= uRing) continue;
            sum += texelFetch(uD, q, 0);
            n += 1.0;
        }
    oD = sum / n;
}
