#include "rho_map.h"

#include "shaders.h"

namespace shrefract {

using namespace gl;

RhoMap::RhoMap(const SurfaceLayout& L, GpuMemory& memory) : width_(L.rhoWidth), height_(L.rhoHeight) {
    // Which sample (or correction) each texel shows; RhoTexel is four uint32.
    static_assert(sizeof(RhoTexel) == 4 * sizeof(uint32_t));
    index_ = makeTexture2D(GL_RGBA32UI, width_, height_, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                           L.rho.data(), GL_NEAREST);
    memory.rho = static_cast<size_t>(width_) * height_ * 16;
    target_.create(width_, height_, GL_LINEAR);
    memory.targets += static_cast<size_t>(width_) * height_ * 16;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    program_ = buildProgram(shaders::source("fullscreen.vert"), shaders::source("unpack.frag"), "unpack");
    glUseProgram(program_);
    glUniform1i(glGetUniformLocation(program_, "uRhoIndex"), 0);
    glUniform1i(glGetUniformLocation(program_, "uD"), 1);
    glUniform1i(glGetUniformLocation(program_, "uMuWidth"), L.muWidth);
    glUseProgram(0);
    glGenVertexArrays(1, &emptyVao_);
}

RhoMap::~RhoMap() {
    glDeleteProgram(program_);
    glDeleteTextures(1, &index_);
    glDeleteVertexArrays(1, &emptyVao_);
    target_.destroy();
}

void RhoMap::unpack(GLuint d, bool correction, const StageClock& clock) {
    clock.begin(kUnpack);
    glViewport(0, 0, width_, height_);
    glBindFramebuffer(GL_FRAMEBUFFER, target_.fbo);
    glBindVertexArray(emptyVao_);
    glUseProgram(program_);
    glUniform1i(glGetUniformLocation(program_, "uCorrection"), correction ? 1 : 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, index_);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, d);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    clock.end(kUnpack, &Timings::unpack);
}

MapMesh::MapMesh(const Bake& bake, GpuMemory& memory) {
    program_ = buildProgram(shaders::source("shade.vert"), shaders::source("shade.frag"), "shading");
    glUseProgram(program_);
    glUniform1i(glGetUniformLocation(program_, "uRho"), 1);
    glUseProgram(0);
    static_assert(sizeof(MapVertex) == 8 * sizeof(float));
    const std::vector<MapVertex> vertices = bake.refractionMapMesh();
    vertices_ = static_cast<int>(vertices.size());
    glGenVertexArrays(1, &vao_);
    glBindVertexArray(vao_);
    glGenBuffers(1, &vbo_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(MapVertex), vertices.data(), GL_STATIC_DRAW);
    for (int a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    memory.mesh = vertices.size() * sizeof(MapVertex);
}

MapMesh::~MapMesh() {
    glDeleteProgram(program_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteBuffers(1, &vbo_);
}

void MapMesh::draw(GLuint map) const {
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, map);
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLES, 0, vertices_);
}

}  // namespace shrefract
