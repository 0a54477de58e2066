// The per-frame pipeline (paper §5.3.2, Figure 9; docs/runtime.md), in one of two paths:
//   rho    (paper): local view -> D_mu (generated passes, ping-pong) -> [smoothing] -> unpack
//                   into rho with correction texels -> shade (bilinear rho lookup)
//   direct (today's GPUs): local view -> D_mu -> [smoothing] -> shade the sample grid as a
//                   refined mesh, D fetched per vertex and interpolated by the rasterizer;
//                   or, with vertex decompression, one draw: the shading pass's vertex shader
//                   evaluates the SH at each sample itself.
//   charts (paper §5.2, Figure 6; chart bakes): the unfolded mesh drawn in texture space for the
//                   local view and D (only covered texels) -> gutters (dilation, seam-aware)
//                   -> [texture-space smoothing] into the atlas refraction map -> shade as rho.
//                   runtime/src/chart_pipeline.{h,cpp}.
#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "chart_pipeline.h"
#include "common/bakefile.h"
#include "common/error.h"
#include "common/sh.h"
#include "environment_gl.h"
#include "error_fold.h"
#include "gl.h"
#include "ior.h"
#include "shadergen.h"
#include "shaders.h"
#include "shrefract/runtime.h"

namespace shrefract {

using namespace gl;

namespace {

// A float render target with its own framebuffer.
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

void setInt(GLuint p, const char* name, int v) { glUniform1i(glGetUniformLocation(p, name), v); }
void setFloat(GLuint p, const char* name, float v) { glUniform1f(glGetUniformLocation(p, name), v); }

enum Stage { kView, kDecompress, kSmooth, kUnpack, kShade, kStages };

// The weights as they go to the GPU: at the precision they were stored (docs/runtime.md).
enum class WeightFormat { Float32, Float16, Unorm8 };

}  // namespace

struct Refractor::Impl {
    Bake bake;
    RefractorOptions options;
    gl::Loader loader = nullptr;
    int order = 0, maxOrder = 0;  // in use; uploaded
    GpuMemory memory;
    bool smoothing = false, correction = true;
    bool direct = false, spread = true;
    // Direct path: the SH may be evaluated in the shading's vertex shader (one pass, chosen or
    // "auto"); they are, unless smoothing (which needs D_mu in texture space) is on.
    // "auto" evaluates in the vertex shader up to this order and in texture space above it:
    // measured on llvmpipe (scripts/bench-runtime, docs/runtime.md), vertex decompression is
    // 0.65x the rho path's frame at order 1 but 1.3-1.8x at orders 4 and 8, where the texture
    // pass is 0.8-0.9x. Asked for explicitly, "vertex" holds at every order.
    static constexpr int kAutoVertexMaxOrder = 1;
    bool vertexShAllowed = false, vertexShRequired = false;
    bool vertexMode() const {
        return vertexShAllowed && !smoothing && (vertexShRequired || order <= kAutoVertexMaxOrder);
    }
    int muW = 0, muH = 0, rhoW = 0, rhoH = 0, listWidth = 1;
    float diagonal = 1.0f;  // of the samples' bounding box, object units (the jitter cell's unit)
    ShaderLimits limits;
    ShForm form = ShForm::Auto;
    WeightFormat weightFormat = WeightFormat::Float32;
    std::vector<float> u8Scale, u8Offset;  // per coefficient k, 4 each: code / 255 * scale + offset
    struct Compiled {
        DecompressionShaders shaders;
        std::vector<GLuint> programs;  // texture-space passes
        GLuint shadeVertexSh = 0;      // direct path, vertex decompression: the shading program
    };
    std::map<int, Compiled> compiled;  // by order, built on first use
    GLuint positionTex = 0, normalTex = 0, weightArray = 0, rhoIndexTex = 0;
    std::vector<GLuint> weightTex;  // one per coefficient (2006 preset)
    GLuint rangeTex = 0, nbrIndexTex = 0, nbrWeightTex = 0;
    Target localView, sum[2], smoothed, rho;
    GLuint viewProgram = 0, smoothProgram = 0, unpackProgram = 0;
    GLuint shadeRhoProgram = 0, shadeDirectProgram = 0;
    GLuint emptyVao = 0, rhoVao = 0, rhoVbo = 0, directVao = 0, directIbo = 0;
    int rhoVertexCount = 0, directIndexCount = 0;
    GLuint queries[kStages] = {};
    Timings timings;
    GLuint lastD = 0;            // texture holding the D_mu fed to unpack or to the direct shading
    bool rhoReady = false;       // the rho target holds the map for the last update()
    glm::vec3 lastEye{0, 0, 3};  // object space, of the last update()
    // Chart bakes: the isolated-surface pipeline, whose refraction map (the atlas) is `rho`.
    std::unique_ptr<ChartPipeline> charts;
    // The bake's error model folded into D_mu's length (runtime/src/error_fold.h), when it has one
    // and RefractorOptions::errorModel is on; texture-space decompression only.
    std::unique_ptr<ErrorFold> errorFold;
    IorShading ior;              // setIor(): shading at other indices (runtime/src/ior.h)

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
    void bindWeights(const DecompressionPass& pass, int firstUnit);
    void setWeightUniforms(GLuint program, int K);
    // The texture-space stages: local view, decompression passes, smoothing (into lastD).
    void decompressInTextureSpace(bool timed);
    void ensureRhoResources();
    void buildRhoMesh();
    GLuint directTextureProgram();
    void unpackRho(bool timed);
    void buildChartMap(bool timed);
};

// Binds the weight samplers of `pass` from texture unit `firstUnit` on (the pass's own order of
// samplers; local view and partial sum are bound by the caller).
void Refractor::Impl::bindWeights(const DecompressionPass& pass, int firstUnit) {
    int unit = firstUnit;
    for (const SamplerBinding& s : pass.samplers) {
        if (s.kind == SamplerBinding::Weight) bindTexture(unit++, GL_TEXTURE_2D, weightTex[s.coefficient]);
        if (s.kind == SamplerBinding::WeightArray) bindTexture(unit++, GL_TEXTURE_2D_ARRAY, weightArray);
    }
}

void Refractor::Impl::setWeightUniforms(GLuint program, int K) {
    if (weightFormat != WeightFormat::Unorm8) return;
    glUniform4fv(glGetUniformLocation(program, "uWeightScale"), K, u8Scale.data());
    glUniform4fv(glGetUniformLocation(program, "uWeightOffset"), K, u8Offset.data());
}

const Refractor::Impl::Compiled& Refractor::Impl::compiledFor(int L) {
    auto it = compiled.find(L);
    if (it != compiled.end()) return it->second;
    Compiled c;
    c.shaders = generateDecompression(L, limits, form);
    const int K = shEvenCount(L);
    for (size_t i = 0; i < c.shaders.passes.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        // Chart bakes rasterize the unfolded mesh instead of the full-screen triangle, so only
        // covered texels are decompressed (paper §5.2).
        GLuint p = buildProgram(charts ? ChartPipeline::textureSpaceVertexShader() : c.shaders.vertex,
                                pass.fragment,
                                "decompression pass " + std::to_string(i + 1) + " (" +
                                    c.shaders.summary() + ")");
        glUseProgram(p);
        for (size_t u = 0; u < pass.samplers.size(); ++u)
            glUniform1i(glGetUniformLocation(p, pass.samplers[u].name.c_str()), static_cast<int>(u));
        setWeightUniforms(p, K);
        c.programs.push_back(p);
    }
    if (vertexShAllowed) {
        // The one pass's generated shPass() inside the direct shading's vertex shader.
        SHREFRACT_CHECK(c.shaders.passes.size() == 1);
        const DecompressionPass& pass = c.shaders.passes[0];
        const std::string vs = shaders::withVersion(
            shaders::fill(shaders::source("shade_direct.vert"), "#pragma shrefract_generated",
                          pass.generated),
            limits.version, "#define SHREFRACT_VERTEX_SH");
        const std::string fs = shaders::withVersion(shaders::source("shade.frag"), limits.version,
                                                    "#define SHREFRACT_DIRECT");
        GLuint p = buildProgram(vs, fs, "direct shading with vertex decompression (" + c.shaders.summary() + ")");
        glUseProgram(p);
        setInt(p, "uPosition", 2);
        setInt(p, "uNormal", 3);
        setInt(p, "uMuWidth", muW);
        // Units 0 and 1 are the environment and (unused here) D; weights from unit 4 on.
        int unit = 4;
        for (const SamplerBinding& s : pass.samplers)
            if (s.kind == SamplerBinding::Weight || s.kind == SamplerBinding::WeightArray)
                setInt(p, s.name.c_str(), unit++);
        setWeightUniforms(p, K);
        c.shadeVertexSh = p;
    }
    glUseProgram(0);
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
    if (options.order < -1 || options.maxOrder < -1)
        throw std::invalid_argument("shrefract: RefractorOptions order " +
                                    std::to_string(options.order) + ", maxOrder " +
                                    std::to_string(options.maxOrder) + ": -1 (all) or 0 and up");
    m->maxOrder = options.maxOrder < 0 ? d.order : std::min(options.maxOrder, d.order);
    m->order = options.order < 0 ? m->maxOrder : std::min(options.order, m->maxOrder);
    m->smoothing = options.smoothing;
    m->correction = options.correction;
    m->muW = L.muWidth;
    m->muH = L.muHeight;
    glm::vec3 lo(L.position[0]), hi(L.position[0]);
    for (const glm::vec3& p : L.position) lo = glm::min(lo, p), hi = glm::max(hi, p);
    m->diagonal = std::max(glm::length(hi - lo), 1e-6f);
    m->rhoW = L.rhoWidth;
    m->rhoH = L.rhoHeight;
    GLint units = 16;
    glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
    m->limits = shaderPreset(options.preset, units);
    m->form = parseShForm(options.form);
    if (options.shading != "spread" && options.shading != "sharp" && options.shading != "blend" &&
        options.shading != "jitter")
        throw std::invalid_argument("shrefract: shading \"" + options.shading + "\" (spread | sharp | blend | jitter)");
    m->spread = options.shading != "sharp";

    // Which path, and where the SH are evaluated on the direct one. Chart bakes have their own.
    const bool charts = L.isChartLayout();
    if (charts && options.path != "auto" && options.path != "charts")
        throw std::invalid_argument("shrefract: path \"" + options.path + "\" for a " +
                                    ToString(L.kind) + " bake (chart bakes take \"charts\")");
    if (charts)
        m->direct = false;
    else if (options.path == "auto")
        m->direct = options.preset != "2006";
    else if (options.path == "direct" || options.path == "rho")
        m->direct = options.path == "direct";
    else
        throw std::invalid_argument("shrefract: path \"" + options.path + "\" (direct | rho | auto)");
    const std::string& dec = options.decompression;
    if (dec != "auto" && dec != "vertex" && dec != "texture")
        throw std::invalid_argument("shrefract: decompression \"" + dec + "\" (vertex | texture | auto)");
    if (dec == "vertex" && (!m->direct || options.smoothing))
        throw std::invalid_argument(
            "shrefract: vertex decompression needs the direct path and no smoothing");

    // Weights at their stored precision: u8 codes as RGBA8 UNORM (dequantized in the shader),
    // f16 as RGBA16F, f32 as RGBA32F (RGBA16F when the app asks for half).
    m->weightFormat = d.precision == Precision::U8    ? WeightFormat::Unorm8
                      : d.precision == Precision::F16 ? WeightFormat::Float16
                      : options.halfWeights           ? WeightFormat::Float16
                                                      : WeightFormat::Float32;
    m->limits.unormWeights = m->weightFormat == WeightFormat::Unorm8;
    const int K = shEvenCount(m->maxOrder);
    const size_t muTexels = static_cast<size_t>(m->muW) * m->muH;
    if (m->limits.unormWeights) {
        m->u8Scale.resize(size_t(K) * 4);
        m->u8Offset.resize(size_t(K) * 4);
        for (size_t i = 0; i < m->u8Scale.size(); ++i) {
            m->u8Scale[i] = d.u8Scale[i] * 255.0f;  // the texel is code / 255
            m->u8Offset[i] = d.u8Offset[i];
        }
    }
    // A single decompression pass (the modern preset) can run in the shading's vertex shader.
    const bool onePass = generateDecompression(m->order, m->limits, m->form).passes.size() == 1;
    m->vertexShAllowed = m->direct && onePass && (dec == "vertex" || dec == "auto");
    m->vertexShRequired = dec == "vertex";
    if (dec == "vertex" && !onePass)
        throw std::invalid_argument("shrefract: vertex decompression needs a one-pass preset");

    // Samples (P, N), mu layout: the view pass reads them, and so does the direct path's
    // vertex shader (gl_VertexID = sample). Chart bakes take P and N from their mesh.
    if (!charts) {
        m->positionTex = makeTexture2D(GL_RGB32F, m->muW, m->muH, GL_RGB, GL_FLOAT,
                                       muImage3(L.position, m->muW, m->muH).data(), GL_NEAREST);
        m->normalTex = makeTexture2D(GL_RGB32F, m->muW, m->muH, GL_RGB, GL_FLOAT,
                                     muImage3(L.normal, m->muW, m->muH).data(), GL_NEAREST);
        m->memory.samples = 2 * muTexels * 12;  // RGB32F
    }
    // Where sample i sits in the mu textures: texel i, or its atlas texel for chart bakes.
    std::vector<size_t> texelOf(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const glm::ivec2 t = L.muTexel(i);
        texelOf[i] = static_cast<size_t>(t.y) * m->muW + t.x;
    }

    // Only bands 0..maxOrder go to the GPU: the weights are coefficient-major, so those are the
    // first shEvenCount(maxOrder) layers.
    GLenum internal = GL_RGBA32F, type = GL_FLOAT;
    size_t texelBytes = 16;
    if (m->weightFormat == WeightFormat::Float16) internal = GL_RGBA16F, texelBytes = 8;
    if (m->weightFormat == WeightFormat::Unorm8) internal = GL_RGBA8, type = GL_UNSIGNED_BYTE, texelBytes = 4;
    m->memory.weights = K * muTexels * texelBytes;
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
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, internal, m->muW, m->muH, K, 0, GL_RGBA, type, nullptr);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    std::vector<float> padded(muTexels * 4, 0.0f);
    std::vector<uint8_t> codes(muTexels * 4, 0);
    for (int k = 0; k < K; ++k) {
        const float* w = &d.weights[static_cast<size_t>(k) * n * 4];
        const void* data = padded.data();
        if (m->weightFormat == WeightFormat::Unorm8) {
            // The file's codes again: the dequantized weights map back exactly (round to nearest).
            for (size_t i = 0; i < size_t(n) * 4; ++i) {
                const double scale = d.u8Scale[k * 4 + i % 4], offset = d.u8Offset[k * 4 + i % 4];
                const double code = scale > 0 ? std::nearbyint((double(w[i]) - offset) / scale) : 0.0;
                codes[texelOf[i / 4] * 4 + i % 4] = static_cast<uint8_t>(std::clamp(code, 0.0, 255.0));
            }
            data = codes.data();
        } else if (charts) {
            for (int i = 0; i < n; ++i) std::memcpy(&padded[texelOf[i] * 4], &w[size_t(i) * 4], 4 * sizeof(float));
        } else {
            std::memcpy(padded.data(), w, static_cast<size_t>(n) * 4 * sizeof(float));
        }
        if (m->limits.weightArray)
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, k, m->muW, m->muH, 1, GL_RGBA, type, data);
        else
            m->weightTex.push_back(makeTexture2D(internal, m->muW, m->muH, GL_RGBA, type, data, GL_NEAREST));
    }
    if (d.errorOrder >= 0 && options.errorModel) {
        m->errorFold = std::make_unique<ErrorFold>(d, texelOf);
        m->memory.weights += m->errorFold->bytes();
    }
    // Neighbour lists (CSR) for smoothing.
    if (!L.neighbourIndex.empty() && L.neighbourOffset.size() == static_cast<size_t>(n)) {
        std::vector<uint32_t> range(muTexels * 2, 0);
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
    // Texture-space targets: the vertex-decompression direct path needs none (until smoothing,
    // refractionMap() or readDirectionalMap() asks for D_mu: decompressInTextureSpace).
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    // Fixed programs.
    m->viewProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("local_view.frag"), "local view");
    glUseProgram(m->viewProgram);
    setInt(m->viewProgram, "uPosition", 0);
    setInt(m->viewProgram, "uNormal", 1);
    m->smoothProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("smooth.frag"), "smoothing");
    glUseProgram(m->smoothProgram);
    const char* smoothSamplers[] = {"uD", "uRange", "uNbrIndex", "uNbrWeight"};
    for (int u = 0; u < 4; ++u) setInt(m->smoothProgram, smoothSamplers[u], u);
    setInt(m->smoothProgram, "uMuWidth", m->muW);
    setInt(m->smoothProgram, "uListWidth", m->listWidth);

    glGenVertexArrays(1, &m->emptyVao);
    glGenQueries(kStages, m->queries);
    if (m->direct) {
        // The refined mesh: one vertex per mu sample (no attributes: gl_VertexID), and every
        // triangle's regular barycentric subdivision at rate r as indices; both halves of a grid
        // cell keep the triangle's winding (corner 0 -> 1 -> 2).
        const int r = L.rate;
        std::vector<uint32_t> indices;
        indices.reserve(static_cast<size_t>(L.triangleCount) * r * r * 3);
        for (int t = 0; t < L.triangleCount; ++t)
            for (int j = 0; j < r; ++j)
                for (int i = 0; i + j < r; ++i) {
                    indices.insert(indices.end(), {L.sampleAt(t, i, j), L.sampleAt(t, i + 1, j),
                                                   L.sampleAt(t, i, j + 1)});
                    if (i + j + 1 < r)
                        indices.insert(indices.end(), {L.sampleAt(t, i + 1, j), L.sampleAt(t, i + 1, j + 1),
                                                       L.sampleAt(t, i, j + 1)});
                }
        m->directIndexCount = static_cast<int>(indices.size());
        glGenVertexArrays(1, &m->directVao);
        glBindVertexArray(m->directVao);
        glGenBuffers(1, &m->directIbo);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->directIbo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, indices.size() * sizeof(uint32_t), indices.data(),
                     GL_STATIC_DRAW);
        glBindVertexArray(0);
        m->memory.mesh = indices.size() * sizeof(uint32_t);
        if (!m->vertexMode()) m->directTextureProgram();
    } else if (charts) {
        // The atlas is the refraction map; the unfolded mesh draws it in texture space and shades.
        m->rho.create(m->rhoW, m->rhoH, GL_LINEAR);
        m->memory.targets += muTexels * 16;
        m->buildRhoMesh();
        m->charts = std::make_unique<ChartPipeline>(
            L, m->rhoVao, m->rhoVertexCount, options.gutter < 0 ? L.atlas.gutter : options.gutter,
            options.seamAware);
        m->memory.rho = m->charts->indexBytes();
        m->memory.targets += m->charts->targetBytes();
    } else {
        m->ensureRhoResources();
        m->buildRhoMesh();
    }
    glUseProgram(0);
    m->compiledFor(m->order);
    SHREFRACT_GL_CHECK();
    return std::unique_ptr<Refractor>(new Refractor(std::move(m)));
}

