// Refractor: what an app holds. It uploads nothing itself: create() picks the one pipeline the
// bake, the shader limits and the options call for (pipeline.h), and every frame is delegated to
// it. What stays here is what all pipelines share: the settings an app changes between frames,
// the per-frame shading uniforms, the variable-IOR shading and the stage timer.
#include <algorithm>
#include <stdexcept>

#include "bake_data.h"
#include "chart_pipeline.h"
#include "common/bakefile.h"
#include "decompression.h"
#include "direct_pipeline.h"
#include "environment_gl.h"
#include "frame_uniforms.h"
#include "gl.h"
#include "gpu_timer.h"
#include "ior.h"
#include "rho_pipeline.h"
#include "shrefract/runtime.h"

namespace shrefract {

using namespace gl;

struct Refractor::Impl {
    Bake bake;
    RefractorOptions options;
    gl::Loader loader = nullptr;
    int maxOrder = 0;          // bands uploaded
    PipelineSettings settings;  // order in use, smoothing, correction
    GpuMemory memory;
    float diagonal = 1.0f;  // of the samples' bounding box, object units (the jitter cell's unit)
    std::unique_ptr<GpuStageTimer> timer;
    Timings timings;
    std::unique_ptr<Pipeline> pipeline;
    IorShading ior;  // setIor(): shading at other indices (runtime/src/ior.h)
    FrameView frame;  // of the last update()
    bool updated = false;

    void use() const { ensureLoaded(loader); }
};

namespace {

// The pipeline for this bake, these limits and options: chart bakes take the chart pipeline;
// joining bakes the direct one where the limits fetch textures in the vertex shader (unless the
// app asks for rho), else rho.
std::unique_ptr<Pipeline> makePipeline(const PipelineInputs& in) {
    const RefractorOptions& o = in.options;
    if (bakeData(in.bake).layout.isChartLayout()) return std::make_unique<ChartPipeline>(in);
    if (o.path == RefractorPath::Charts)
        throw std::invalid_argument("shrefract: path \"charts\" for a joining bake (direct | rho | auto)");
    const bool direct = o.path == RefractorPath::Direct ||
                        (o.path == RefractorPath::Auto && in.limits.vertexTextureFetch);
    if (o.decompression == DecompressionSite::Vertex && (!direct || o.smoothing))
        throw std::invalid_argument(
            "shrefract: vertex decompression needs the direct path and no smoothing");
    if (direct) return std::make_unique<DirectPipeline>(in);
    return std::make_unique<RhoPipeline>(in);
}

}  // namespace

Refractor::Refractor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Refractor> Refractor::create(const Bake& bake, const RefractorOptions& options) {
    auto m = std::make_unique<Impl>();
    m->bake = bake;
    m->options = options;
    m->loader = options.loader ? options.loader : currentContextLoader();
    m->use();
    // Without a current context GLVND's dispatch returns null for everything.
    const GLubyte* version = glGetString(GL_VERSION);
    if (!version) throw std::runtime_error("shrefract: no current OpenGL context");
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 33)
        throw std::runtime_error(std::string("shrefract: needs OpenGL 3.3 core, context is ") +
                                 reinterpret_cast<const char*>(version));
    const BakeData& d = bakeData(bake);
    const SurfaceLayout& L = d.layout;
    if (L.sampleCount() == 0 || L.muWidth * L.muHeight < L.sampleCount() || L.triangleCount == 0)
        throw std::invalid_argument("shrefract: bake has an empty or inconsistent layout");
    if (options.order < -1 || options.maxOrder < -1)
        throw std::invalid_argument("shrefract: RefractorOptions order " +
                                    std::to_string(options.order) + ", maxOrder " +
                                    std::to_string(options.maxOrder) + ": -1 (all) or 0 and up");
    m->maxOrder = options.maxOrder < 0 ? d.order : std::min(options.maxOrder, d.order);
    m->settings.order = options.order < 0 ? m->maxOrder : std::min(options.order, m->maxOrder);
    m->settings.smoothing = options.smoothing;
    m->settings.correction = options.correction;
    m->diagonal = samplesDiagonal(L);
    // Auto shading: the one measured best for the bake's basis (docs/runtime.md "Shading where
    // the bake is unsure": scripts/compare's chart).
    if (options.shading == Shading::Auto)
        m->options.shading = d.basis == Basis::Grid ? Shading::Blend : Shading::Jitter;
    if (options.taps != -1 && options.taps != 1 && options.taps != 4)
        throw std::invalid_argument("shrefract: RefractorOptions taps " + std::to_string(options.taps) +
                                    ": 1, 4 or -1 (by the bake's basis)");
    // Four taps on a grid-basis bake: its sharper exits alias where SH's low-pass does not
    // (docs/runtime.md "Four taps": scripts/compare's chart).
    if (options.taps == -1) m->options.taps = d.basis == Basis::Grid ? 4 : 1;
    if (!(options.jitterGate >= 0.0f))
        throw std::invalid_argument("shrefract: RefractorOptions jitterGate " +
                                    std::to_string(options.jitterGate) +
                                    ": 0 (ungated) or more radians");
    GLint units = 16;
    glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
    const PipelineInputs in{bake,        m->options,         m->settings, m->maxOrder,
                            shaderPreset(options.preset, units), options.form, m->memory};
    m->pipeline = makePipeline(in);
    m->timer = std::make_unique<GpuStageTimer>(kStages);
    m->timer->setEnabled(options.timings);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    SHREFRACT_GL_CHECK();
    return std::unique_ptr<Refractor>(new Refractor(std::move(m)));
}

