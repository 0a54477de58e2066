// The uniforms every shading program of the runtime reads once per frame (shade.frag,
// shade_ior.frag, baseline.frag): the camera and placement, the glass's medium, the display.
#pragma once

#include <glm/glm.hpp>

#include "gl.h"

namespace shrefract {

struct FrameUniforms {
    glm::mat4 model{1.0f}, viewProjection{1.0f};
    glm::mat3 normalMatrix{1.0f};  // inverse transpose of the model's linear part
    glm::vec3 eye{0.0f};           // world space, from the view matrix
    float eta = 1.5f;              // the bake's index of refraction
    glm::vec3 kappa{0.0f};         // absorption per object-space unit
    bool toneMap = false;
    float exposure = 1.0f;

    FrameUniforms(const glm::mat4& view, const glm::mat4& projection, const glm::mat4& model);
    // Sets uModel, uViewProjection, uNormalMatrix, uEye, uEta, uKappa, uToneMap, uExposure on the
    // program in use, `p`.
    void set(GLuint p) const;
};

}  // namespace shrefract
