// D_mu in texture space (paper §5.3.2): the local view direction per sample, the generated
// decompression passes (shadergen.h) ping-ponging partial sums, the bake's error model folded in
// (error_fold.h), and the optional smoothing through the neighbour lists. It owns the weights on
// the GPU, so the direct pipeline's vertex-shader decompression binds them from here too.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "common/bakefile.h"
#include "error_fold.h"
#include "gl.h"
#include "pipeline.h"
#include "shadergen.h"

namespace shrefract {

// The weights as they go to the GPU: at the precision they were stored (docs/runtime.md).
enum class WeightFormat { Float32, Float16, Unorm8 };

class Decompression {
public:
    // Uploads bands 0..maxOrder of the weights (at their stored precision, RGBA16F for float32
    // ones when options.halfWeights), the error model (options.errorModel) and the neighbour
    // lists; adds their bytes to `memory`. Throws std::runtime_error when GL cannot hold them.
    Decompression(const BakeData& bake, const RefractorOptions& options, int maxOrder,
                  const ShaderLimits& limits, ShForm form, SampleCover& cover, GpuMemory& memory);
    ~Decompression();
    Decompression(const Decompression&) = delete;
    Decompression& operator=(const Decompression&) = delete;

    struct Compiled {
        DecompressionShaders shaders;
        std::vector<GLuint> programs;  // the texture-space passes
    };
    // The passes of order L, generated and compiled on first use.
    const Compiled& compiled(int L);
    // Local view, passes, error fold and (if `smoothing`) smoothing for `eyeObject`; returns
    // the texture holding D_mu, also result() until the next run.
    GLuint run(glm::vec3 eyeObject, int order, bool smoothing, const StageClock& clock);
    GLuint result() const { return result_; }
    GLuint localViewTexture() const { return localView_.texture; }
    bool canSmooth() const { return rangeTex_ != 0; }
    // The bake's error model is folded into D_mu (ErrorFold): only in texture space.
    bool foldsError() const { return errorFold_ != nullptr; }

    // Binds the weight samplers of `pass` from texture unit `firstUnit` on, in the pass's order.
    void bindWeights(const DecompressionPass& pass, int firstUnit) const;
    // Sets the 8-bit weights' dequantization uniforms on `program` (in use), if they are u8.
    void setWeightUniforms(GLuint program, int coefficients) const;
    const ShaderLimits& limits() const { return limits_; }
    ShForm form() const { return form_; }
    int muWidth() const { return muW_; }
    int muHeight() const { return muH_; }
    // A mu-layout texture read back in sample order (chart bakes: each sample's atlas texel).
    std::vector<float> readSamples(GLuint texture) const;

private:
    const BakeData& bake_;
    SampleCover& cover_;
    GpuMemory& memory_;
    ShaderLimits limits_;
    ShForm form_;
    int muW_ = 0, muH_ = 0, listWidth_ = 1;
    WeightFormat weightFormat_ = WeightFormat::Float32;
    std::vector<float> u8Scale_, u8Offset_;  // per coefficient, 4 each: code / 255 * scale + offset
    std::map<int, Compiled> compiled_;
    GLuint weightArray_ = 0;
    GLuint rangeTexture_ = 0;  // the grid basis's u8 scale and offset (SamplerBinding::WeightRange)
    std::vector<GLuint> weightTex_;  // one per coefficient (the 2006 preset)
    GLuint rangeTex_ = 0, nbrIndexTex_ = 0, nbrWeightTex_ = 0;
    GLuint smoothProgram_ = 0, emptyVao_ = 0;
    gl::Target localView_, sum_[2], smoothed_;
    GLuint result_ = 0;
    std::unique_ptr<ErrorFold> errorFold_;
};

}  // namespace shrefract
