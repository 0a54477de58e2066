#include "gl.h"

#include <cstdio>
#include <stdexcept>
#include <vector>

namespace shrefract::gl {

#define SHREFRACT_GL_DEFINE(type, name) type name = nullptr;
SHREFRACT_GL_FUNCTIONS(SHREFRACT_GL_DEFINE)
#undef SHREFRACT_GL_DEFINE

namespace {
Loader g_loaded = nullptr;
}

void ensureLoaded(Loader loader) {
    if (!loader) throw std::runtime_error("shrefract: no OpenGL loader (is a context current?)");
    if (loader == g_loaded) return;
#define SHREFRACT_GL_LOAD(type, name)                                                     \
    name = reinterpret_cast<type>(loader(#name));                                         \
    if (!name) throw std::runtime_error("shrefract: OpenGL function " #name " not found");
    SHREFRACT_GL_FUNCTIONS(SHREFRACT_GL_LOAD)
#undef SHREFRACT_GL_LOAD
    g_loaded = loader;
}

static GLuint compile(GLenum stage, const std::string& source, const std::string& what) {
    GLuint s = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(s, 1, &text, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        glGetShaderiv(s, GL_INFO_LOG_LENGTH, &n);
        std::vector<char> log(n + 1, '\0');
        glGetShaderInfoLog(s, n, nullptr, log.data());
        glDeleteShader(s);
        throw std::runtime_error("shrefract: compiling " + what + " (" +
                                 (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                                 "): " + log.data());
    }
    return s;
}

GLuint buildProgram(const std::string& vertex, const std::string& fragment,
                    const std::string& what) {
    GLuint vs = compile(GL_VERTEX_SHADER, vertex, what);
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, fragment, what);
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        glGetProgramiv(p, GL_INFO_LOG_LENGTH, &n);
        std::vector<char> log(n + 1, '\0');
        glGetProgramInfoLog(p, n, nullptr, log.data());
        glDeleteProgram(p);
        throw std::runtime_error("shrefract: linking " + what + ": " + log.data());
    }
    return p;
}

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

#ifndef NDEBUG
void checkGlError(const char* file, int line) {
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) std::fprintf(stderr, "shrefract: GL error 0x%04x at %s:%d\n", e, file, line);
}
#endif

void Target::create(int w, int h, GLenum filter) {
    texture = makeTexture2D(GL_RGBA32F, w, h, GL_RGBA, GL_FLOAT, nullptr, filter);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("shrefract: RGBA32F render target incomplete");
}

void Target::destroy() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (texture) glDeleteTextures(1, &texture);
    fbo = texture = 0;
}

std::vector<float> readTextureRGBA(GLuint texture, int w, int h) {
    std::vector<float> out(static_cast<size_t>(w) * h * 4);
    glBindTexture(GL_TEXTURE_2D, texture);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, out.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    return out;
}

SavedTarget::SavedTarget() {
    glGetIntegerv(GL_VIEWPORT, viewport_);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer_);
}

SavedTarget::~SavedTarget() {
    glUseProgram(0);
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(framebuffer_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
}

}  // namespace shrefract::gl
