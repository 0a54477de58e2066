#include "sample_grid.h"

#include <cstring>

#include "shaders.h"

namespace shrefract {

using namespace gl;

namespace {

// Per-sample vec3s, padded into a mu-sized RGB float image.
std::vector<float> muImage3(const std::vector<glm::vec3>& v, int w, int h) {
    std::vector<float> out(static_cast<size_t>(w) * h * 3, 0.0f);
    std::memcpy(out.data(), v.data(), v.size() * sizeof(glm::vec3));
    return out;
}

}  // namespace

SampleGrid::SampleGrid(const SurfaceLayout& L, GpuMemory& memory) {
    const int w = L.muWidth, h = L.muHeight;
    position_ = makeTexture2D(GL_RGB32F, w, h, GL_RGB, GL_FLOAT, muImage3(L.position, w, h).data(), GL_NEAREST);
    normal_ = makeTexture2D(GL_RGB32F, w, h, GL_RGB, GL_FLOAT, muImage3(L.normal, w, h).data(), GL_NEAREST);
    memory.samples = 2 * static_cast<size_t>(w) * h * 12;  // RGB32F
    viewProgram_ = buildProgram(shaders::source("fullscreen.vert"), shaders::source("local_view.frag"), "local view");
    glUseProgram(viewProgram_);
    glUniform1i(glGetUniformLocation(viewProgram_, "uPosition"), 0);
    glUniform1i(glGetUniformLocation(viewProgram_, "uNormal"), 1);
    glUseProgram(0);
}

SampleGrid::~SampleGrid() {
    glDeleteProgram(viewProgram_);
    for (GLuint t : {position_, normal_}) glDeleteTextures(1, &t);
}

const std::string& SampleGrid::vertexShader() const { return shaders::source("fullscreen.vert"); }

void SampleGrid::localView(glm::vec3 eye) {
    glUseProgram(viewProgram_);
    glUniform3f(glGetUniformLocation(viewProgram_, "uEye"), eye.x, eye.y, eye.z);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, position_);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, normal_);
    draw();
}

void SampleGrid::draw() const { glDrawArrays(GL_TRIANGLES, 0, 3); }  // the full-screen triangle

}  // namespace shrefract
