#include "decompression.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "common/sh.h"
#include "shaders.h"

namespace shrefract {

using namespace gl;

namespace {

void bindTexture(int unit, GLenum target, GLuint texture) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, texture);
}

}  // namespace

Decompression::Decompression(const BakeData& d, const RefractorOptions& options, int maxOrder,
                             const ShaderLimits& limits, ShForm form, SampleCover& cover,
                             GpuMemory& memory)
    : bake_(d), cover_(cover), memory_(memory), limits_(limits), form_(form) {
    const SurfaceLayout& L = d.layout;
    const int n = L.sampleCount();
    muW_ = L.muWidth, muH_ = L.muHeight;
    const size_t muTexels = static_cast<size_t>(muW_) * muH_;
    // Weights at their stored precision: u8 codes as RGBA8 UNORM (dequantized in the shader),
    // f16 as RGBA16F, f32 as RGBA32F (RGBA16F when the app asks for half).
    weightFormat_ = d.precision == Precision::U8    ? WeightFormat::Unorm8
                    : d.precision == Precision::F16 ? WeightFormat::Float16
                    : options.halfWeights           ? WeightFormat::Float16
                                                    : WeightFormat::Float32;
    limits_.unormWeights = weightFormat_ == WeightFormat::Unorm8;
    const bool grid = d.basis == Basis::Grid;
    if (grid && !limits_.weightArray)
        throw std::invalid_argument("shrefract: a grid-basis bake needs the modern preset (its " +
                                    std::to_string(d.coefficientCount()) +
                                    " weight layers go in one texture array)");
    const int K = grid ? d.coefficientCount() : shEvenCount(maxOrder);
    if (limits_.unormWeights) {
        u8Scale_.resize(size_t(K) * 4);
        u8Offset_.resize(size_t(K) * 4);
        for (size_t i = 0; i < u8Scale_.size(); ++i) {
            u8Scale_[i] = d.u8Scale[i] * 255.0f;  // the texel is code / 255
            u8Offset_[i] = d.u8Offset[i];
        }
    }
    // Where sample i sits in the mu textures: texel i, or its atlas texel for chart bakes.
    std::vector<size_t> texelOf(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const glm::ivec2 t = L.muTexel(i);
        texelOf[i] = static_cast<size_t>(t.y) * muW_ + t.x;
    }

    // Only bands 0..maxOrder go to the GPU: the weights are coefficient-major, so those are the
    // first shEvenCount(maxOrder) layers.
    GLenum internal = GL_RGBA32F, type = GL_FLOAT;
    size_t texelBytes = 16;
    if (weightFormat_ == WeightFormat::Float16) internal = GL_RGBA16F, texelBytes = 8;
    if (weightFormat_ == WeightFormat::Unorm8) internal = GL_RGBA8, type = GL_UNSIGNED_BYTE, texelBytes = 4;
    memory_.weights = K * muTexels * texelBytes;
    if (limits_.weightArray) {
        // GL 3.3 guarantees 256 layers (order 20 needs 231); llvmpipe allows 2048.
        GLint maxLayers = 256;
        glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
        if (K > maxLayers)
            throw std::runtime_error("shrefract: " +
                                     (grid ? "grid " + d.grid.ToString()
                                           : "order " + std::to_string(maxOrder)) +
                                     " needs " + std::to_string(K) + " weight layers, GL allows " +
                                     std::to_string(maxLayers) +
                                     (grid ? " (bake a coarser --grid)" : " (set maxOrder lower)"));
        glGenTextures(1, &weightArray_);
        glBindTexture(GL_TEXTURE_2D_ARRAY, weightArray_);
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, internal, muW_, muH_, K, 0, GL_RGBA, type, nullptr);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    std::vector<float> padded(muTexels * 4, 0.0f);
    std::vector<uint8_t> codes(muTexels * 4, 0);
    for (int k = 0; k < K; ++k) {
        const float* w = &d.weights[static_cast<size_t>(k) * n * 4];
        const void* data = padded.data();
        if (weightFormat_ == WeightFormat::Unorm8) {
            // The file's codes again: the dequantized weights map back exactly (round to nearest).
            for (size_t i = 0; i < size_t(n) * 4; ++i) {
                const double scale = d.u8Scale[k * 4 + i % 4], offset = d.u8Offset[k * 4 + i % 4];
                const double code = scale > 0 ? std::nearbyint((double(w[i]) - offset) / scale) : 0.0;
                codes[texelOf[i / 4] * 4 + i % 4] = static_cast<uint8_t>(std::clamp(code, 0.0, 255.0));
            }
            data = codes.data();
        } else {
            for (int i = 0; i < n; ++i) std::memcpy(&padded[texelOf[i] * 4], &w[size_t(i) * 4], 4 * sizeof(float));
        }
        if (limits_.weightArray)
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, k, muW_, muH_, 1, GL_RGBA, type, data);
        else
            weightTex_.push_back(makeTexture2D(internal, muW_, muH_, GL_RGBA, type, data, GL_NEAREST));
    }
    if (grid && limits_.unormWeights) {  // the dequantization as a K x 2 texture (shadergen.h)
        std::vector<float> range(size_t(K) * 8);
        std::copy(u8Scale_.begin(), u8Scale_.end(), range.begin());
        std::copy(u8Offset_.begin(), u8Offset_.end(), range.begin() + size_t(K) * 4);
        rangeTexture_ = makeTexture2D(GL_RGBA32F, K, 2, GL_RGBA, GL_FLOAT, range.data(), GL_NEAREST);
        memory_.weights += range.size() * sizeof(float);
    }
    // The fold feeds the lobe; sharp shading draws none, so it neither uploads nor runs it.
    if (d.errorOrder >= 0 && options.errorModel && options.shading != Shading::Sharp) {
        errorFold_ = std::make_unique<ErrorFold>(d, texelOf, cover_.vertexShader());
        memory_.weights += errorFold_->bytes();
    }
    // Neighbour lists (CSR) for smoothing.
    if (!L.neighbourIndex.empty() && L.neighbourOffset.size() == static_cast<size_t>(n)) {
        std::vector<uint32_t> range(muTexels * 2, 0);
        for (int i = 0; i < n; ++i) {
            range[2 * i] = L.neighbourOffset[i];
            range[2 * i + 1] = L.neighbourCount[i];
        }
        rangeTex_ = makeTexture2D(GL_RG32UI, muW_, muH_, GL_RG_INTEGER, GL_UNSIGNED_INT,
                                  range.data(), GL_NEAREST);
        const size_t total = L.neighbourIndex.size();
        listWidth_ = static_cast<int>(std::min<size_t>(total, 4096));
        const int listH = static_cast<int>((total + listWidth_ - 1) / listWidth_);
        std::vector<uint32_t> idx(static_cast<size_t>(listWidth_) * listH, 0);
        std::vector<float> wts(idx.size(), 0.0f);
        std::copy(L.neighbourIndex.begin(), L.neighbourIndex.end(), idx.begin());
        std::copy(L.neighbourWeight.begin(), L.neighbourWeight.end(), wts.begin());
        nbrIndexTex_ = makeTexture2D(GL_R32UI, listWidth_, listH, GL_RED_INTEGER, GL_UNSIGNED_INT,
                                     idx.data(), GL_NEAREST);
        nbrWeightTex_ = makeTexture2D(GL_R32F, listWidth_, listH, GL_RED, GL_FLOAT, wts.data(),
                                      GL_NEAREST);
        memory_.neighbours = muTexels * 8 + idx.size() * 4 + wts.size() * 4;
    }
    smoothProgram_ = buildProgram(shaders::source("fullscreen.vert"), shaders::source("smooth.frag"), "smoothing");
    glUseProgram(smoothProgram_);
    const char* smoothSamplers[] = {"uD", "uRange", "uNbrIndex", "uNbrWeight"};
    for (int u = 0; u < 4; ++u) glUniform1i(glGetUniformLocation(smoothProgram_, smoothSamplers[u]), u);
    glUniform1i(glGetUniformLocation(smoothProgram_, "uMuWidth"), muW_);
    glUniform1i(glGetUniformLocation(smoothProgram_, "uListWidth"), listWidth_);
    glUseProgram(0);
    glGenVertexArrays(1, &emptyVao_);
}

