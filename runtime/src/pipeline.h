// The per-frame pipelines a Refractor runs (paper §5.3.2, Figure 9; docs/runtime.md). One is
// chosen when the refractor is created, from the bake's layout, the shader limits and the
// options, and the refractor delegates every frame to it:
//   RhoPipeline    (rho_pipeline.h): the paper's joining path: local view -> D_mu -> [smoothing]
//                  -> unpack into rho with correction texels -> shade with a bilinear rho lookup;
//   DirectPipeline (direct_pipeline.h): the sample grid drawn as a refined mesh, D fetched per
//                  vertex and interpolated by the rasterizer, or evaluated in the vertex shader;
//   ChartPipeline  (chart_pipeline.h): chart bakes (paper §5.2, Figure 6): D over the atlas's
//                  covered texels -> gutters -> [texture-space smoothing] -> shade as rho.
// All three decompress D_mu through the same generated passes (decompression.h).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gl.h"
#include "gpu_timer.h"
#include "shadergen.h"
#include "shrefract/runtime.h"

namespace shrefract {

class Decompression;
struct IorShading;

enum Stage { kView, kDecompress, kSmooth, kUnpack, kShade, kStages };

// Where a timed update() records its stages; default-constructed: untimed (work an app asked
// for outside its frame, such as refractionMap() on the direct path).
struct StageClock {
    GpuStageTimer* timer = nullptr;
    Timings* timings = nullptr;
    bool timed() const { return timings != nullptr; }
    void begin(Stage s) const {
        if (timer) timer->begin(s);
    }
    void end(Stage s, double Timings::*field) const {
        if (timer) timer->end(s, &(timings->*field));
    }
};

// What the refractor's setters change between frames.
struct PipelineSettings {
    int order = 0;  // SH order in use
    bool smoothing = false;
    bool correction = true;
};

// How the decompression passes cover the samples' mu layout: a full-screen triangle over the
// sample texture (joining layouts), or the unfolded mesh in texture space (charts: only covered
// texels are decompressed).
class SampleCover {
public:
    virtual ~SampleCover() = default;
    virtual const std::string& vertexShader() const = 0;  // the passes link with it
    // The local view direction of every sample into the bound framebuffer (mu-sized).
    virtual void localView(glm::vec3 eyeObject) = 0;
    // Rasterizes the covered texels with the program in use.
    virtual void draw() const = 0;
    // Whether texels outside the cover must read 0 (the targets are cleared when made).
    virtual bool partial() const = 0;
};

// What a pipeline is made from (in the current context).
struct PipelineInputs {
    const Bake& bake;
    const RefractorOptions& options;
    const PipelineSettings& settings;  // the refractor's, read at every frame
    int maxOrder;                      // bands uploaded
    ShaderLimits limits;
    ShForm form;
    GpuMemory& memory;                 // what the pipeline allocates is added here
};

class Pipeline {
public:
    virtual ~Pipeline() = default;
    virtual RefractorPath path() const = 0;
    virtual DecompressionSite decompressionSite() const { return DecompressionSite::Texture; }
    virtual Decompression& decompression() = 0;
    // Compiles what the current order's frames need (setOrder()); throws on GL failure.
    virtual void prepare() = 0;
    virtual int passCount() = 0;  // texture-space decompression passes per frame (0: none)
    // Throws std::invalid_argument if the pipeline cannot smooth as asked.
    virtual void checkSmoothing(bool /*on*/) const {}
    // Builds this frame's D for a viewer at `eyeObject` (object space), and the refraction map
    // where the shading reads it. `textureD`: D_mu is also wanted in texture space (the
    // variable-IOR shading reads it there).
    virtual void update(glm::vec3 eyeObject, bool textureD, const StageClock& clock) = 0;
    // The shading program for this frame: the plain one, or `ior`'s (setIor()) when not null.
    virtual GLuint shadingProgram(IorShading* ior) = 0;
    // With `program` in use and the frame's uniforms and environment set: binds the pipeline's
    // textures and draws the object. `eyeObject`: the drawing camera in object space.
    virtual void draw(GLuint program, bool ior, glm::vec3 eyeObject) = 0;
    // The refraction map for the last update(), built on request where the pipeline does not
    // shade from it.
    virtual GLuint refractionMap() = 0;
    virtual glm::ivec2 refractionMapSize() const = 0;
    // D_mu for the last update() in texture space, decompressing it there if the pipeline did
    // not: what readDirectionalMap() reads and a bracketing bake's direct shading samples.
    virtual GLuint directionalMap() = 0;
    // What this pipeline's variable-IOR shading reads from a bracketing bake's pipeline: D_mu
    // (direct) or the refraction map (rho, charts).
    virtual GLuint bracketInput(Pipeline& other) { return other.refractionMap(); }
    // Chart pipelines only; the others ignore these.
    virtual void setGutter(int /*texels*/) {}
    virtual int gutter() const { return 0; }
    virtual void setSeamAware(bool /*on*/) {}
    virtual bool seamAware() const { return false; }
};

}  // namespace shrefract
