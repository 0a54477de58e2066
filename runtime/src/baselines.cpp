// Single-sided refraction and Wyman 2005 (docs/evaluation.md). Pass 1 (Wyman only) draws the
// nearest back faces' normals and view depth into a viewport-sized RGBA32F target; pass 2 shades
// the front faces into the caller's framebuffer.
#include "bake_data.h"
#include "shrefract/baselines.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "common/bakefile.h"
#include "gl.h"
#include "environment_gl.h"
#include "frame_uniforms.h"
#include "gpu_timer.h"
#include "shaders.h"

namespace shrefract {

using namespace gl;

struct Baseline::Impl {
    Bake bake;
    BaselineOptions options;
    gl::Loader loader = nullptr;
    GLuint backProgram = 0, shadeProgram = 0, vao = 0, vbo = 0;
    GLuint backTexture = 0, backDepth = 0, backFbo = 0;
    int backW = 0, backH = 0, vertexCount = 0;
    std::unique_ptr<GpuStageTimer> timer;  // stages: 0 back faces, 1 shading
    BaselineTimings timings;

    void use() const { ensureLoaded(loader); }
    void resizeBack(int w, int h) {
        if (w == backW && h == backH) return;
        if (backFbo) glDeleteFramebuffers(1, &backFbo);
        if (backTexture) glDeleteTextures(1, &backTexture);
        if (backDepth) glDeleteRenderbuffers(1, &backDepth);
        glGenTextures(1, &backTexture);
        glBindTexture(GL_TEXTURE_2D, backTexture);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glGenRenderbuffers(1, &backDepth);
        glBindRenderbuffer(GL_RENDERBUFFER, backDepth);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
        glGenFramebuffers(1, &backFbo);
        glBindFramebuffer(GL_FRAMEBUFFER, backFbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, backTexture, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, backDepth);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error("shrefract: back-face target incomplete");
        backW = w, backH = h;
    }
};

Baseline::Baseline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Baseline> Baseline::create(const Bake& bake, const std::vector<float>& normalDistance,
                                           const BaselineOptions& options) {
    auto m = std::make_unique<Impl>();
    m->bake = bake;
    m->options = options;
    m->loader = options.loader ? options.loader : currentContextLoader();
    m->use();
    if (!glGetString(GL_VERSION)) throw std::runtime_error("shrefract: no current OpenGL context");
    const SurfaceLayout& L = bakeData(bake).layout;
    const size_t points = L.isChartLayout() ? L.atlas.vertexPosition.size() : size_t(L.sampleCount());
    if (options.method == BaselineMethod::Wyman && normalDistance.size() != points)
        throw std::invalid_argument("shrefract: Wyman needs d_N for every drawn point (" +
                                    std::to_string(points) + "), got " +
                                    std::to_string(normalDistance.size()));
    m->backProgram = buildProgram(shaders::source("baseline.vert"), shaders::source("back_face.frag"), "Wyman back faces");
    m->shadeProgram = buildProgram(shaders::source("baseline.vert"), shaders::source("baseline.frag"), "baseline shading");
    glUseProgram(m->shadeProgram);
    glUniform1i(glGetUniformLocation(m->shadeProgram, "uBack"), 1);
    glUseProgram(0);

    // The Refractor's mesh (common/bakefile.h drawCorners), d_N per drawn point.
    std::vector<float> vertices;
    vertices.reserve(static_cast<size_t>(L.triangleCount) * 3 * 7);
    for (const DrawCorner& c : drawCorners(L)) {
        const float dN = normalDistance.empty() ? 0.0f : normalDistance[c.id];
        const float v[7] = {c.position.x, c.position.y, c.position.z, c.normal.x, c.normal.y,
                            c.normal.z, dN};
        vertices.insert(vertices.end(), v, v + 7);
    }
    m->vertexCount = L.triangleCount * 3;
    glGenVertexArrays(1, &m->vao);
    glBindVertexArray(m->vao);
    glGenBuffers(1, &m->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(float), vertices.data(), GL_STATIC_DRAW);
    for (int a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, 7 * sizeof(float),
                          reinterpret_cast<void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    m->timer = std::make_unique<GpuStageTimer>(2);
    m->timer->setEnabled(options.timings);
    SHREFRACT_GL_CHECK();
    return std::unique_ptr<Baseline>(new Baseline(std::move(m)));
}

Baseline::~Baseline() {
    Impl& m = *impl_;
    try {
        m.use();
    } catch (...) {
        (void)m.timer.release();  // no GL any more: nothing to release safely
        return;
    }
    glDeleteProgram(m.backProgram);
    glDeleteProgram(m.shadeProgram);
    glDeleteVertexArrays(1, &m.vao);
    glDeleteBuffers(1, &m.vbo);
    if (m.backFbo) glDeleteFramebuffers(1, &m.backFbo);
    if (m.backTexture) glDeleteTextures(1, &m.backTexture);
    if (m.backDepth) glDeleteRenderbuffers(1, &m.backDepth);
}

const BaselineTimings& Baseline::timings() const { return impl_->timings; }
void Baseline::setTimings(bool on) {
    if (!on) impl_->timings = BaselineTimings{};
    impl_->timer->setEnabled(on);
}
bool Baseline::timingsEnabled() const { return impl_->timer->enabled(); }

void Baseline::draw(const glm::mat4& view, const glm::mat4& projection, const glm::mat4& model,
                    const Environment& environment) {
    Impl& m = *impl_;
    m.use();
    GLint viewport[4], framebuffer = 0;
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
    FrameUniforms frame(view, projection, model);
    frame.eta = m.bake.ior();
    frame.kappa = m.options.absorption.value_or(m.bake.absorption());
    frame.toneMap = m.options.toneMap;
    frame.exposure = m.options.exposure;
    const float scale = std::cbrt(std::abs(glm::determinant(glm::mat3(model))));
    auto common = [&](GLuint p) {
        glUseProgram(p);
        frame.set(p);
        glUniformMatrix4fv(glGetUniformLocation(p, "uView"), 1, GL_FALSE, glm::value_ptr(view));
    };
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glBindVertexArray(m.vao);

    m.timings.backFaces = 0;
    const bool wyman = m.options.method == BaselineMethod::Wyman;
    if (wyman) {
        m.timer->begin(0);
        m.resizeBack(viewport[2], viewport[3]);
        glBindFramebuffer(GL_FRAMEBUFFER, m.backFbo);
        glViewport(0, 0, viewport[2], viewport[3]);
        glClearColor(0, 0, 0, 0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        common(m.backProgram);
        glDrawArrays(GL_TRIANGLES, 0, m.vertexCount);
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
        glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
        m.timer->end(0, &m.timings.backFaces);
    }

    m.timer->begin(1);
    GLuint p = m.shadeProgram;
    common(p);
    glUniform1f(glGetUniformLocation(p, "uScale"), scale);
    glUniform1i(glGetUniformLocation(p, "uMethod"), wyman ? 1 : 0);
    glUniform1i(glGetUniformLocation(p, "uTir"), static_cast<int>(m.options.tir));
    glUniform2f(glGetUniformLocation(p, "uViewportOrigin"), float(viewport[0]), float(viewport[1]));
    useEnvironment(p, environment, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, wyman ? m.backTexture : 0);
    glDrawArrays(GL_TRIANGLES, 0, m.vertexCount);
    glBindVertexArray(0);
    glUseProgram(0);
    glActiveTexture(GL_TEXTURE0);
    m.timer->end(1, &m.timings.shade);
    SHREFRACT_GL_CHECK();
}

}  // namespace shrefract
