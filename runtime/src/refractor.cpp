// The per-frame pipeline (paper §5.3.2, Figure 9), all texture-space passes in the mu layout
// except the unpack into rho:
//   local view direction -> D_mu (generated passes, ping-pong) -> [smoothing] -> rho -> shade.
#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "common/bakefile.h"
#include "common/sh.h"
#include "gl.h"
#include "shaders.h"
#include "shadergen.h"
#include "shrefract/runtime.h"

namespace shrefract {

using namespace gl;

namespace {

GLuint makeTexture2D(GLenum internal, int w, int h, GLenum format, GLenum type, const void* data,
                     GLenum filter) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

// A float render target with its own framebuffer.
struct Target {
    GLuint texture = 0, fbo = 0;
    void create(int w, int h, GLenum filter) {
        texture = makeTexture2D(GL_RGBA32F, w, h, GL_RGBA, GL_FLOAT, nullptr, filter);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error("shrefract: RGBA32F render target incomplete");
    }
    void destroy() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        if (texture) glDeleteTextures(1, &texture);
        fbo = texture = 0;
    }
};

// Padded copy of per-sample vec3s into a mu-sized RGB float image.
std::vector<float> muImage3(const std::vector<glm::vec3>& v, int w, int h) {
    std::vector<float> out(static_cast<size_t>(w) * h * 3, 0.0f);
    std::memcpy(out.data(), v.data(), v.size() * sizeof(glm::vec3));
    return out;
}

void bindTexture(int unit, GLenum target, GLuint texture) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, texture);
}

enum Stage { kView, kDecompress, kSmooth, kUnpack, kShade, kStages };

}  // namespace

struct Refractor::Impl {
    Bake bake;
    RefractorOptions options;
    gl::Loader loader = nullptr;
    int order = 0, maxOrder = 0;  // in use; uploaded
    GpuMemory memory;
    bool smoothing = false, correction = true;
    int muW = 0, muH = 0, rhoW = 0, rhoH = 0, listWidth = 1;
    ShaderLimits limits;
    ShForm form = ShForm::Auto;
    struct Compiled {
        DecompressionShaders shaders;
        std::vector<GLuint> programs;
    };
    std::map<int, Compiled> compiled;  // by order, built on first use
    GLuint positionTex = 0, normalTex = 0, weightArray = 0, rhoIndexTex = 0;
    std::vector<GLuint> weightTex;  // one per coefficient (2006 preset)
    GLuint rangeTex = 0, nbrIndexTex = 0, nbrWeightTex = 0;
    Target localView, sum[2], smoothed, rho;
    GLuint viewProgram = 0, smoothProgram = 0, unpackProgram = 0, shadeProgram = 0;
    GLuint emptyVao = 0, meshVao = 0, meshVbo = 0;
    int vertexCount = 0;
    GLuint queries[kStages] = {};
    Timings timings;
    GLuint lastD = 0;  // texture holding the D_mu fed to unpack
    GLuint lastDFbo = 0;

    void use() const { ensureLoaded(loader); }
    const Compiled& compiledFor(int L);
    void begin(Stage s) {
        if (options.timings) glBeginQuery(GL_TIME_ELAPSED, queries[s]);
    }
    void end(Stage s, double* ms) {
        if (!options.timings) return;
        // Software rasterizers (llvmpipe) defer the work to a flush; finish inside the query so
        // that the stage's time is measured, not only its submission.
        glFinish();
        glEndQuery(GL_TIME_ELAPSED);
        GLuint64 ns = 0;
        glGetQueryObjectui64v(queries[s], GL_QUERY_RESULT, &ns);
        *ms = ns * 1e-6;
    }
};