// The direct shading that fetches D_mu per vertex (texture-space decompression), on first use.
GLuint Refractor::Impl::directTextureProgram() {
    if (shadeDirectProgram) return shadeDirectProgram;
    shadeDirectProgram = buildProgram(
        shaders::source("shade_direct.vert"),
        shaders::withVersion(shaders::source("shade.frag"), "330 core", "#define SHREFRACT_DIRECT"),
        "direct shading");
    glUseProgram(shadeDirectProgram);
    setInt(shadeDirectProgram, "uD", 1);
    setInt(shadeDirectProgram, "uPosition", 2);
    setInt(shadeDirectProgram, "uNormal", 3);
    setInt(shadeDirectProgram, "uMuWidth", muW);
    return shadeDirectProgram;
}

// rho: the index texture, the target and the unpack program. Made at creation on the rho path,
// on request (refractionMap()) on the direct path.
void Refractor::Impl::ensureRhoResources() {
    if (rhoIndexTex) return;
    const SurfaceLayout& L = bake.data().layout;
    // Which sample (or correction) each texel shows; RhoTexel is four uint32.
    static_assert(sizeof(RhoTexel) == 4 * sizeof(uint32_t));
    rhoIndexTex = makeTexture2D(GL_RGBA32UI, rhoW, rhoH, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                                L.rho.data(), GL_NEAREST);
    memory.rho = static_cast<size_t>(rhoW) * rhoH * 16;
    rho.create(rhoW, rhoH, GL_LINEAR);
    memory.targets += static_cast<size_t>(rhoW) * rhoH * 16;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    unpackProgram = buildProgram(shaders::source("fullscreen.vert"), shaders::source("unpack.frag"), "unpack");
    glUseProgram(unpackProgram);
    setInt(unpackProgram, "uRhoIndex", 0);
    setInt(unpackProgram, "uD", 1);
    setInt(unpackProgram, "uMuWidth", muW);
    glUseProgram(0);
}

