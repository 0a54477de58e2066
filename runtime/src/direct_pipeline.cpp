#include "bake_data.h"
#include "direct_pipeline.h"

#include <stdexcept>

#include "common/error.h"
#include "common/sh.h"
#include "ior.h"
#include "shaders.h"

namespace shrefract {

using namespace gl;

DirectPipeline::DirectPipeline(const PipelineInputs& in)
    : layout_(bakeData(in.bake).layout),
      settings_(in.settings),
      memory_(in.memory),
      grid_(layout_, in.memory),
      decompression_(bakeData(in.bake), in.options, in.maxOrder, in.limits, in.form, grid_, in.memory) {
    const DecompressionSite site = in.options.decompression;
    // A single decompression pass (the modern preset) can run in the shading's vertex shader.
    const bool onePass = decompression_.compiled(settings_.order).programs.size() == 1;
    if (site == DecompressionSite::Vertex && !onePass)
        throw std::invalid_argument("shrefract: vertex decompression needs a one-pass preset");
    vertexAllowed_ = onePass && site != DecompressionSite::Texture;
    vertexRequired_ = site == DecompressionSite::Vertex;

    // The refined mesh: one vertex per mu sample (no attributes: gl_VertexID), and every
    // triangle's regular subdivision as indices (common/bakefile.h refinedTriangles).
    const std::vector<uint32_t> indices = refinedTriangles(layout_);
    indexCount_ = static_cast<int>(indices.size());
    glGenVertexArrays(1, &vao_);
    glBindVertexArray(vao_);
    glGenBuffers(1, &indices_);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices_);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, indices.size() * sizeof(uint32_t), indices.data(),
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
    in.memory.mesh = indices.size() * sizeof(uint32_t);
    if (!vertexMode()) textureProgram();
    prepare();
}

DirectPipeline::~DirectPipeline() {
    for (auto& [L, p] : vertexPrograms_) glDeleteProgram(p);
    if (textureProgram_) glDeleteProgram(textureProgram_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteBuffers(1, &indices_);
}

bool DirectPipeline::vertexMode() const {
    return vertexAllowed_ && !settings_.smoothing &&
           (vertexRequired_ || (settings_.order <= kAutoVertexMaxOrder && !decompression_.foldsError()));
}

void DirectPipeline::prepare() {
    decompression_.compiled(settings_.order);
    if (vertexAllowed_) vertexProgram(settings_.order);
}

int DirectPipeline::passCount() {
    return vertexMode() ? 0 : static_cast<int>(decompression_.compiled(settings_.order).programs.size());
}

void DirectPipeline::checkSmoothing(bool on) const {
    if (on && vertexRequired_)
        throw std::invalid_argument(
            "shrefract: smoothing needs texture-space decompression (decompression \"vertex\" was asked for)");
}

GLuint DirectPipeline::vertexProgram(int order) {
    auto it = vertexPrograms_.find(order);
    if (it != vertexPrograms_.end()) return it->second;
    // The one pass's generated shPass() inside the direct shading's vertex shader.
    const Decompression::Compiled& c = decompression_.compiled(order);
    SHREFRACT_CHECK(c.shaders.passes.size() == 1);
    const DecompressionPass& pass = c.shaders.passes[0];
    const std::string version = decompression_.limits().version;
    const std::string vs = shaders::withVersion(
        shaders::fill(shaders::source("shade_direct.vert"), "#pragma shrefract_generated", pass.generated),
        version, "#define SHREFRACT_VERTEX_SH");
    const std::string fs = shaders::withVersion(shaders::source("shade.frag"), version, "#define SHREFRACT_DIRECT");
    const GLuint p = buildProgram(vs, fs, "direct shading with vertex decompression (" + c.shaders.summary() + ")");
    glUseProgram(p);
    glUniform1i(glGetUniformLocation(p, "uPosition"), 2);
    glUniform1i(glGetUniformLocation(p, "uNormal"), 3);
    glUniform1i(glGetUniformLocation(p, "uMuWidth"), decompression_.muWidth());
    // Units 0 and 1 are the environment and (unused here) D; weights from unit 4 on.
    int unit = 4;
    for (const SamplerBinding& s : pass.samplers)
        if (s.kind == SamplerBinding::Weight || s.kind == SamplerBinding::WeightArray ||
            s.kind == SamplerBinding::WeightRange)
            glUniform1i(glGetUniformLocation(p, s.name.c_str()), unit++);
    decompression_.setWeightUniforms(p, shEvenCount(order));
    glUseProgram(0);
    return vertexPrograms_.emplace(order, p).first->second;
}

GLuint DirectPipeline::textureProgram() {
    if (textureProgram_) return textureProgram_;
    textureProgram_ = buildProgram(
        shaders::source("shade_direct.vert"),
        shaders::withVersion(shaders::source("shade.frag"), "330 core", "#define SHREFRACT_DIRECT"),
        "direct shading");
    glUseProgram(textureProgram_);
    glUniform1i(glGetUniformLocation(textureProgram_, "uD"), 1);
    glUniform1i(glGetUniformLocation(textureProgram_, "uPosition"), 2);
    glUniform1i(glGetUniformLocation(textureProgram_, "uNormal"), 3);
    glUniform1i(glGetUniformLocation(textureProgram_, "uMuWidth"), decompression_.muWidth());
    glUseProgram(0);
    return textureProgram_;
}

void DirectPipeline::update(glm::vec3 eyeObject, bool textureD, const StageClock& clock) {
    eye_ = eyeObject;
    ready_ = false;
    const int L = settings_.order;
    if (!vertexMode()) {
        decompression_.run(eyeObject, L, settings_.smoothing, clock);
    } else if (textureD || map_) {
        // Everything else happens in draw(); D_mu in texture space only for who asked for it.
        decompression_.run(eyeObject, L, settings_.smoothing, textureD ? clock : StageClock{});
    }
    if (map_) {  // an app that asked for the refraction map keeps getting it
        map_->unpack(decompression_.result(), settings_.correction, {});
        ready_ = true;
    }
}

GLuint DirectPipeline::shadingProgram(IorShading* ior) {
    if (ior) return ior->program(true, decompression_.muWidth());
    return vertexMode() ? vertexProgram(settings_.order) : textureProgram();
}

void DirectPipeline::draw(GLuint program, bool ior, glm::vec3 eyeObject) {
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, decompression_.result());
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, grid_.positions());
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, grid_.normals());
    if (!ior && vertexMode()) {
        // The eye in object space, and the weights from unit 4 on (vertexProgram's assignment).
        glUniform3f(glGetUniformLocation(program, "uEyeObject"), eyeObject.x, eyeObject.y, eyeObject.z);
        decompression_.bindWeights(decompression_.compiled(settings_.order).shaders.passes[0], 4);
    }
    glBindVertexArray(vao_);
    glDrawElements(GL_TRIANGLES, indexCount_, GL_UNSIGNED_INT, nullptr);
}

GLuint DirectPipeline::refractionMap() {
    if (!map_) map_ = std::make_unique<RhoMap>(layout_, memory_);
    if (!ready_) {
        if (vertexMode()) decompression_.run(eye_, settings_.order, settings_.smoothing, {});
        map_->unpack(decompression_.result(), settings_.correction, {});
        ready_ = true;
    }
    return map_->texture();
}

GLuint DirectPipeline::directionalMap() {
    // With vertex decompression: the same generated shPass(), run in texture space for the last eye.
    if (vertexMode()) decompression_.run(eye_, settings_.order, settings_.smoothing, {});
    return decompression_.result();
}

}  // namespace shrefract