const Refractor::Impl::Compiled& Refractor::Impl::compiledFor(int L) {
    auto it = compiled.find(L);
    if (it != compiled.end()) return it->second;
    Compiled c;
    c.shaders = generateDecompression(L, limits, form);
    for (size_t i = 0; i < c.shaders.passes.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        GLuint p = buildProgram(c.shaders.vertex, pass.fragment,
                                "decompression pass " + std::to_string(i + 1) + " (" +
                                    c.shaders.summary() + ")");
        glUseProgram(p);
        for (size_t u = 0; u < pass.samplers.size(); ++u)
            glUniform1i(glGetUniformLocation(p, pass.samplers[u].name.c_str()), static_cast<int>(u));
        c.programs.push_back(p);
    }
    return compiled.emplace(L, std::move(c)).first->second;
}

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
    const BakeData& d = bake.data();
    const SurfaceLayout& L = d.layout;
    const int n = L.sampleCount();
    if (n == 0 || L.muWidth * L.muHeight < n || L.triangleCount == 0)
        throw std::invalid_argument("shrefract: bake has an empty or inconsistent layout");
    m->maxOrder = options.maxOrder < 0 ? d.order : std::min(options.maxOrder, d.order);
    m->order = options.order < 0 ? m->maxOrder : std::min(options.order, m->maxOrder);
    m->smoothing = options.smoothing;
    m->correction = options.correction;
    m->muW = L.muWidth;
    m->muH = L.muHeight;
    m->rhoW = L.rhoWidth;
    m->rhoH = L.rhoHeight;
    GLint units = 16;
    glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
    m->limits = shaderPreset(options.preset, units);
    m->form = parseShForm(options.form);

    // Samples (P, N) and weights, mu layout.
    m->positionTex = makeTexture2D(GL_RGB32F, m->muW, m->muH, GL_RGB, GL_FLOAT,
                                   muImage3(L.position, m->muW, m->muH).data(), GL_NEAREST);
    m->normalTex = makeTexture2D(GL_RGB32F, m->muW, m->muH, GL_RGB, GL_FLOAT,
                                 muImage3(L.normal, m->muW, m->muH).data(), GL_NEAREST);
    // Only bands 0..maxOrder go to the GPU: the weights are coefficient-major, so those are the
    // first shEvenCount(maxOrder) layers.
    const int K = shEvenCount(m->maxOrder);
    const size_t layer = static_cast<size_t>(m->muW) * m->muH * 4;
    const size_t muTexels = static_cast<size_t>(m->muW) * m->muH;
    // Weights stored at half or 8 bits in the file go to the GPU as RGBA16F: half the memory of
    // RGBA32F, and no precision the file had is lost (u8 codes dequantize to within half's 11
    // bits). Float32 bakes stay RGBA32F.
    const bool half = d.precision != Precision::F32;
    const GLenum weightFormat = half ? GL_RGBA16F : GL_RGBA32F;
    m->memory.weights = K * muTexels * (half ? 8 : 16);
    m->memory.samples = 2 * muTexels * 12;  // P, N: RGB32F
    m->memory.rho = static_cast<size_t>(m->rhoW) * m->rhoH * 16;  // RGBA32UI
    std::vector<float> padded(layer, 0.0f);
    if (m->limits.weightArray) {
        // GL 3.3 guarantees 256 layers (order 20 needs 231); llvmpipe allows 2048.
        GLint maxLayers = 256;
        glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
        if (K > maxLayers)
            throw std::runtime_error("shrefract: order " + std::to_string(m->maxOrder) + " needs " +
                                     std::to_string(K) + " weight layers, GL allows " +
                                     std::to_string(maxLayers) + " (set maxOrder lower)");
        glGenTextures(1, &m->weightArray);
        glBindTexture(GL_TEXTURE_2D_ARRAY, m->weightArray);
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, weightFormat, m->muW, m->muH, K, 0, GL_RGBA, GL_FLOAT,
                     nullptr);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    for (int k = 0; k < K; ++k) {
        std::memcpy(padded.data(), &d.weights[static_cast<size_t>(k) * n * 4],
                    static_cast<size_t>(n) * 4 * sizeof(float));
        if (m->limits.weightArray) {
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, k, m->muW, m->muH, 1, GL_RGBA, GL_FLOAT,
                            padded.data());
        } else {
            m->weightTex.push_back(makeTexture2D(weightFormat, m->muW, m->muH, GL_RGBA, GL_FLOAT,
                                                 padded.data(), GL_NEAREST));
        }
    }
    // rho: which sample (or correction) each texel shows; RhoTexel is four uint32.
    static_assert(sizeof(RhoTexel) == 4 * sizeof(uint32_t));
    m->rhoIndexTex = makeTexture2D(GL_RGBA32UI, m->rhoW, m->rhoH, GL_RGBA_INTEGER,
                                   GL_UNSIGNED_INT, L.rho.data(), GL_NEAREST);
    // Neighbour lists (CSR) for smoothing.
    if (!L.neighbourIndex.empty() && L.neighbourOffset.size() == static_cast<size_t>(n)) {
        std::vector<uint32_t> range(static_cast<size_t>(m->muW) * m->muH * 2, 0);
        for (int i = 0; i < n; ++i) {
            range[2 * i] = L.neighbourOffset[i];
            range[2 * i + 1] = L.neighbourCount[i];
        }
        m->rangeTex = makeTexture2D(GL_RG32UI, m->muW, m->muH, GL_RG_INTEGER, GL_UNSIGNED_INT,
                                    range.data(), GL_NEAREST);
        const size_t total = L.neighbourIndex.size();
        m->listWidth = static_cast<int>(std::min<size_t>(total, 4096));
        const int listH = static_cast<int>((total + m->listWidth - 1) / m->listWidth);
        std::vector<uint32_t> idx(static_cast<size_t>(m->listWidth) * listH, 0);
        std::vector<float> wts(idx.size(), 0.0f);
        std::copy(L.neighbourIndex.begin(), L.neighbourIndex.end(), idx.begin());
        std::copy(L.neighbourWeight.begin(), L.neighbourWeight.end(), wts.begin());
        m->nbrIndexTex = makeTexture2D(GL_R32UI, m->listWidth, listH, GL_RED_INTEGER,
                                       GL_UNSIGNED_INT, idx.data(), GL_NEAREST);
        m->nbrWeightTex = makeTexture2D(GL_R32F, m->listWidth, listH, GL_RED, GL_FLOAT,
                                        wts.data(), GL_NEAREST);
        m->memory.neighbours = muTexels * 8 + idx.size() * 4 + wts.size() * 4;
    }
    m->localView.create(m->muW, m->muH, GL_NEAREST);
    m->sum[0].create(m->muW, m->muH, GL_NEAREST);
    m->sum[1].create(m->muW, m->muH, GL_NEAREST);
    m->smoothed.create(m->muW, m->muH, GL_NEAREST);
    m->rho.create(m->rhoW, m->rhoH, GL_LINEAR);
    m->memory.targets = 4 * muTexels * 16 + static_cast<size_t>(m->rhoW) * m->rhoH * 16;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    // Fixed programs.
    m->viewProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("local_view.frag"), "local view");
    glUseProgram(m->viewProgram);
    glUniform1i(glGetUniformLocation(m->viewProgram, "uPosition"), 0);
    glUniform1i(glGetUniformLocation(m->viewProgram, "uNormal"), 1);
    m->smoothProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("smooth.frag"), "smoothing");
    glUseProgram(m->smoothProgram);
    const char* smoothSamplers[] = {"uD", "uRange", "uNbrIndex", "uNbrWeight"};
    for (int u = 0; u < 4; ++u)
        glUniform1i(glGetUniformLocation(m->smoothProgram, smoothSamplers[u]), u);
    glUniform1i(glGetUniformLocation(m->smoothProgram, "uMuWidth"), m->muW);
    glUniform1i(glGetUniformLocation(m->smoothProgram, "uListWidth"), m->listWidth);
    m->unpackProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("unpack.frag"), "unpack");
    glUseProgram(m->unpackProgram);
    glUniform1i(glGetUniformLocation(m->unpackProgram, "uRhoIndex"), 0);
    glUniform1i(glGetUniformLocation(m->unpackProgram, "uD"), 1);
    glUniform1i(glGetUniformLocation(m->unpackProgram, "uMuWidth"), m->muW);
    m->shadeProgram = buildProgram(shaders::source("shade.vert"), shaders::source("shade.frag"), "shading");
    glUseProgram(m->shadeProgram);
    glUniform1i(glGetUniformLocation(m->shadeProgram, "uRho"), 0);
    glUniform1i(glGetUniformLocation(m->shadeProgram, "uEnvironment"), 1);
    glUseProgram(0);

    // The mesh to draw, rebuilt from rho and the samples: triangle t's corners are its grid
    // samples (0,0), (r,0), (0,r); UVs point at their texel centres in rho.
    const int r = L.rate;
    std::vector<float> vertices;
    vertices.reserve(static_cast<size_t>(L.triangleCount) * 3 * 8);
    for (int t = 0; t < L.triangleCount; ++t) {
        const glm::ivec2 corners[3] = {{0, 0}, {r, 0}, {0, r}};
        for (glm::ivec2 c : corners) {
            uint32_t s = L.sampleAt(t, c.x, c.y);
            glm::ivec2 texel = L.rhoTexel(t, c.x, c.y);
            glm::vec3 p = L.position[s], nn = L.normal[s];
            float v[8] = {p.x, p.y, p.z, nn.x, nn.y, nn.z, (texel.x + 0.5f) / m->rhoW,
                          (texel.y + 0.5f) / m->rhoH};
            vertices.insert(vertices.end(), v, v + 8);
        }
    }
    m->vertexCount = L.triangleCount * 3;
    glGenVertexArrays(1, &m->emptyVao);
    glGenVertexArrays(1, &m->meshVao);
    glBindVertexArray(m->meshVao);
    glGenBuffers(1, &m->meshVbo);
    glBindBuffer(GL_ARRAY_BUFFER, m->meshVbo);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(float), vertices.data(), GL_STATIC_DRAW);
    for (int a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    glGenQueries(kStages, m->queries);
    m->compiledFor(m->order);
    SHREFRACT_GL_CHECK();
    return std::unique_ptr<Refractor>(new Refractor(std::move(m)));
}

