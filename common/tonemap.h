// HDR to display, shared by the runtime (C++ and its GLSL twin in shaders/shading.glsl) and the
// bake-side reference renderer and image metrics, so every image is tone mapped alike.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace shrefract {

// c * exposure, then the ACES filmic fit of Narkowicz 2015 clamped to [0, 1], then the sRGB
// transfer function (docs/runtime.md "Tone map").
inline glm::vec3 toneMapAces(glm::vec3 c, float exposure = 1.0f) {
    c *= exposure;
    c = glm::clamp((c * (2.51f * c + 0.03f)) / (c * (2.43f * c + 0.59f) + 0.14f), 0.0f, 1.0f);
    for (int i = 0; i < 3; ++i)
        c[i] = c[i] <= 0.0031308f ? 12.92f * c[i] : 1.055f * std::pow(c[i], 1.0f / 2.4f) - 0.055f;
    return c;
}

}  // namespace shrefract