// The rho path's shading (and the chart path's): its program and the mesh, UVs into the map.
void Refractor::Impl::buildRhoMesh() {
    shadeRhoProgram = buildProgram(shaders::source("shade.vert"), shaders::source("shade.frag"), "shading");
    glUseProgram(shadeRhoProgram);
    setInt(shadeRhoProgram, "uRho", 1);
    glUseProgram(0);
    static_assert(sizeof(MapVertex) == 8 * sizeof(float));
    const std::vector<MapVertex> vertices = bake.refractionMapMesh();
    rhoVertexCount = static_cast<int>(vertices.size());
    glGenVertexArrays(1, &rhoVao);
    glBindVertexArray(rhoVao);
    glGenBuffers(1, &rhoVbo);
    glBindBuffer(GL_ARRAY_BUFFER, rhoVbo);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(MapVertex), vertices.data(), GL_STATIC_DRAW);
    for (int a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    memory.mesh = vertices.size() * sizeof(MapVertex);
}

Refractor::~Refractor() {
    Impl& m = *impl_;
    try {
        m.use();
    } catch (...) {
        return;  // no GL any more: nothing to release safely
    }
    for (auto& [L, c] : m.compiled) {
        for (GLuint p : c.programs) glDeleteProgram(p);
        if (c.shadeVertexSh) glDeleteProgram(c.shadeVertexSh);
    }
    for (GLuint p : {m.viewProgram, m.smoothProgram, m.unpackProgram, m.shadeRhoProgram,
                     m.shadeDirectProgram})
        if (p) glDeleteProgram(p);
    m.ior.destroy();
    GLuint textures[] = {m.positionTex, m.normalTex, m.weightArray, m.rhoIndexTex,
                         m.rangeTex,    m.nbrIndexTex, m.nbrWeightTex};
    for (GLuint t : textures)
        if (t) glDeleteTextures(1, &t);
    if (!m.weightTex.empty())
        glDeleteTextures(static_cast<GLsizei>(m.weightTex.size()), m.weightTex.data());
    for (Target* t : {&m.localView, &m.sum[0], &m.sum[1], &m.smoothed, &m.rho}) t->destroy();
    for (GLuint v : {m.emptyVao, m.rhoVao, m.directVao})
        if (v) glDeleteVertexArrays(1, &v);
    for (GLuint b : {m.rhoVbo, m.directIbo})
        if (b) glDeleteBuffers(1, &b);
    glDeleteQueries(kStages, m.queries);
    m.charts.reset();
    m.errorFold.reset();
}

