#include "ior.h"

#include "shaders.h"

namespace shrefract {

using namespace gl;

namespace {
constexpr int kBracketUnit = 5;  // after environment 0, D 1, positions 2, normals 3
}

glm::vec3 iorBlendWeights(glm::vec3 ior, float nA, float nB) {
    return (ior - glm::vec3(nA)) / (nB - nA);
}

GLuint IorShading::program(bool direct, int muWidth) {
    GLuint& p = direct ? directProgram : rhoProgram;
    if (p) return p;
    if (direct) {
        p = buildProgram(
            shaders::withVersion(shaders::source("shade_direct.vert"), "330 core",
                                 "#define SHREFRACT_IOR_BRACKET"),
            shaders::withVersion(shaders::source("shade_ior.frag"), "330 core",
                                 "#define SHREFRACT_DIRECT"),
            "direct shading at another index of refraction");
        glUseProgram(p);
        glUniform1i(glGetUniformLocation(p, "uD"), 1);
        glUniform1i(glGetUniformLocation(p, "uPosition"), 2);
        glUniform1i(glGetUniformLocation(p, "uNormal"), 3);
        glUniform1i(glGetUniformLocation(p, "uDB"), kBracketUnit);
        glUniform1i(glGetUniformLocation(p, "uMuWidth"), muWidth);
    } else {
        p = buildProgram(shaders::source("shade.vert"), shaders::source("shade_ior.frag"),
                         "shading at another index of refraction");
        glUseProgram(p);
        glUniform1i(glGetUniformLocation(p, "uRho"), 1);
        glUniform1i(glGetUniformLocation(p, "uRhoB"), kBracketUnit);
    }
    return p;
}

void IorShading::setUniforms(GLuint p, float bakeIor, float bracketIor) const {
    // Mode 1 (paper §5.4): straight path at index 1 <-> the bake. Mode 2: this bake <-> the
    // bracketing one.
    const bool two = bracket != nullptr;
    const glm::vec3 t = two ? iorBlendWeights(ior, bakeIor, bracketIor)
                            : iorBlendWeights(ior, 1.0f, bakeIor);
    glUniform1i(glGetUniformLocation(p, "uMode"), two ? 2 : 1);
    glUniform3f(glGetUniformLocation(p, "uBlend"), t.x, t.y, t.z);
    glUniform3f(glGetUniformLocation(p, "uEtaRGB"), ior.x, ior.y, ior.z);
    glActiveTexture(GL_TEXTURE0 + kBracketUnit);
    glBindTexture(GL_TEXTURE_2D, two ? bracketD : 0);
}

void IorShading::destroy() {
    for (GLuint p : {rhoProgram, directProgram})
        if (p) glDeleteProgram(p);
    rhoProgram = directProgram = 0;
}

}  // namespace shrefract