Refractor::~Refractor() {
    Impl& m = *impl_;
    try {
        m.use();
    } catch (...) {
        return;  // no GL any more: nothing to release safely
    }
    for (auto& [L, c] : m.compiled)
        for (GLuint p : c.programs) glDeleteProgram(p);
    for (GLuint p : {m.viewProgram, m.smoothProgram, m.unpackProgram, m.shadeProgram})
        glDeleteProgram(p);
    GLuint textures[] = {m.positionTex, m.normalTex, m.weightArray, m.rhoIndexTex,
                         m.rangeTex,    m.nbrIndexTex, m.nbrWeightTex};
    for (GLuint t : textures)
        if (t) glDeleteTextures(1, &t);
    if (!m.weightTex.empty())
        glDeleteTextures(static_cast<GLsizei>(m.weightTex.size()), m.weightTex.data());
    for (Target* t : {&m.localView, &m.sum[0], &m.sum[1], &m.smoothed, &m.rho}) t->destroy();
    glDeleteVertexArrays(1, &m.emptyVao);
    glDeleteVertexArrays(1, &m.meshVao);
    glDeleteBuffers(1, &m.meshVbo);
    glDeleteQueries(kStages, m.queries);
}

void Refractor::update(glm::vec3 eye, const glm::mat4& model) {
    Impl& m = *impl_;
    m.use();
    GLint viewport[4], framebuffer = 0;
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindVertexArray(m.emptyVao);
    glViewport(0, 0, m.muW, m.muH);

    // Eye to object space, then the local view direction per sample.
    glm::vec3 eyeObject = glm::vec3(glm::inverse(model) * glm::vec4(eye, 1.0f));
    m.begin(kView);
    glBindFramebuffer(GL_FRAMEBUFFER, m.localView.fbo);
    glUseProgram(m.viewProgram);
    glUniform3f(glGetUniformLocation(m.viewProgram, "uEye"), eyeObject.x, eyeObject.y,
                eyeObject.z);
    bindTexture(0, GL_TEXTURE_2D, m.positionTex);
    bindTexture(1, GL_TEXTURE_2D, m.normalTex);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    m.end(kView, &m.timings.view);

    // D_mu: the generated passes, partial sums ping-ponging between sum[0] and sum[1].
    const Impl::Compiled& c = m.compiledFor(m.order);
    m.begin(kDecompress);
    for (size_t i = 0; i < c.programs.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        glBindFramebuffer(GL_FRAMEBUFFER, m.sum[i % 2].fbo);
        glUseProgram(c.programs[i]);
        for (size_t u = 0; u < pass.samplers.size(); ++u) {
            const SamplerBinding& s = pass.samplers[u];
            int unit = static_cast<int>(u);
            switch (s.kind) {
                case SamplerBinding::LocalView:
                    bindTexture(unit, GL_TEXTURE_2D, m.localView.texture);
                    break;
                case SamplerBinding::PartialSum:
                    bindTexture(unit, GL_TEXTURE_2D, m.sum[(i + 1) % 2].texture);
                    break;
                case SamplerBinding::Weight:
                    bindTexture(unit, GL_TEXTURE_2D, m.weightTex[s.coefficient]);
                    break;
                case SamplerBinding::WeightArray:
                    bindTexture(unit, GL_TEXTURE_2D_ARRAY, m.weightArray);
                    break;
            }
        }
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    m.end(kDecompress, &m.timings.decompress);
    m.timings.passes = static_cast<int>(c.programs.size());
    const Target& d = m.sum[(c.programs.size() + 1) % 2];
    m.lastD = d.texture;
    m.lastDFbo = d.fbo;

    // Optional spatial smoothing through the neighbour lists.
    m.timings.smooth = 0;
    if (m.smoothing && m.rangeTex) {
        m.begin(kSmooth);
        glBindFramebuffer(GL_FRAMEBUFFER, m.smoothed.fbo);
        glUseProgram(m.smoothProgram);
        bindTexture(0, GL_TEXTURE_2D, d.texture);
        bindTexture(1, GL_TEXTURE_2D, m.rangeTex);
        bindTexture(2, GL_TEXTURE_2D, m.nbrIndexTex);
        bindTexture(3, GL_TEXTURE_2D, m.nbrWeightTex);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        m.end(kSmooth, &m.timings.smooth);
        m.lastD = m.smoothed.texture;
        m.lastDFbo = m.smoothed.fbo;
    }

    // Unpack into rho, writing the correction texels.
    m.begin(kUnpack);
    glViewport(0, 0, m.rhoW, m.rhoH);
    glBindFramebuffer(GL_FRAMEBUFFER, m.rho.fbo);
    glUseProgram(m.unpackProgram);
    glUniform1i(glGetUniformLocation(m.unpackProgram, "uCorrection"), m.correction ? 1 : 0);
    bindTexture(0, GL_TEXTURE_2D, m.rhoIndexTex);
    bindTexture(1, GL_TEXTURE_2D, m.lastD);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    m.end(kUnpack, &m.timings.unpack);

    glUseProgram(0);
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    SHREFRACT_GL_CHECK();
}

void Refractor::draw(const glm::mat4& view, const glm::mat4& projection, const glm::mat4& model,
                     const Environment& environment) {
    Impl& m = *impl_;
    m.use();
    m.begin(kShade);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glUseProgram(m.shadeProgram);
    GLuint p = m.shadeProgram;
    glm::mat4 vp = projection * view;
    glm::mat3 rotation(model);
    glm::mat3 normalMatrix = glm::inverseTranspose(rotation);
    glm::vec3 eye = glm::vec3(glm::inverse(view)[3]);
    glUniformMatrix4fv(glGetUniformLocation(p, "uModel"), 1, GL_FALSE, glm::value_ptr(model));
    glUniformMatrix4fv(glGetUniformLocation(p, "uViewProjection"), 1, GL_FALSE, glm::value_ptr(vp));
    glUniformMatrix3fv(glGetUniformLocation(p, "uNormalMatrix"), 1, GL_FALSE,
                       glm::value_ptr(normalMatrix));
    glUniformMatrix3fv(glGetUniformLocation(p, "uModelRotation"), 1, GL_FALSE,
                       glm::value_ptr(rotation));
    glUniform3f(glGetUniformLocation(p, "uEye"), eye.x, eye.y, eye.z);
    glUniform1f(glGetUniformLocation(p, "uEta"), m.bake.ior());
    glm::vec3 kappa = m.bake.absorption();
    glUniform3f(glGetUniformLocation(p, "uKappa"), kappa.x, kappa.y, kappa.z);
    glUniform1i(glGetUniformLocation(p, "uToneMap"), m.options.toneMap ? 1 : 0);
    glUniform1f(glGetUniformLocation(p, "uExposure"), m.options.exposure);
    bindTexture(0, GL_TEXTURE_2D, m.rho.texture);
    bindTexture(1, GL_TEXTURE_CUBE_MAP, environment.cubeMap());
    glBindVertexArray(m.meshVao);
    glDrawArrays(GL_TRIANGLES, 0, m.vertexCount);
    glBindVertexArray(0);
    glUseProgram(0);
    glActiveTexture(GL_TEXTURE0);
    m.end(kShade, &m.timings.shade);
    SHREFRACT_GL_CHECK();
}

unsigned Refractor::refractionMap() const { return impl_->rho.texture; }
glm::ivec2 Refractor::refractionMapSize() const { return {impl_->rhoW, impl_->rhoH}; }

void Refractor::setOrder(int L) {
    impl_->use();
    impl_->order = std::clamp(L, 0, impl_->maxOrder);
    impl_->compiledFor(impl_->order);
}
int Refractor::order() const { return impl_->order; }
void Refractor::setSmoothing(bool on) { impl_->smoothing = on; }
void Refractor::setCorrection(bool on) { impl_->correction = on; }
void Refractor::setTimings(bool on) {
    if (!on) impl_->timings = Timings{};
    impl_->options.timings = on;
}
const Timings& Refractor::timings() const { return impl_->timings; }
const GpuMemory& Refractor::memory() const { return impl_->memory; }
int Refractor::passCount() const {
    return static_cast<int>(impl_->compiledFor(impl_->order).programs.size());
}

std::string Refractor::form() const {
    return ToString(impl_->compiledFor(impl_->order).shaders.form);
}

void Refractor::dumpShaders(const std::string& dir) const {
    impl_->use();
    shrefract::dumpShaders(impl_->compiledFor(impl_->order).shaders, dir);
}

static std::vector<float> readTexture(GLuint texture, int w, int h) {
    std::vector<float> out(static_cast<size_t>(w) * h * 4);
    glBindTexture(GL_TEXTURE_2D, texture);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, out.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    return out;
}

std::vector<float> Refractor::readDirectionalMap() const {
    impl_->use();
    std::vector<float> all = readTexture(impl_->lastD, impl_->muW, impl_->muH);
    all.resize(static_cast<size_t>(impl_->bake.sampleCount()) * 4);
    return all;
}

std::vector<float> Refractor::readLocalViewMap() const {
    impl_->use();
    std::vector<float> all = readTexture(impl_->localView.texture, impl_->muW, impl_->muH);
    all.resize(static_cast<size_t>(impl_->bake.sampleCount()) * 4);
    return all;
}

std::vector<float> Refractor::readRefractionMap() const {
    impl_->use();
    return readTexture(impl_->rho.texture, impl_->rhoW, impl_->rhoH);
}

}  // namespace shrefract
