#include "bake_data.h"
#include "chart_pipeline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "common/decompress.h"
#include "ior.h"
#include "shaders.h"

namespace shrefract {

using namespace gl;

namespace {

void bindTexture(int unit, GLuint texture) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, texture);
}

void setSamplers(GLuint program, std::initializer_list<const char*> names) {
    glUseProgram(program);
    int unit = 0;
    for (const char* n : names) glUniform1i(glGetUniformLocation(program, n), unit++);
}

}  // namespace

const std::string& ChartPipeline::vertexShader() const {
    return shaders::source("chart_texture.vert");
}

ChartPipeline::ChartPipeline(const PipelineInputs& in)
    : layout_(bakeData(in.bake).layout), settings_(in.settings), width_(layout_.muWidth),
      height_(layout_.muHeight),
      dilation_(std::max(0, in.options.gutter < 0 ? layout_.atlas.gutter : in.options.gutter)),
      seamAware_(in.options.seamAware), mesh_(in.bake, in.memory) {
    const SurfaceLayout& layout = layout_;
    if (in.options.path != RefractorPath::Auto && in.options.path != RefractorPath::Charts)
        throw std::invalid_argument(std::string("shrefract: path \"") + nameOf(in.options.path) +
                                    "\" for a " + nameOf(layout.kind) +
                                    " bake (chart bakes take \"charts\")");
    // The atlas is the refraction map; the unfolded mesh draws it in texture space and shades.
    atlas_.create(width_, height_, GL_LINEAR);
    in.memory.targets += static_cast<size_t>(width_) * height_ * 16;
    glGenVertexArrays(1, &emptyVao_);
    const std::string& full = shaders::source("fullscreen.vert");
    viewProgram_ = buildProgram(vertexShader(), shaders::source("chart_view.frag"),
                                "chart local view");
    dilateProgram_ = buildProgram(full, shaders::source("dilate.frag"), "gutter dilation");
    setSamplers(dilateProgram_, {"uD", "uRings"});
    seamProgram_ = buildProgram(full, shaders::source("seam_fill.frag"), "seam-aware gutters");
    setSamplers(seamProgram_, {"uD", "uRings", "uSeamIndex", "uSeamSample", "uSeamWeight"});
    smoothProgram_ = buildProgram(full, shaders::source("smooth_atlas.frag"), "atlas smoothing");
    setSamplers(smoothProgram_, {"uD", "uRings"});

    // Seam sources: an index per atlas texel into a near-square list of (four texels, weights).
    const std::vector<SeamSource>& seam = layout.atlas.seam;
    seamEntries_ = static_cast<int>(seam.size());
    listWidth_ = std::max(1, static_cast<int>(std::ceil(std::sqrt(double(seam.size())))));
    const int listHeight = std::max(1, (seamEntries_ + listWidth_ - 1) / listWidth_);
    std::vector<uint32_t> index(static_cast<size_t>(width_) * height_, 0u);
    std::vector<uint32_t> texels(static_cast<size_t>(listWidth_) * listHeight * 4, 0u);
    std::vector<float> weights(texels.size(), 0.0f);
    for (size_t e = 0; e < seam.size(); ++e) {
        index[seam[e].texel] = static_cast<uint32_t>(e + 1);
        for (int k = 0; k < 4; ++k) {
            if (seam[e].weight[k] == 0.0f) continue;
            const glm::ivec2 t = layout.muTexel(static_cast<int>(seam[e].sample[k]));
            texels[4 * e + k] = static_cast<uint32_t>(t.y) * width_ + t.x;
            weights[4 * e + k] = seam[e].weight[k];
        }
    }
    seamIndex_ = makeTexture2D(GL_R32UI, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_INT,
                               index.data(), GL_NEAREST);
    seamSample_ = makeTexture2D(GL_RGBA32UI, listWidth_, listHeight, GL_RGBA_INTEGER,
                                GL_UNSIGNED_INT, texels.data(), GL_NEAREST);
    seamWeight_ = makeTexture2D(GL_RGBA32F, listWidth_, listHeight, GL_RGBA, GL_FLOAT,
                                weights.data(), GL_NEAREST);
    glUseProgram(seamProgram_);
    glUniform1i(glGetUniformLocation(seamProgram_, "uListWidth"), listWidth_);
    uploadRings();

    for (int i = 0; i < 2; ++i) {
        pingTex_[i] = makeTexture2D(GL_RGBA32F, width_, height_, GL_RGBA, GL_FLOAT, nullptr,
                                    GL_NEAREST);
        glGenFramebuffers(1, &pingFbo_[i]);
        glBindFramebuffer(GL_FRAMEBUFFER, pingFbo_[i]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, pingTex_[i], 0);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error("shrefract: RGBA32F gutter target incomplete");
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    in.memory.rho = indexBytes();
    in.memory.targets += targetBytes();
    decompression_ = std::make_unique<Decompression>(bakeData(in.bake), in.options, in.maxOrder,
                                                     in.limits, in.form, *this, in.memory);
    prepare();
}

ChartPipeline::~ChartPipeline() {
    for (GLuint p : {viewProgram_, dilateProgram_, seamProgram_, smoothProgram_}) glDeleteProgram(p);
    GLuint textures[] = {rings_, seamIndex_, seamSample_, seamWeight_, pingTex_[0], pingTex_[1]};
    glDeleteTextures(6, textures);
    glDeleteFramebuffers(2, pingFbo_);
    glDeleteVertexArrays(1, &emptyVao_);
    atlas_.destroy();
}

void ChartPipeline::uploadRings() {
    const std::vector<uint8_t> rings = gutterRings(layout_, dilation_);
    if (rings_) glDeleteTextures(1, &rings_);
    rings_ = makeTexture2D(GL_R8UI, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
                           rings.data(), GL_NEAREST);
}

void ChartPipeline::setGutter(int texels) {
    const int width = std::max(0, texels < 0 ? layout_.atlas.gutter : texels);
    if (width == dilation_) return;
    dilation_ = width;
    uploadRings();
}

size_t ChartPipeline::indexBytes() const {
    const size_t texels = static_cast<size_t>(width_) * height_;
    const size_t list = static_cast<size_t>(listWidth_) *
                        std::max(1, (seamEntries_ + listWidth_ - 1) / listWidth_);
    return texels * (1 + 4) + list * 32;  // rings R8UI, index R32UI, RGBA32UI + RGBA32F entries
}

size_t ChartPipeline::targetBytes() const { return 2 * static_cast<size_t>(width_) * height_ * 16; }

void ChartPipeline::localView(glm::vec3 eye) {
    glUseProgram(viewProgram_);
    glUniform3f(glGetUniformLocation(viewProgram_, "uEye"), eye.x, eye.y, eye.z);
    draw();
}

void ChartPipeline::draw() const {
    glBindVertexArray(mesh_.vao());
    glDrawArrays(GL_TRIANGLES, 0, mesh_.vertexCount());
    glBindVertexArray(emptyVao_);
}

void ChartPipeline::pass(GLuint program, GLuint src, GLuint dstFbo) {
    glBindFramebuffer(GL_FRAMEBUFFER, dstFbo);
    glUseProgram(program);
    bindTexture(0, src);
    bindTexture(1, rings_);
    if (program == seamProgram_) {
        bindTexture(2, seamIndex_);
        bindTexture(3, seamSample_);
        bindTexture(4, seamWeight_);
    }
    glBindVertexArray(emptyVao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

GLuint ChartPipeline::fillGutters(GLuint d, GLuint outFbo) {
    glViewport(0, 0, width_, height_);
    // One dilation pass per ring, then the seam sources; a plain copy when there is neither.
    const bool seam = seamAware_ && seamEntries_ > 0 && dilation_ > 0;
    const int passes = std::max(1, dilation_ + (seam ? 1 : 0));
    GLuint src = d;
    for (int i = 0; i < passes; ++i) {
        const bool last = i == passes - 1;
        const GLuint dstFbo = last && outFbo ? outFbo : pingFbo_[i % 2];
        if (seam && last) {
            pass(seamProgram_, src, dstFbo);
        } else {
            glUseProgram(dilateProgram_);
            glUniform1i(glGetUniformLocation(dilateProgram_, "uRing"), i < dilation_ ? i + 1 : 0);
            pass(dilateProgram_, src, dstFbo);
        }
        src = pingTex_[i % 2];
    }
    return outFbo ? 0 : src;
}


int ChartPipeline::passCount() {
    return static_cast<int>(decompression_->compiled(settings_.order).programs.size());
}

void ChartPipeline::update(glm::vec3 eyeObject, bool /*textureD: D_mu is always made*/,
                           const StageClock& clock) {
    eye_ = eyeObject;
    decompression_->run(eyeObject, settings_.order, settings_.smoothing, clock);
    buildMap(clock);
}

void ChartPipeline::buildMap(const StageClock& clock) {
    clock.begin(kUnpack);
    const GLuint filled = fillGutters(decompression_->result(), settings_.smoothing ? 0 : atlas_.fbo);
    clock.end(kUnpack, &Timings::unpack);
    directional_ = decompression_->result();
    if (settings_.smoothing) {
        clock.begin(kSmooth);
        glViewport(0, 0, width_, height_);
        pass(smoothProgram_, filled, atlas_.fbo);
        clock.end(kSmooth, &Timings::smooth);
        directional_ = atlas_.texture;  // readDirectionalMap(): the smoothed values
    }
    ready_ = true;
}

GLuint ChartPipeline::shadingProgram(IorShading* ior) {
    return ior ? ior->program(false, width_) : mesh_.program();
}

void ChartPipeline::draw(GLuint, bool, glm::vec3) { mesh_.draw(atlas_.texture); }

GLuint ChartPipeline::refractionMap() {
    if (!ready_) {
        decompression_->run(eye_, settings_.order, settings_.smoothing, {});
        buildMap({});
    }
    return atlas_.texture;
}

}  // namespace shrefract
