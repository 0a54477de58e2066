// The paper's pipeline for joining bakes (paper §5.3, Figure 9): local view -> D_mu (generated
// passes) -> [smoothing] -> unpack into the rho layout with interpolation-correction texels ->
// shade the mesh with a bilinear lookup in rho. The refraction map is built every frame.
#pragma once

#include "decompression.h"
#include "pipeline.h"
#include "rho_map.h"
#include "sample_grid.h"

namespace shrefract {

class RhoPipeline : public Pipeline {
public:
    explicit RhoPipeline(const PipelineInputs& in);  // throws on GL failure

    RefractorPath path() const override { return RefractorPath::Rho; }
    Decompression& decompression() override { return decompression_; }
    void prepare() override { decompression_.compiled(settings_.order); }
    int passCount() override;
    void update(glm::vec3 eyeObject, bool textureD, const StageClock& clock) override;
    GLuint shadingProgram(IorShading* ior) override;
    void draw(GLuint program, bool ior, glm::vec3 eyeObject) override;
    GLuint refractionMap() override;
    glm::ivec2 refractionMapSize() const override { return map_.size(); }
    GLuint directionalMap() override { return decompression_.result(); }

private:
    const PipelineSettings& settings_;
    SampleGrid grid_;
    Decompression decompression_;
    RhoMap map_;
    MapMesh mesh_;
    bool ready_ = false;  // the map holds the last update()'s D
};

}  // namespace shrefract
