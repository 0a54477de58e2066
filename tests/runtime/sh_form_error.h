// Float32 error of the GL decompression against a double-precision reference, for comparing
// the generator's SH evaluation forms (polynomial vs recurrence). Shared by the runtime tests and
// shrefract-bench-shforms (eval/cmd/bench-shforms.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/bakefile.h"
#include "common/sh.h"
#include "shrefract/runtime.h"
#include "test_bake.h"

namespace shrefract::test {

// The octahedron bake of randomBake() with every weight uniform in [-1, 1] (no decay, no band-0
// bias): the worst case for cancellation across functions is what the forms are compared on.
inline BakeData uniformWeightBake(int order, int rate, unsigned seed = 11) {
    BakeData d = randomBake(order, rate, seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (float& w : d.weights) w = u(rng);
    return d;
}

// Eyes around the octahedron (object space), so local view directions cover the sphere.
inline std::vector<glm::vec3> formErrorEyes() {
    return {{0.3f, 0.8f, 3.0f}, {-2.5f, -1.0f, 0.4f}, {1.2f, -2.6f, -1.5f}, {-0.7f, 2.9f, -1.1f}};
}

struct FormError {
    double max = 0, median = 0;
    size_t values = 0;  // samples x eyes x 4 channels
};

// For each eye: update(), read back D_mu and the local view directions the passes used, and
// compare with sum_k weight_k y_k(w) in double (shEvalAllRecurrence at the GL direction,
// normalized in double).
inline FormError measureFormError(Refractor& r, const BakeData& d,
                                  const std::vector<glm::vec3>& eyes) {
    const int L = r.order();
    const int n = d.layout.sampleCount();
    const std::vector<ShLM> functions = shEvenFunctions(L);
    std::vector<double> all(shCount(L)), errors;
    errors.reserve(static_cast<size_t>(n) * eyes.size() * 4);
    for (glm::vec3 eye : eyes) {
        r.update(FrameView::fromEye(eye));
        std::vector<float> gl = r.readDirectionalMap();
        std::vector<float> view = r.readLocalViewMap();
        for (int i = 0; i < n; ++i) {
            glm::dvec3 w(view[4 * i], view[4 * i + 1], view[4 * i + 2]);
            shEvalAllRecurrence(L, glm::normalize(w), all.data());
            double ref[4] = {0, 0, 0, 0};
            for (size_t k = 0; k < functions.size(); ++k) {
                double y = all[shIndex(functions[k].l, functions[k].m)];
                const float* wk = &d.weights[(k * n + i) * 4];
                for (int c = 0; c < 4; ++c) ref[c] += double(wk[c]) * y;
            }
            for (int c = 0; c < 4; ++c) errors.push_back(std::abs(double(gl[4 * i + c]) - ref[c]));
        }
    }
    FormError e;
    e.values = errors.size();
    if (errors.empty()) return e;
    e.max = *std::max_element(errors.begin(), errors.end());
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    e.median = errors[errors.size() / 2];
    return e;
}

}  // namespace shrefract::test
