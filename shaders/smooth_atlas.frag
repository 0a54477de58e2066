#version 330 core
// Spatial smoothing in texture space for chart layouts (paper §5.2: "simple local averaging
// filters"): a 3 x 3 binomial filter (1 2 1) x (1 2 1) over the filled texels (covered and
// gutter, rings below 255), normalized; unfilled texels stay 0.
uniform sampler2D uD;
uniform usampler2D uRings;
layout(location = 0) out vec4 oD;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (texelFetch(uRings, p, 0).x == 255u) {
        oD = vec4(0.0);
        return;
    }
    ivec2 size = textureSize(uD, 0);
    vec4 sum = vec4(0.0);
    float weight = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            if (texelFetch(uRings, q, 0).x == 255u) continue;
            float w = float((2 - abs(dx)) * (2 - abs(dy)));
            sum += w * texelFetch(uD, q, 0);
            weight += w;
        }
    oD = sum / weight;
}
