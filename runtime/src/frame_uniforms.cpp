#include "frame_uniforms.h"

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace shrefract {

using namespace gl;

FrameUniforms::FrameUniforms(const glm::mat4& view, const glm::mat4& projection,
                             const glm::mat4& model_)
    : model(model_),
      viewProjection(projection * view),
      normalMatrix(glm::inverseTranspose(glm::mat3(model_))),
      eye(glm::vec3(glm::inverse(view)[3])) {}

void FrameUniforms::set(GLuint p) const {
    glUniformMatrix4fv(glGetUniformLocation(p, "uModel"), 1, GL_FALSE, glm::value_ptr(model));
    glUniformMatrix4fv(glGetUniformLocation(p, "uViewProjection"), 1, GL_FALSE,
                       glm::value_ptr(viewProjection));
    glUniformMatrix3fv(glGetUniformLocation(p, "uNormalMatrix"), 1, GL_FALSE,
                       glm::value_ptr(normalMatrix));
    glUniform3f(glGetUniformLocation(p, "uEye"), eye.x, eye.y, eye.z);
    glUniform1f(glGetUniformLocation(p, "uEta"), eta);
    glUniform3f(glGetUniformLocation(p, "uKappa"), kappa.x, kappa.y, kappa.z);
    glUniform1i(glGetUniformLocation(p, "uToneMap"), toneMap ? 1 : 0);
    glUniform1f(glGetUniformLocation(p, "uExposure"), exposure);
}

}  // namespace shrefract