Decompression::~Decompression() {
    for (auto& [L, c] : compiled_)
        for (GLuint p : c.programs) glDeleteProgram(p);
    glDeleteProgram(smoothProgram_);
    for (GLuint t : {weightArray_, rangeTexture_, rangeTex_, nbrIndexTex_, nbrWeightTex_})
        if (t) glDeleteTextures(1, &t);
    if (!weightTex_.empty())
        glDeleteTextures(static_cast<GLsizei>(weightTex_.size()), weightTex_.data());
    for (Target* t : {&localView_, &sum_[0], &sum_[1], &smoothed_}) t->destroy();
    glDeleteVertexArrays(1, &emptyVao_);
}

void Decompression::bindWeights(const DecompressionPass& pass, int firstUnit) const {
    int unit = firstUnit;
    for (const SamplerBinding& s : pass.samplers) {
        if (s.kind == SamplerBinding::Weight) bindTexture(unit++, GL_TEXTURE_2D, weightTex_[s.coefficient]);
        if (s.kind == SamplerBinding::WeightArray) bindTexture(unit++, GL_TEXTURE_2D_ARRAY, weightArray_);
        if (s.kind == SamplerBinding::WeightRange) bindTexture(unit++, GL_TEXTURE_2D, rangeTexture_);
    }
}