Refractor::~Refractor() {
    Impl& m = *impl_;
    try {
        m.use();
    } catch (...) {
        // No GL any more: nothing can be released safely, so nothing is.
        (void)m.pipeline.release();
        (void)m.timer.release();
        return;
    }
    m.ior.destroy();
}

glm::vec3 FrameView::eye() const { return glm::vec3(glm::inverse(view)[3]); }

FrameView FrameView::fromEye(glm::vec3 eye, const glm::mat4& model) {
    FrameView f;
    f.view[3] = glm::vec4(-eye, 1.0f);  // a translation: the inverse's origin is `eye` exactly
    f.model = model;
    return f;
}

void Refractor::update(const FrameView& frame) {
    Impl& m = *impl_;
    m.use();
    const SavedTarget saved;
    m.frame = frame;
    m.updated = true;
    const glm::vec3 eyeObject = glm::vec3(glm::inverse(frame.model) * glm::vec4(frame.eye(), 1.0f));
    m.timings = Timings{};
    const StageClock clock{m.timer.get(), &m.timings};
    m.pipeline->update(eyeObject, m.ior.active, clock);
    if (m.ior.active && m.ior.bracket) {
        // The bracketing bake's D for the same view; its stages count in this frame's.
        Refractor* other = m.ior.bracket;
        other->update(frame);
        m.ior.bracketD = m.pipeline->bracketInput(*other->impl_->pipeline);
        const Timings& b = other->impl_->timings;
        m.timings.view += b.view, m.timings.decompress += b.decompress;
        m.timings.smooth += b.smooth, m.timings.unpack += b.unpack;
        m.timings.passes += b.passes;
        m.use();
    }
    SHREFRACT_GL_CHECK();
}

void Refractor::draw(const Environment& environment) {
    Impl& m = *impl_;
    if (!m.updated) throw std::logic_error("shrefract: Refractor::draw() before update()");
    m.use();
    const glm::mat4& model = m.frame.model;
    m.timer->begin(kShade);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    const bool ior = m.ior.active;
    const GLuint p = m.pipeline->shadingProgram(ior ? &m.ior : nullptr);
    glUseProgram(p);
    FrameUniforms uniforms(m.frame.view, m.frame.projection, model);
    uniforms.eta = m.bake.ior();
    uniforms.kappa = m.options.absorption.value_or(m.bake.absorption());
    uniforms.toneMap = m.options.toneMap;
    uniforms.exposure = m.options.exposure;
    uniforms.set(p);
    const glm::mat3 rotation(model);
    glUniformMatrix3fv(glGetUniformLocation(p, "uModelRotation"), 1, GL_FALSE, &rotation[0][0]);
    const RefractorOptions& o = m.options;
    glUniform1i(glGetUniformLocation(p, "uSpread"), o.shading != Shading::Sharp ? 1 : 0);
    glUniform1f(glGetUniformLocation(p, "uSpreadScale"), o.spreadScale);
    glUniform1f(glGetUniformLocation(p, "uBlendSigma"), o.shading == Shading::Blend ? o.blendSigma : 0.0f);
    glUniform1f(glGetUniformLocation(p, "uJitterCell"),
                o.shading == Shading::Jitter ? o.jitterCell * m.diagonal : 0.0f);
    glUniform1f(glGetUniformLocation(p, "uJitterGate"), o.jitterGate);
    glUniform1f(glGetUniformLocation(p, "uFootprintScale"), o.footprintScale);
    glUniform1i(glGetUniformLocation(p, "uTaps"), o.taps);
    useEnvironment(p, environment, 0);
    if (ior)
        m.ior.setUniforms(p, m.bake.ior(), m.ior.bracket ? m.ior.bracket->impl_->bake.ior() : 0.0f);
    m.pipeline->draw(p, ior, glm::vec3(glm::inverse(model) * glm::vec4(uniforms.eye, 1.0f)));
    glBindVertexArray(0);
    glUseProgram(0);
    glActiveTexture(GL_TEXTURE0);
    m.timer->end(kShade, &m.timings.shade);
    SHREFRACT_GL_CHECK();
}

