// Lat-long EXR -> GL cube map with its prefiltered mip chain (spread shading), and the
// background pass.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/gtc/type_ptr.hpp>

#include "common/error.h"
#include "common/latlong.h"
#include "common/prefilter.h"
#include "environment_gl.h"
#include "gl.h"
#include "shaders.h"
#include "shrefract/runtime.h"

namespace shrefract {

using namespace gl;

Environment Environment::loadLatLong(const std::string& path, int faceSize) {
    LatLongImage image = shrefract::loadLatLong(path);
    return fromLatLong(image.width, image.height, image.rgb, faceSize);
}

Environment Environment::fromLatLong(int width, int height, const std::vector<float>& rgb,
                                     int faceSize) {
    const std::string problem = latLongProblem(width, height, rgb);
    if (!problem.empty()) throw std::invalid_argument("shrefract: Environment::fromLatLong: " + problem);
    ensureLoaded(currentContextLoader());
    Environment env;
    env.faceSize_ = faceSize > 0 ? faceSize : std::max(1, height / 2);
    // The faces are built on the CPU (common/latlong.h), where the reference renderer reads
    // the same ones; so is the mip chain (common/prefilter.h), which the CPU twin of spread
    // shading reads too. Level l >= 1 is level 0 convolved with a vMF lobe one texel wide.
    LatLongImage image{width, height, rgb};
    const PrefilteredCube cube = prefilterCube(cubeFromLatLong(image, env.faceSize_));
    env.levels_ = static_cast<int>(cube.levels.size());
    glGenTextures(1, &env.texture_);
    glBindTexture(GL_TEXTURE_CUBE_MAP, env.texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int level = 0; level < env.levels_; ++level) {
        const CubeMapImage& c = cube.levels[static_cast<size_t>(level)];
        for (int f = 0; f < 6; ++f)
            glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, level, GL_RGB32F, c.faceSize, c.faceSize,
                         0, GL_RGB, GL_FLOAT, c.faces[f].data());
    }
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, env.levels_ - 1);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glTexParameteri(GL_TEXTURE_CUBE_MAP, wrap, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    env.program_ = buildProgram(shaders::source("fullscreen.vert"), shaders::source("background.frag"), "background");
    glGenVertexArrays(1, &env.vao_);
    return env;
}

Environment::Environment(Environment&& o) noexcept { *this = std::move(o); }

Environment& Environment::operator=(Environment&& o) noexcept {
    std::swap(texture_, o.texture_);
    std::swap(program_, o.program_);
    std::swap(vao_, o.vao_);
    std::swap(faceSize_, o.faceSize_);
    std::swap(levels_, o.levels_);
    return *this;
}

Environment::~Environment() {
    if (!texture_) return;
    try {
        ensureLoaded(currentContextLoader());
    } catch (...) {
        return;
    }
    glDeleteTextures(1, &texture_);
    glDeleteProgram(program_);
    glDeleteVertexArrays(1, &vao_);
}

void Environment::drawBackground(const glm::mat4& view, const glm::mat4& projection, bool toneMap,
                                 float exposure) const {
    ensureLoaded(currentContextLoader());
    GLint viewport[4];
    glGetIntegerv(GL_VIEWPORT, viewport);
    glm::mat4 rotationOnly = glm::mat4(glm::mat3(view));
    glm::mat4 inverse = glm::inverse(projection * rotationOnly);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glUseProgram(program_);
    useEnvironment(program_, *this, 0);
    glUniform1i(glGetUniformLocation(program_, "uToneMap"), toneMap ? 1 : 0);
    glUniform1f(glGetUniformLocation(program_, "uExposure"), exposure);
    glUniformMatrix4fv(glGetUniformLocation(program_, "uInverseViewProjection"), 1, GL_FALSE,
                       glm::value_ptr(inverse));
    glUniform2f(glGetUniformLocation(program_, "uViewport"), float(viewport[2]), float(viewport[3]));
    glUniform2f(glGetUniformLocation(program_, "uViewportOrigin"), float(viewport[0]),
                float(viewport[1]));
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glDepthMask(GL_TRUE);
}

void useEnvironment(unsigned program, const Environment& environment, int unit) {
    glUniform1i(glGetUniformLocation(program, "uEnvironment"), unit);
    glUniform1f(glGetUniformLocation(program, "uEnvironmentFaceSize"), float(environment.faceSize()));
    glUniform1f(glGetUniformLocation(program, "uEnvironmentLevels"), float(environment.levels()));
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_CUBE_MAP, environment.cubeMap());
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
}

}  // namespace shrefract