void Decompression::setWeightUniforms(GLuint program, int K) const {
    if (weightFormat_ != WeightFormat::Unorm8 || bake_.basis == Basis::Grid) return;
    glUniform4fv(glGetUniformLocation(program, "uWeightScale"), K, u8Scale_.data());
    glUniform4fv(glGetUniformLocation(program, "uWeightOffset"), K, u8Offset_.data());
}

const Decompression::Compiled& Decompression::compiled(int L) {
    auto it = compiled_.find(L);
    if (it != compiled_.end()) return it->second;
    Compiled c;
    c.shaders = bake_.basis == Basis::Grid
                    ? generateGridDecompression(bake_.grid.nTheta, bake_.grid.nPhi, limits_)
                    : generateDecompression(L, limits_, form_);
    const int K = shEvenCount(L);
    for (size_t i = 0; i < c.shaders.passes.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        GLuint p = buildProgram(cover_.vertexShader(), pass.fragment,
                                "decompression pass " + std::to_string(i + 1) + " (" +
                                    c.shaders.summary() + ")");
        glUseProgram(p);
        for (size_t u = 0; u < pass.samplers.size(); ++u)
            glUniform1i(glGetUniformLocation(p, pass.samplers[u].name.c_str()), static_cast<int>(u));
        setWeightUniforms(p, K);
        c.programs.push_back(p);
    }
    glUseProgram(0);
    return compiled_.emplace(L, std::move(c)).first->second;
}

