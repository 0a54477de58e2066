// The isolated-surface pipeline (paper §5.2, Figure 6) for chart layouts (isolated, uv):
//   local view   the unfolded mesh drawn in texture space (chart_texture.vert, chart_view.frag);
//   D_mu         the generated decompression passes, rasterizing the same mesh: only the
//                covered texels are decompressed (this class is their SampleCover);
//   D+_mu        dilation into the gutters, one pass per ring (dilate.frag), then seam-aware
//                sources (seam_fill.frag);
//   smoothing    a local filter in texture space (smooth_atlas.frag);
// and the result is the refraction map in the atlas layout, which the shading pass looks up as
// on the rho pipeline (rho_map.h MapMesh), and an app's own material can too. The CPU twin is
// common/decompress.h chartRefractionMap.
#pragma once

#include <cstddef>
#include <memory>

#include <glm/glm.hpp>

#include "common/bakefile.h"
#include "decompression.h"
#include "gl.h"
#include "pipeline.h"
#include "rho_map.h"

namespace shrefract {

class ChartPipeline : public Pipeline, public SampleCover {
public:
    // Throws std::invalid_argument for a path other than auto or charts, std::runtime_error on
    // GL failure.
    explicit ChartPipeline(const PipelineInputs& in);
    ~ChartPipeline() override;
    ChartPipeline(const ChartPipeline&) = delete;
    ChartPipeline& operator=(const ChartPipeline&) = delete;

    // Pipeline
    RefractorPath path() const override { return RefractorPath::Charts; }
    Decompression& decompression() override { return *decompression_; }
    void prepare() override { decompression_->compiled(settings_.order); }
    int passCount() override;
    void update(glm::vec3 eyeObject, bool textureD, const StageClock& clock) override;
    GLuint shadingProgram(IorShading* ior) override;
    void draw(GLuint program, bool ior, glm::vec3 eyeObject) override;
    GLuint refractionMap() override;
    glm::ivec2 refractionMapSize() const override { return {width_, height_}; }
    GLuint directionalMap() override { return directional_; }
    void setGutter(int texels) override;
    int gutter() const override { return dilation_; }
    void setSeamAware(bool on) override { seamAware_ = on; }
    bool seamAware() const override { return seamAware_; }

    // SampleCover: the unfolded mesh in texture space.
    const std::string& vertexShader() const override;
    void localView(glm::vec3 eyeObject) override;
    void draw() const override;
    bool partial() const override { return true; }

private:
    // D -> D+ (the unpack's place in the timings) -> [texture-space smoothing] into the atlas.
    void buildMap(const StageClock& clock);
    // D -> D+: the dilation rings and the seam-aware sources. The last pass writes into
    // `outFbo` when it is not 0; returns the texture holding D+ otherwise.
    GLuint fillGutters(GLuint d, GLuint outFbo);
    void uploadRings();
    void pass(GLuint program, GLuint src, GLuint dstFbo);
    size_t indexBytes() const;  // the ring map and the seam sources
    size_t targetBytes() const;  // the two ping-pong targets

    const SurfaceLayout& layout_;
    const PipelineSettings& settings_;
    int width_ = 0, height_ = 0;
    int dilation_ = 0, seamEntries_ = 0, listWidth_ = 1;
    bool seamAware_ = true;
    gl::Target atlas_;  // the refraction map
    MapMesh mesh_;      // also the unfolded mesh the texture-space passes rasterize
    GLuint emptyVao_ = 0;
    GLuint viewProgram_ = 0, dilateProgram_ = 0, seamProgram_ = 0, smoothProgram_ = 0;
    GLuint rings_ = 0, seamIndex_ = 0, seamSample_ = 0, seamWeight_ = 0;
    GLuint pingTex_[2] = {0, 0}, pingFbo_[2] = {0, 0};
    std::unique_ptr<Decompression> decompression_;
    glm::vec3 eye_{0, 0, 3};
    GLuint directional_ = 0;  // D_mu of the last update (the atlas when smoothed)
    bool ready_ = false;      // the atlas holds the map for the last update()
};

}  // namespace shrefract
