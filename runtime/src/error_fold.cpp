#include "error_fold.h"

#include <stdexcept>
#include <vector>

#include "common/sh.h"
#include "shadergen.h"
#include "shaders.h"

namespace shrefract {

using namespace gl;

ErrorFold::ErrorFold(const BakeData& bake, const std::vector<size_t>& texelOf,
                     const std::string& vertexShader)
    : width_(bake.layout.muWidth), height_(bake.layout.muHeight) {
    const int Ke = bake.errorCoefficientCount(), n = bake.layout.sampleCount();
    const size_t texels = size_t(width_) * height_;
    // One layer per coefficient, red only: the generated shPass() reads layer k as e_k's weight
    // and accumulates it in .x (the other channels read 0 and 1, and are ignored).
    glGenTextures(1, &errors_);
    glBindTexture(GL_TEXTURE_2D_ARRAY, errors_);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R16F, width_, height_, Ke, 0, GL_RED, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    std::vector<float> layer(texels, 0.0f);
    for (int k = 0; k < Ke; ++k) {
        for (int i = 0; i < n; ++i) layer[texelOf[i]] = bake.errors[size_t(k) * n + i];
        glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, k, width_, height_, 1, GL_RED, GL_FLOAT, layer.data());
    }
    // The SH of the error model as the weights' are generated: one pass, weights in an array.
    ShaderLimits limits = shaderPreset(ShaderPreset::Modern, 16);
    const DecompressionShaders sh = generateDecompression(bake.errorOrder, limits, ShForm::Polynomial);
    if (sh.passes.size() != 1) throw std::logic_error("shrefract: the error model needs one pass");
    program_ = buildProgram(vertexShader,
                            shaders::withVersion(shaders::fill(shaders::source("error_fold.frag"),
                                                               "#pragma shrefract_generated",
                                                               sh.passes[0].generated),
                                                 limits.version),
                            "error model");
    glUseProgram(program_);
    glUniform1i(glGetUniformLocation(program_, "uLocalView"), 0);
    glUniform1i(glGetUniformLocation(program_, "uD"), 1);
    glUniform1i(glGetUniformLocation(program_, "uWeights"), 2);
    target_.create(width_, height_, GL_NEAREST);
    // Charts draw only their footprint: the texels around it stay 0, as in the other mu targets.
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    bytes_ = texels * (size_t(Ke) * 2 + 16);
}

ErrorFold::~ErrorFold() {
    target_.destroy();
    if (errors_) glDeleteTextures(1, &errors_);
    if (program_) glDeleteProgram(program_);
}

unsigned ErrorFold::apply(unsigned d, unsigned localView, const std::function<void()>& draw) {
    glBindFramebuffer(GL_FRAMEBUFFER, target_.fbo);
    glUseProgram(program_);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, localView);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, d);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D_ARRAY, errors_);
    draw();
    return target_.texture;
}

}  // namespace shrefract