GLuint Decompression::run(glm::vec3 eyeObject, int order, bool smoothing, const StageClock& clock) {
    const size_t muBytes = static_cast<size_t>(muW_) * muH_ * 16;  // one RGBA32F mu target
    if (!localView_.fbo) {  // made on first use
        localView_.create(muW_, muH_, GL_NEAREST);
        sum_[0].create(muW_, muH_, GL_NEAREST);
        sum_[1].create(muW_, muH_, GL_NEAREST);
        memory_.targets += 3 * muBytes;
        if (cover_.partial()) {  // the passes draw the cover only: the texels around it stay 0
            for (Target* t : {&localView_, &sum_[0], &sum_[1]}) {
                glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
                glClearColor(0, 0, 0, 0);
                glClear(GL_COLOR_BUFFER_BIT);
            }
        }
    }
    if (smoothing && rangeTex_ && !smoothed_.fbo) {
        smoothed_.create(muW_, muH_, GL_NEAREST);
        memory_.targets += muBytes;
    }
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindVertexArray(emptyVao_);
    glViewport(0, 0, muW_, muH_);

    // The local view direction per sample.
    clock.begin(kView);
    glBindFramebuffer(GL_FRAMEBUFFER, localView_.fbo);
    cover_.localView(eyeObject);
    clock.end(kView, &Timings::view);

    // D_mu: the generated passes, partial sums ping-ponging between sum[0] and sum[1].
    const Compiled& c = compiled(order);
    clock.begin(kDecompress);
    for (size_t i = 0; i < c.programs.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        glBindFramebuffer(GL_FRAMEBUFFER, sum_[i % 2].fbo);
        glUseProgram(c.programs[i]);
        for (size_t u = 0; u < pass.samplers.size(); ++u) {
            const SamplerBinding& s = pass.samplers[u];
            const int unit = static_cast<int>(u);
            switch (s.kind) {
                case SamplerBinding::LocalView:
                    bindTexture(unit, GL_TEXTURE_2D, localView_.texture);
                    break;
                case SamplerBinding::PartialSum:
                    bindTexture(unit, GL_TEXTURE_2D, sum_[(i + 1) % 2].texture);
                    break;
                case SamplerBinding::Weight:
                    bindTexture(unit, GL_TEXTURE_2D, weightTex_[s.coefficient]);
                    break;
                case SamplerBinding::WeightArray:
                    bindTexture(unit, GL_TEXTURE_2D_ARRAY, weightArray_);
                    break;
                case SamplerBinding::WeightRange:
                    bindTexture(unit, GL_TEXTURE_2D, rangeTexture_);
                    break;
            }
        }
        cover_.draw();
    }
    clock.end(kDecompress, &Timings::decompress);
    if (clock.timed()) clock.timings->passes = static_cast<int>(c.programs.size());
    result_ = sum_[(c.programs.size() + 1) % 2].texture;
    if (errorFold_) result_ = errorFold_->apply(result_, localView_.texture, [&] { cover_.draw(); });

    // Optional spatial smoothing through the neighbour lists.
    if (clock.timed()) clock.timings->smooth = 0;
    if (smoothing && rangeTex_) {
        clock.begin(kSmooth);
        glBindFramebuffer(GL_FRAMEBUFFER, smoothed_.fbo);
        glUseProgram(smoothProgram_);
        bindTexture(0, GL_TEXTURE_2D, result_);
        bindTexture(1, GL_TEXTURE_2D, rangeTex_);
        bindTexture(2, GL_TEXTURE_2D, nbrIndexTex_);
        bindTexture(3, GL_TEXTURE_2D, nbrWeightTex_);
        glBindVertexArray(emptyVao_);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        clock.end(kSmooth, &Timings::smooth);
        result_ = smoothed_.texture;
    }
    return result_;
}

std::vector<float> Decompression::readSamples(GLuint texture) const {
    const std::vector<float> all = readTextureRGBA(texture, muW_, muH_);
    const SurfaceLayout& L = bake_.layout;
    std::vector<float> samples(static_cast<size_t>(L.sampleCount()) * 4);
    for (int i = 0; i < L.sampleCount(); ++i) {
        const glm::ivec2 t = L.muTexel(i);
        std::copy_n(&all[(static_cast<size_t>(t.y) * muW_ + t.x) * 4], 4, &samples[size_t(i) * 4]);
    }
    return samples;
}

}  // namespace shrefract
