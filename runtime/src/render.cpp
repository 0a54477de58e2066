#include "shrefract/render.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include <ImfOutputFile.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <glm/gtc/matrix_transform.hpp>

#include "common/exr_output.h"
#include "common/output.h"
#include "common/png.h"
#include "common/tonemap.h"
#include "shrefract/baselines.h"
#include "gl.h"

namespace shrefract {

using namespace gl;

Camera Camera::orbit(float azimuthDeg, float elevationDeg, float distance, glm::vec3 target) {
    if (!(distance > 0.0f)) throw std::invalid_argument("orbit distance must be > 0");
    float az = glm::radians(azimuthDeg), el = glm::radians(elevationDeg);
    Camera c;
    c.target = target;
    // Azimuth 0 looks from +z toward the target; positive azimuth turns toward +x; y is up.
    c.eye = target + distance * glm::vec3(std::cos(el) * std::sin(az), std::sin(el),
                                          std::cos(el) * std::cos(az));
    return c;
}

glm::vec3 toneMap(glm::vec3 c, float exposure) { return toneMapAces(c, exposure); }

glm::mat4 viewMatrix(const Camera& camera) {
    return glm::lookAt(camera.eye, camera.target, camera.up);
}

glm::mat4 projectionMatrix(const Camera& camera, int width, int height) {
    // Clip planes scale with the viewing distance, so objects of any size are drawn (a fixed
    // 0.01..1000 lost spheres scaled by 1e-4 and 1e4: tests/stability).
    const float distance = glm::length(camera.eye - camera.target);
    return glm::perspective(glm::radians(camera.fovDegrees), float(width) / float(height),
                            1e-2f * distance, 1e2f * distance);
}

namespace {

using DrawObject = std::function<void(const glm::mat4& view, const glm::mat4& projection)>;

// One frame of each kind of method, between binding a target and reading or finishing it.
DrawObject drawing(Refractor& refractor, const Environment& environment) {
    return [&refractor, &environment](const glm::mat4& view, const glm::mat4& projection) {
        refractor.update({view, projection, glm::mat4(1.0f)});
        environment.drawBackground(view, projection);
        refractor.draw(environment);
    };
}
DrawObject drawing(Baseline& baseline, const Environment& environment) {
    return [&baseline, &environment](const glm::mat4& view, const glm::mat4& projection) {
        environment.drawBackground(view, projection);
        baseline.draw(view, projection, glm::mat4(1.0f), environment);
    };
}

// Offscreen colour + direction targets (OffscreenTarget), then `drawObject(view, projection)`,
// read back.
RenderedFrame renderWith(const DrawObject& drawObject, const Camera& camera, int width, int height) {
    ensureLoaded(currentContextLoader());
    OffscreenTarget target(width, height);
    target.bind();
    drawObject(viewMatrix(camera), projectionMatrix(camera, width, height));
    RenderedFrame out = target.read();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return out;
}

double timeWith(const DrawObject& drawObject, const Camera& camera, int width, int height, int frames) {
    if (frames < 1) throw std::invalid_argument("shrefract: frameWallMs needs at least one frame");
    ensureLoaded(currentContextLoader());
    OffscreenTarget target(width, height);
    const glm::mat4 view = viewMatrix(camera), projection = projectionMatrix(camera, width, height);
    using Clock = std::chrono::steady_clock;
    auto frame = [&] {
        const auto t0 = Clock::now();
        target.bind();
        drawObject(view, projection);
        glFinish();
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    };
    const auto warm = Clock::now();
    for (int k = 0; k < 2 || Clock::now() - warm < std::chrono::milliseconds(500); ++k) frame();
    std::vector<double> ms;
    for (int k = 0; k < frames; ++k) ms.push_back(frame());
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
    return ms[ms.size() / 2];
}

}  // namespace

RenderedFrame renderFrame(Refractor& refractor, const Environment& environment,
                          const Camera& camera, int width, int height) {
    RenderedFrame out = renderWith(drawing(refractor, environment), camera, width, height);
    out.timings = refractor.timings();
    return out;
}

RenderedFrame renderFrame(Baseline& baseline, const Environment& environment,
                          const Camera& camera, int width, int height) {
    return renderWith(drawing(baseline, environment), camera, width, height);
}

double frameWallMs(Refractor& refractor, const Environment& environment, const Camera& camera,
                   int width, int height, int frames) {
    // Never with the stage timers: each would wait for the GPU (gpu_timer.h).
    const bool timers = refractor.timingsEnabled();
    refractor.setTimings(false);
    const double ms = timeWith(drawing(refractor, environment), camera, width, height, frames);
    refractor.setTimings(timers);
    return ms;
}

double frameWallMs(Baseline& baseline, const Environment& environment, const Camera& camera,
                   int width, int height, int frames) {
    const bool timers = baseline.timingsEnabled();
    baseline.setTimings(false);
    const double ms = timeWith(drawing(baseline, environment), camera, width, height, frames);
    baseline.setTimings(timers);
    return ms;
}

OffscreenTarget::OffscreenTarget(int width, int height) : width_(width), height_(height) {
    if (width < 1 || height < 1) throw std::invalid_argument("shrefract: empty offscreen target");
    ensureLoaded(currentContextLoader());
    GLuint textures[2];
    glGenTextures(2, textures);
    color_ = textures[0];
    directions_ = textures[1];
    for (GLuint t : textures) {
        glBindTexture(GL_TEXTURE_2D, t);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenRenderbuffers(1, &depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glGenFramebuffers(1, &fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, directions_, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!complete) {
        glDeleteFramebuffers(1, &fbo_);
        glDeleteRenderbuffers(1, &depth_);
        glDeleteTextures(2, textures);
        throw std::runtime_error("shrefract: offscreen framebuffer incomplete");
    }
}

OffscreenTarget::~OffscreenTarget() {
    try {
        ensureLoaded(currentContextLoader());
    } catch (...) {
        return;  // no context any more: nothing to release safely
    }
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (depth_) glDeleteRenderbuffers(1, &depth_);
    GLuint textures[2] = {color_, directions_};
    glDeleteTextures(2, textures);
    fbo_ = depth_ = color_ = directions_ = 0;
}

void OffscreenTarget::bind() {
    ensureLoaded(currentContextLoader());
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, buffers);
    glViewport(0, 0, width_, height_);
    glClearColor(0, 0, 0, 0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

RenderedFrame OffscreenTarget::read() const {
    ensureLoaded(currentContextLoader());
    RenderedFrame out;
    out.width = width_;
    out.height = height_;
    GLint previous = 0;
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &previous);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    std::vector<float> rows(static_cast<size_t>(width_) * height_ * 4);
    const size_t stride = static_cast<size_t>(width_) * 4;
    for (int a = 0; a < 2; ++a) {
        glReadBuffer(GL_COLOR_ATTACHMENT0 + a);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, rows.data());
        std::vector<float>& dst = a == 0 ? out.color : out.directions;
        dst.resize(rows.size());
        // GL's rows are bottom-up.
        for (int y = 0; y < height_; ++y)
            std::copy_n(&rows[(height_ - 1 - y) * stride], stride, &dst[y * stride]);
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, previous);
    return out;
}

void writePng(const std::string& path, const RenderedFrame& frame, float exposure) {
    const int w = frame.width, h = frame.height;
    std::vector<unsigned char> pixels(static_cast<size_t>(w) * h * 3);
    for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i) {
        glm::vec3 c = toneMap({frame.color[4 * i], frame.color[4 * i + 1], frame.color[4 * i + 2]},
                              exposure);
        for (int k = 0; k < 3; ++k)
            pixels[3 * i + k] = static_cast<unsigned char>(std::lround(c[k] * 255.0f));
    }
    writePngRgb8(path, w, h, pixels.data());
}

void writeExr(const std::string& path, int width, int height, const std::vector<float>& rgba) {
    writeAtomically(path, [&](const std::string& staged) {
        Imf::Header header(width, height);
        const char* names[4] = {"R", "G", "B", "A"};
        Imf::FrameBuffer fb;
        for (int c = 0; c < 4; ++c) {
            header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
            fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(rgba.data() + c),
                                           4 * sizeof(float), 4 * sizeof(float) * width));
        }
        writeExrFile(staged, [&](Imf::OStream& stream) {
            Imf::OutputFile file(stream, header);
            file.setFrameBuffer(fb);
            file.writePixels(height);
        });
    });
}

}  // namespace shrefract