unsigned Refractor::refractionMap() {
    impl_->use();
    const SavedTarget saved;
    return impl_->pipeline->refractionMap();
}

void Refractor::setIor(glm::vec3 ior) {
    if (!(glm::all(glm::greaterThanEqual(ior, glm::vec3(1.0f))) &&
          glm::all(glm::lessThanEqual(ior, glm::vec3(5.0f)))))
        throw std::invalid_argument("shrefract: setIor: every index must lie in [1, 5]");
    impl_->ior.active = true;
    impl_->ior.ior = ior;
}

void Refractor::resetIor() { impl_->ior.active = false; }

void Refractor::setIorBracket(Refractor* other) {
    if (other) {
        const SurfaceLayout &a = bakeData(impl_->bake).layout, &b = bakeData(other->impl_->bake).layout;
        if (other == this || a.sampleCount() != b.sampleCount() ||
            a.triangleCount != b.triangleCount || a.rate != b.rate ||
            a.muWidth != b.muWidth || a.rhoWidth != b.rhoWidth || a.rhoHeight != b.rhoHeight)
            throw std::invalid_argument(
                "shrefract: setIorBracket: the bracketing bake must have this bake's layout (same "
                "mesh and rate)");
        if (other->impl_->bake.ior() == impl_->bake.ior())
            throw std::invalid_argument(
                "shrefract: setIorBracket: the bracketing bake has this bake's index of refraction");
    }
    impl_->ior.bracket = other;
}

glm::ivec2 Refractor::refractionMapSize() const { return impl_->pipeline->refractionMapSize(); }
RefractorPath Refractor::path() const { return impl_->pipeline->path(); }
DecompressionSite Refractor::decompression() const { return impl_->pipeline->decompressionSite(); }
Shading Refractor::shading() const { return impl_->options.shading; }
int Refractor::taps() const { return impl_->options.taps; }

void Refractor::setOrder(int L) {
    // As RefractorOptions::order: -1 is every uploaded band, above maxOrder clamps to it.
    if (L < -1)
        throw std::invalid_argument("shrefract: setOrder(" + std::to_string(L) +
                                    "): -1 (all) or 0 and up");
    impl_->use();
    impl_->settings.order = L < 0 ? impl_->maxOrder : std::min(L, impl_->maxOrder);
    impl_->pipeline->prepare();
}
int Refractor::order() const { return impl_->settings.order; }
void Refractor::setSmoothing(bool on) {
    impl_->pipeline->checkSmoothing(on);
    impl_->settings.smoothing = on;
}
void Refractor::setCorrection(bool on) { impl_->settings.correction = on; }
void Refractor::setGutter(int texels) {
    impl_->use();
    impl_->pipeline->setGutter(texels);
}
int Refractor::gutter() const { return impl_->pipeline->gutter(); }
void Refractor::setSeamAware(bool on) { impl_->pipeline->setSeamAware(on); }
bool Refractor::seamAware() const { return impl_->pipeline->seamAware(); }
void Refractor::setTimings(bool on) {
    if (!on) impl_->timings = Timings{};
    impl_->timer->setEnabled(on);
}
bool Refractor::timingsEnabled() const { return impl_->timer->enabled(); }
const Timings& Refractor::timings() const { return impl_->timings; }
const GpuMemory& Refractor::memory() const { return impl_->memory; }
int Refractor::passCount() const { return impl_->pipeline->passCount(); }

ShForm Refractor::form() const {
    return impl_->pipeline->decompression().compiled(impl_->settings.order).shaders.form;
}

void Refractor::dumpShaders(const std::string& dir) const {
    impl_->use();
    shrefract::dumpShaders(impl_->pipeline->decompression().compiled(impl_->settings.order).shaders, dir);
}

std::vector<float> Refractor::readDirectionalMap() const {
    Impl& m = *impl_;
    m.use();
    GLuint d = 0;
    {
        const SavedTarget saved;
        d = m.pipeline->directionalMap();
    }
    return m.pipeline->decompression().readSamples(d);
}

std::vector<float> Refractor::readLocalViewMap() const {
    impl_->use();
    if (!impl_->pipeline->decompression().localViewTexture()) readDirectionalMap();
    return impl_->pipeline->decompression().readSamples(impl_->pipeline->decompression().localViewTexture());
}

std::vector<float> Refractor::readRefractionMap() {
    impl_->use();
    const GLuint t = refractionMap();
    const glm::ivec2 size = refractionMapSize();
    return readTextureRGBA(t, size.x, size.y);
}

}  // namespace shrefract