void Refractor::Impl::decompressInTextureSpace(bool timed) {
    const size_t muBytes = static_cast<size_t>(muW) * muH * 16;  // one RGBA32F mu target
    if (!localView.fbo) {  // made on first use
        localView.create(muW, muH, GL_NEAREST);
        sum[0].create(muW, muH, GL_NEAREST);
        sum[1].create(muW, muH, GL_NEAREST);
        memory.targets += 3 * muBytes;
        if (charts) {  // the passes draw the charts only: the texels around them stay 0
            for (Target* t : {&localView, &sum[0], &sum[1]}) {
                glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
                glClearColor(0, 0, 0, 0);
                glClear(GL_COLOR_BUFFER_BIT);
            }
        }
    }
    if (smoothing && rangeTex && !smoothed.fbo) {
        smoothed.create(muW, muH, GL_NEAREST);
        memory.targets += muBytes;
    }
    const bool timing = timed && options.timings;
    auto begin = [&](Stage s) {
        if (timing) this->begin(s);
    };
    auto end = [&](Stage s, double* ms) {
        if (timing) this->end(s, ms);
    };
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindVertexArray(emptyVao);
    glViewport(0, 0, muW, muH);

    // The local view direction per sample.
    begin(kView);
    glBindFramebuffer(GL_FRAMEBUFFER, localView.fbo);
    if (charts) {
        charts->localView(lastEye);
    } else {
        glUseProgram(viewProgram);
        glUniform3f(glGetUniformLocation(viewProgram, "uEye"), lastEye.x, lastEye.y, lastEye.z);
        bindTexture(0, GL_TEXTURE_2D, positionTex);
        bindTexture(1, GL_TEXTURE_2D, normalTex);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    end(kView, &timings.view);

    // D_mu: the generated passes, partial sums ping-ponging between sum[0] and sum[1].
    const Compiled& c = compiledFor(order);
    begin(kDecompress);
    for (size_t i = 0; i < c.programs.size(); ++i) {
        const DecompressionPass& pass = c.shaders.passes[i];
        glBindFramebuffer(GL_FRAMEBUFFER, sum[i % 2].fbo);
        glUseProgram(c.programs[i]);
        for (size_t u = 0; u < pass.samplers.size(); ++u) {
            const SamplerBinding& s = pass.samplers[u];
            int unit = static_cast<int>(u);
            switch (s.kind) {
                case SamplerBinding::LocalView:
                    bindTexture(unit, GL_TEXTURE_2D, localView.texture);
                    break;
                case SamplerBinding::PartialSum:
                    bindTexture(unit, GL_TEXTURE_2D, sum[(i + 1) % 2].texture);
                    break;
                case SamplerBinding::Weight:
                    bindTexture(unit, GL_TEXTURE_2D, weightTex[s.coefficient]);
                    break;
                case SamplerBinding::WeightArray:
                    bindTexture(unit, GL_TEXTURE_2D_ARRAY, weightArray);
                    break;
            }
        }
        if (charts)
            charts->drawFootprint();
        else
            glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    end(kDecompress, &timings.decompress);
    if (timed) timings.passes = static_cast<int>(c.programs.size());
    lastD = sum[(c.programs.size() + 1) % 2].texture;
    if (errorFold)
        lastD = errorFold->apply(lastD, localView.texture, [&] {
            if (charts)
                charts->drawFootprint();
            else
                glDrawArrays(GL_TRIANGLES, 0, 3);
        });

    // Optional spatial smoothing through the neighbour lists.
    if (timed) timings.smooth = 0;
    if (smoothing && rangeTex) {
        begin(kSmooth);
        glBindFramebuffer(GL_FRAMEBUFFER, smoothed.fbo);
        glUseProgram(smoothProgram);
        bindTexture(0, GL_TEXTURE_2D, lastD);
        bindTexture(1, GL_TEXTURE_2D, rangeTex);
        bindTexture(2, GL_TEXTURE_2D, nbrIndexTex);
        bindTexture(3, GL_TEXTURE_2D, nbrWeightTex);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        end(kSmooth, &timings.smooth);
        lastD = smoothed.texture;
    }
}

void Refractor::Impl::unpackRho(bool timed) {
    const bool timing = timed && options.timings;
    if (timing) begin(kUnpack);
    glViewport(0, 0, rhoW, rhoH);
    glBindFramebuffer(GL_FRAMEBUFFER, rho.fbo);
    glBindVertexArray(emptyVao);
    glUseProgram(unpackProgram);
    setInt(unpackProgram, "uCorrection", correction ? 1 : 0);
    bindTexture(0, GL_TEXTURE_2D, rhoIndexTex);
    bindTexture(1, GL_TEXTURE_2D, lastD);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    if (timing) end(kUnpack, &timings.unpack);
    rhoReady = true;
}

// Chart bakes: D -> gutters (the unpack's place in the timings) -> [texture-space smoothing] into
// the atlas refraction map.
void Refractor::Impl::buildChartMap(bool timed) {
    const bool timing = timed && options.timings;
    if (timing) begin(kUnpack);
    const GLuint filled = charts->fillGutters(lastD, smoothing ? 0 : rho.fbo);
    if (timing) end(kUnpack, &timings.unpack);
    if (smoothing) {
        if (timing) begin(kSmooth);
        charts->smooth(filled, rho.fbo);
        if (timing) end(kSmooth, &timings.smooth);
        lastD = rho.texture;  // readDirectionalMap(): the smoothed values
    }
    rhoReady = true;
}

void Refractor::update(glm::vec3 eye, const glm::mat4& model) {
    Impl& m = *impl_;
    m.use();
    GLint viewport[4], framebuffer = 0;
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
    m.lastEye = glm::vec3(glm::inverse(model) * glm::vec4(eye, 1.0f));  // eye to object space
    m.rhoReady = false;
    m.timings = Timings{};
    if (m.vertexMode()) {
        // Everything happens in draw(); an app that asked for the refraction map keeps getting it.
        if (m.rhoIndexTex) {
            m.decompressInTextureSpace(false);
            m.unpackRho(false);
        }
    } else {
        m.decompressInTextureSpace(true);
        // The rho path unpacks every frame; the direct path only for an app that asked for it.
        if (m.charts) m.buildChartMap(true);
        else if (!m.direct) m.unpackRho(true);
        else if (m.rhoIndexTex) m.unpackRho(false);
    }
    if (m.ior.active) {
        // Shading at other indices (runtime/src/ior.h) reads D_mu from a texture on the direct
        // path, and the bracketing bake's D for the same view; its stages count in this frame's.
        if (m.direct && m.vertexMode()) m.decompressInTextureSpace(true);
        if (Refractor* other = m.ior.bracket) {
            other->update(eye, model);
            Impl& b = *other->impl_;
            if (m.direct && b.vertexMode()) b.decompressInTextureSpace(false);
            m.ior.bracketD = m.direct ? b.lastD : other->refractionMap();
            m.timings.view += b.timings.view, m.timings.decompress += b.timings.decompress;
            m.timings.smooth += b.timings.smooth, m.timings.unpack += b.timings.unpack;
            m.timings.passes += b.timings.passes;
            m.use();
        }
    }
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
    const bool vertexSh = m.vertexMode() && !m.ior.active;
    GLuint p = m.ior.active       ? m.ior.program(m.direct, m.muW)
               : !m.direct        ? m.shadeRhoProgram
               : vertexSh         ? m.compiledFor(m.order).shadeVertexSh
                                  : m.directTextureProgram();
    glUseProgram(p);
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
    setFloat(p, "uEta", m.bake.ior());
    glm::vec3 kappa = m.bake.absorption();
    glUniform3f(glGetUniformLocation(p, "uKappa"), kappa.x, kappa.y, kappa.z);
    setInt(p, "uToneMap", m.options.toneMap ? 1 : 0);
    setFloat(p, "uExposure", m.options.exposure);
    setInt(p, "uSpread", m.spread ? 1 : 0);
    setFloat(p, "uSpreadScale", m.options.spreadScale);
    setFloat(p, "uBlendSigma", m.options.shading == "blend" ? m.options.blendSigma : 0.0f);
    setFloat(p, "uJitterCell", m.options.shading == "jitter" ? m.options.jitterCell * m.diagonal : 0.0f);
    setFloat(p, "uFootprintScale", m.options.footprintScale);
    useEnvironment(p, environment, 0);
    if (m.ior.active)
        m.ior.setUniforms(p, m.bake.ior(), m.ior.bracket ? m.ior.bracket->impl_->bake.ior() : 0.0f);
    if (m.direct) {
        bindTexture(1, GL_TEXTURE_2D, m.lastD);
        bindTexture(2, GL_TEXTURE_2D, m.positionTex);
        bindTexture(3, GL_TEXTURE_2D, m.normalTex);
        if (vertexSh) {
            // Eye in object space, and the weights from unit 4 on (compiledFor's assignment).
            const glm::vec3 e = glm::vec3(glm::inverse(model) * glm::vec4(eye, 1.0f));
            glUniform3f(glGetUniformLocation(p, "uEyeObject"), e.x, e.y, e.z);
            m.bindWeights(m.compiledFor(m.order).shaders.passes[0], 4);
        }
        glBindVertexArray(m.directVao);
        glDrawElements(GL_TRIANGLES, m.directIndexCount, GL_UNSIGNED_INT, nullptr);
    } else {
        bindTexture(1, GL_TEXTURE_2D, m.rho.texture);
        glBindVertexArray(m.rhoVao);
        glDrawArrays(GL_TRIANGLES, 0, m.rhoVertexCount);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    glActiveTexture(GL_TEXTURE0);
    m.end(kShade, &m.timings.shade);
    SHREFRACT_GL_CHECK();
}

unsigned Refractor::refractionMap() {
    Impl& m = *impl_;
    m.use();
    if (!m.rhoReady) {
        GLint viewport[4], framebuffer = 0;
        glGetIntegerv(GL_VIEWPORT, viewport);
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
        if (m.charts) {
            m.decompressInTextureSpace(false);
            m.buildChartMap(false);
        } else {
            m.ensureRhoResources();
            if (m.vertexMode()) m.decompressInTextureSpace(false);
            m.unpackRho(false);
        }
        glUseProgram(0);
        glBindVertexArray(0);
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
        glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    }
    return m.rho.texture;
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
        const SurfaceLayout &a = impl_->bake.data().layout, &b = other->impl_->bake.data().layout;
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

glm::ivec2 Refractor::refractionMapSize() const { return {impl_->rhoW, impl_->rhoH}; }
std::string Refractor::path() const {
    return impl_->charts ? "charts" : impl_->direct ? "direct" : "rho";
}
std::string Refractor::decompression() const { return impl_->vertexMode() ? "vertex" : "texture"; }

void Refractor::setOrder(int L) {
    // As RefractorOptions::order: -1 is every uploaded band, above maxOrder clamps to it.
    if (L < -1)
        throw std::invalid_argument("shrefract: setOrder(" + std::to_string(L) +
                                    "): -1 (all) or 0 and up");
    impl_->use();
    impl_->order = L < 0 ? impl_->maxOrder : std::min(L, impl_->maxOrder);
    impl_->compiledFor(impl_->order);
}
int Refractor::order() const { return impl_->order; }
void Refractor::setSmoothing(bool on) {
    if (on && impl_->vertexShRequired)
        throw std::invalid_argument(
            "shrefract: smoothing needs texture-space decompression (decompression \"vertex\" was asked for)");
    impl_->smoothing = on;
}
void Refractor::setCorrection(bool on) { impl_->correction = on; }
void Refractor::setGutter(int texels) {
    if (!impl_->charts) return;
    impl_->use();
    impl_->charts->setDilation(texels < 0 ? impl_->bake.data().layout.atlas.gutter : texels);
}
int Refractor::gutter() const { return impl_->charts ? impl_->charts->dilation() : 0; }
void Refractor::setSeamAware(bool on) {
    if (impl_->charts) impl_->charts->setSeamAware(on);
}
bool Refractor::seamAware() const { return impl_->charts && impl_->charts->seamAware(); }
void Refractor::setTimings(bool on) {
    if (!on) impl_->timings = Timings{};
    impl_->options.timings = on;
}
const Timings& Refractor::timings() const { return impl_->timings; }
const GpuMemory& Refractor::memory() const { return impl_->memory; }
int Refractor::passCount() const {
    return impl_->vertexMode() ? 0 : static_cast<int>(impl_->compiledFor(impl_->order).programs.size());
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

// A mu-layout texture read back in sample order (chart bakes: each sample from its atlas texel).
static std::vector<float> readSamples(const Refractor::Impl& m, GLuint texture) {
    std::vector<float> all = readTexture(texture, m.muW, m.muH);
    const SurfaceLayout& L = m.bake.data().layout;
    if (L.isChartLayout()) {
        std::vector<float> samples(static_cast<size_t>(L.sampleCount()) * 4);
        for (int i = 0; i < L.sampleCount(); ++i) {
            const glm::ivec2 t = L.muTexel(i);
            std::copy_n(&all[(static_cast<size_t>(t.y) * m.muW + t.x) * 4], 4, &samples[size_t(i) * 4]);
        }
        return samples;
    }
    all.resize(static_cast<size_t>(L.sampleCount()) * 4);
    return all;
}

std::vector<float> Refractor::readDirectionalMap() const {
    Impl& m = *impl_;
    m.use();
    if (m.vertexMode()) {
        // The same generated shPass(), run in texture space for the last eye.
        GLint viewport[4], framebuffer = 0;
        glGetIntegerv(GL_VIEWPORT, viewport);
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
        m.decompressInTextureSpace(false);
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
        glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    }
    return readSamples(m, m.lastD);
}

std::vector<float> Refractor::readLocalViewMap() const {
    impl_->use();
    if (!impl_->localView.texture) readDirectionalMap();
    return readSamples(*impl_, impl_->localView.texture);
}

std::vector<float> Refractor::readRefractionMap() {
    impl_->use();
    const GLuint t = refractionMap();
    return readTexture(t, impl_->rhoW, impl_->rhoH);
}

}  // namespace shrefract
