// The direct pipeline for joining bakes on GPUs that fetch textures in the vertex shader: the
// sample grid drawn as a refined mesh (every triangle's barycentric grid), D fetched per vertex
// and interpolated by the rasterizer. D comes from the texture-space decompression passes, or,
// with vertex decompression, from the shading pass's own vertex shader, which evaluates the SH at
// each sample (one draw). The rho refraction map is built only for an app that asks for it, and
// then kept up to date by every update().
#pragma once

#include <map>
#include <memory>

#include "decompression.h"
#include "pipeline.h"
#include "rho_map.h"
#include "sample_grid.h"

namespace shrefract {

class DirectPipeline : public Pipeline {
public:
    // Throws std::invalid_argument for a vertex decompression the limits cannot give (one pass),
    // std::runtime_error on GL failure.
    explicit DirectPipeline(const PipelineInputs& in);
    ~DirectPipeline() override;

    RefractorPath path() const override { return RefractorPath::Direct; }
    DecompressionSite decompressionSite() const override {
        return vertexMode() ? DecompressionSite::Vertex : DecompressionSite::Texture;
    }
    Decompression& decompression() override { return decompression_; }
    void prepare() override;
    int passCount() override;
    void checkSmoothing(bool on) const override;
    void update(glm::vec3 eyeObject, bool textureD, const StageClock& clock) override;
    GLuint shadingProgram(IorShading* ior) override;
    void draw(GLuint program, bool ior, glm::vec3 eyeObject) override;
    GLuint refractionMap() override;
    glm::ivec2 refractionMapSize() const override { return {layout_.rhoWidth, layout_.rhoHeight}; }
    GLuint directionalMap() override;
    GLuint bracketInput(Pipeline& other) override { return other.directionalMap(); }

private:
    // "auto" evaluates in the vertex shader up to this order and in texture space above it:
    // measured on llvmpipe (scripts/bench-runtime, docs/runtime.md), vertex decompression is
    // 0.65x the rho path's frame at order 1 but 1.3-1.8x at orders 4 and 8, where the texture
    // pass is 0.8-0.9x. Asked for explicitly, vertex decompression holds at every order; auto
    // keeps a bake's error model, which is folded in texture space (a grid-basis bake is order 0).
    static constexpr int kAutoVertexMaxOrder = 1;
    // The SH are evaluated in the shading's vertex shader this frame: allowed (one pass, chosen
    // or auto) and smoothing, which needs D_mu in texture space, off.
    bool vertexMode() const;
    GLuint vertexProgram(int order);  // shade_direct.vert with the order's generated pass
    GLuint textureProgram();          // shade_direct.vert fetching D_mu

    const SurfaceLayout& layout_;
    const PipelineSettings& settings_;
    GpuMemory& memory_;
    SampleGrid grid_;
    Decompression decompression_;
    bool vertexAllowed_ = false, vertexRequired_ = false;
    std::map<int, GLuint> vertexPrograms_;  // by order
    GLuint textureProgram_ = 0;
    GLuint vao_ = 0, indices_ = 0;
    int indexCount_ = 0;
    std::unique_ptr<RhoMap> map_;  // made on the app's first request
    glm::vec3 eye_{0, 0, 3};
    bool ready_ = false;  // the map holds the last update()'s D
};

}  // namespace shrefract
