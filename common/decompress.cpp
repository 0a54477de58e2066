#include "common/decompress.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error.h"
#include "common/frame.h"
#include "common/sh.h"

namespace shrefract {

glm::vec3 localViewDirection(const SurfaceLayout& layout, int i, glm::vec3 omega) {
    return Frame::fromNormal(layout.normal[i]).toLocal(omega);
}

glm::vec3 localViewFromEye(const SurfaceLayout& layout, int i, glm::vec3 eye) {
    return localViewDirection(layout, i, glm::normalize(eye - layout.position[i]));
}

glm::vec4 decompressSample(const BakeData& bake, int i, glm::vec3 wLocal, int order) {
    int L = (order < 0 || order > bake.order) ? bake.order : order;
    int K = shEvenCount(L);
    float basis[512];
    SHREFRACT_CHECK(K <= 512);
    // Below the tangent plane the mirrored function is meant: the stored functions are all
    // even in z, so evaluating at (x, y, z) or (x, y, -z) is the same.
    shEvalEven(L, glm::normalize(wLocal), basis);
    const size_t n = bake.layout.position.size();
    glm::vec4 d(0.0f);
    for (int k = 0; k < K; ++k) {
        const float* w = &bake.weights[(k * n + i) * 4];
        d += basis[k] * glm::vec4(w[0], w[1], w[2], w[3]);
    }
    return d;
}

glm::vec4 interpolateRho(const SurfaceLayout& layout, const glm::vec4* values, int t, float u,
                         float v) {
    const int r = layout.rate;
    float s = u * r, q = v * r;
    int i = std::clamp(static_cast<int>(std::floor(s)), 0, r - 1);
    int j = std::clamp(static_cast<int>(std::floor(q)), 0, r - 1 - i);
    float a = s - i, b = q - j;
    glm::vec4 v00 = values[layout.sampleAt(t, i, j)];
    glm::vec4 v10 = values[layout.sampleAt(t, i + 1, j)];
    glm::vec4 v01 = values[layout.sampleAt(t, i, j + 1)];
    // v11 = v01 + v10 - v00 past the hypotenuse: bilinear equals barycentric on this half-cell.
    glm::vec4 v11 = (i + j + 2 <= r) ? values[layout.sampleAt(t, i + 1, j + 1)] : v10 + v01 - v00;
    return (1 - a) * (1 - b) * v00 + a * (1 - b) * v10 + (1 - a) * b * v01 + a * b * v11;
}

}  // namespace shrefract
