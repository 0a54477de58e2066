// A tiny OpenGL function-pointer loader: the core 3.3 functions the runtime calls, resolved
// through the caller's getProcAddress (eglGetProcAddress, OSMesaGetProcAddress, glfw...).
//
// Why not link libOpenGL.so: an OSMesa context is not reachable through GLVND's dispatch, so
// the same binary could not drive both headless backends. Loading pointers works for both.
// Include this header instead of any GL header; it declares no prototypes.
#pragma once

#include <GL/glcorearb.h>

#include <string>
#include <vector>

namespace shrefract::gl {

// Resolves one GL entry point by name in the current context; nullptr if unknown.
using Loader = void* (*)(const char* name);

// The function list: X(type, name).
#define SHREFRACT_GL_FUNCTIONS(X)                                          \
    X(PFNGLGETERRORPROC, glGetError)                                       \
    X(PFNGLGETSTRINGPROC, glGetString)                                     \
    X(PFNGLGETINTEGERVPROC, glGetIntegerv)                                 \
    X(PFNGLENABLEPROC, glEnable)                                           \
    X(PFNGLDISABLEPROC, glDisable)                                         \
    X(PFNGLVIEWPORTPROC, glViewport)                                       \
    X(PFNGLCLEARPROC, glClear)                                             \
    X(PFNGLCLEARCOLORPROC, glClearColor)                                   \
    X(PFNGLDEPTHFUNCPROC, glDepthFunc)                                     \
    X(PFNGLDEPTHMASKPROC, glDepthMask)                                     \
    X(PFNGLPIXELSTOREIPROC, glPixelStorei)                                 \
    X(PFNGLREADPIXELSPROC, glReadPixels)                                   \
    X(PFNGLREADBUFFERPROC, glReadBuffer)                                   \
    X(PFNGLFINISHPROC, glFinish)                                           \
    X(PFNGLGENTEXTURESPROC, glGenTextures)                                 \
    X(PFNGLDELETETEXTURESPROC, glDeleteTextures)                           \
    X(PFNGLBINDTEXTUREPROC, glBindTexture)                                 \
    X(PFNGLACTIVETEXTUREPROC, glActiveTexture)                             \
    X(PFNGLTEXIMAGE2DPROC, glTexImage2D)                                   \
    X(PFNGLTEXIMAGE3DPROC, glTexImage3D)                                   \
    X(PFNGLTEXSUBIMAGE3DPROC, glTexSubImage3D)                             \
    X(PFNGLTEXPARAMETERIPROC, glTexParameteri)                             \
    X(PFNGLGETTEXIMAGEPROC, glGetTexImage)                                 \
    X(PFNGLGENFRAMEBUFFERSPROC, glGenFramebuffers)                         \
    X(PFNGLDELETEFRAMEBUFFERSPROC, glDeleteFramebuffers)                   \
    X(PFNGLBINDFRAMEBUFFERPROC, glBindFramebuffer)                         \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, glFramebufferTexture2D)               \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, glFramebufferRenderbuffer)         \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, glCheckFramebufferStatus)           \
    X(PFNGLDRAWBUFFERSPROC, glDrawBuffers)                                 \
    X(PFNGLGENRENDERBUFFERSPROC, glGenRenderbuffers)                       \
    X(PFNGLDELETERENDERBUFFERSPROC, glDeleteRenderbuffers)                 \
    X(PFNGLBINDRENDERBUFFERPROC, glBindRenderbuffer)                       \
    X(PFNGLRENDERBUFFERSTORAGEPROC, glRenderbufferStorage)                 \
    X(PFNGLCREATESHADERPROC, glCreateShader)                               \
    X(PFNGLSHADERSOURCEPROC, glShaderSource)                               \
    X(PFNGLCOMPILESHADERPROC, glCompileShader)                             \
    X(PFNGLGETSHADERIVPROC, glGetShaderiv)                                 \
    X(PFNGLGETSHADERINFOLOGPROC, glGetShaderInfoLog)                       \
    X(PFNGLDELETESHADERPROC, glDeleteShader)                               \
    X(PFNGLCREATEPROGRAMPROC, glCreateProgram)                             \
    X(PFNGLATTACHSHADERPROC, glAttachShader)                               \
    X(PFNGLLINKPROGRAMPROC, glLinkProgram)                                 \
    X(PFNGLGETPROGRAMIVPROC, glGetProgramiv)                               \
    X(PFNGLGETPROGRAMINFOLOGPROC, glGetProgramInfoLog)                     \
    X(PFNGLDELETEPROGRAMPROC, glDeleteProgram)                             \
    X(PFNGLUSEPROGRAMPROC, glUseProgram)                                   \
    X(PFNGLGETUNIFORMLOCATIONPROC, glGetUniformLocation)                   \
    X(PFNGLUNIFORM1IPROC, glUniform1i)                                     \
    X(PFNGLUNIFORM1FPROC, glUniform1f)                                     \
    X(PFNGLUNIFORM2FPROC, glUniform2f)                                     \
    X(PFNGLUNIFORM3FPROC, glUniform3f)                                     \
    X(PFNGLUNIFORM4FVPROC, glUniform4fv)                                   \
    X(PFNGLUNIFORMMATRIX3FVPROC, glUniformMatrix3fv)                       \
    X(PFNGLUNIFORMMATRIX4FVPROC, glUniformMatrix4fv)                       \
    X(PFNGLBINDFRAGDATALOCATIONPROC, glBindFragDataLocation)               \
    X(PFNGLBINDATTRIBLOCATIONPROC, glBindAttribLocation)                   \
    X(PFNGLGENVERTEXARRAYSPROC, glGenVertexArrays)                         \
    X(PFNGLDELETEVERTEXARRAYSPROC, glDeleteVertexArrays)                   \
    X(PFNGLBINDVERTEXARRAYPROC, glBindVertexArray)                         \
    X(PFNGLGENBUFFERSPROC, glGenBuffers)                                   \
    X(PFNGLDELETEBUFFERSPROC, glDeleteBuffers)                             \
    X(PFNGLBINDBUFFERPROC, glBindBuffer)                                   \
    X(PFNGLBUFFERDATAPROC, glBufferData)                                   \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, glEnableVertexAttribArray)         \
    X(PFNGLVERTEXATTRIBPOINTERPROC, glVertexAttribPointer)                 \
    X(PFNGLDRAWARRAYSPROC, glDrawArrays)                                   \
    X(PFNGLDRAWELEMENTSPROC, glDrawElements)                               \
    X(PFNGLGENQUERIESPROC, glGenQueries)                                   \
    X(PFNGLDELETEQUERIESPROC, glDeleteQueries)                             \
    X(PFNGLBEGINQUERYPROC, glBeginQuery)                                   \
    X(PFNGLENDQUERYPROC, glEndQuery)                                       \
    X(PFNGLGETQUERYOBJECTUI64VPROC, glGetQueryObjectui64v)

#define SHREFRACT_GL_DECLARE(type, name) extern type name;
SHREFRACT_GL_FUNCTIONS(SHREFRACT_GL_DECLARE)
#undef SHREFRACT_GL_DECLARE

// Resolves every function through `loader` unless it is the loader used last time (cheap to call
// at each entry point). Throws std::runtime_error naming the first missing function.
void ensureLoaded(Loader loader);
// The loader for whatever context is current: OSMesa's if an OSMesa context is current, else
// eglGetProcAddress (which also serves GLX and EGL contexts under GLVND).
Loader currentContextLoader();

// Compiles and links a program; throws std::runtime_error with the info log and `what`.
GLuint buildProgram(const std::string& vertex, const std::string& fragment, const std::string& what);

// A 2D texture with `filter` for minification and magnification and GL_CLAMP_TO_EDGE, from
// `data` (tightly packed rows; nullptr: undefined contents). Leaves it bound to GL_TEXTURE_2D.
GLuint makeTexture2D(GLenum internal, int w, int h, GLenum format, GLenum type, const void* data,
                     GLenum filter);

// Level 0 of a 2D texture of w x h texels, read back as RGBA floats, row-major from row 0.
std::vector<float> readTextureRGBA(GLuint texture, int w, int h);

// An RGBA32F texture and the framebuffer that renders into it (the runtime's passes' targets).
struct Target {
    GLuint texture = 0, fbo = 0;
    // Throws std::runtime_error if the framebuffer is incomplete. Leaves it bound.
    void create(int w, int h, GLenum filter);
    void destroy();
};

// Saves the viewport and the draw framebuffer, and puts them back (with no program, vertex array
// or texture unit other than 0 left current) when it goes out of scope: the runtime's passes
// render into their own targets inside an app's frame.
class SavedTarget {
public:
    SavedTarget();
    ~SavedTarget();
    SavedTarget(const SavedTarget&) = delete;
    SavedTarget& operator=(const SavedTarget&) = delete;

private:
    GLint viewport_[4] = {0, 0, 0, 0};
    GLint framebuffer_ = 0;
};

// GL error check that compiles out of release builds (docs/design.md#errors).
#ifdef NDEBUG
#define SHREFRACT_GL_CHECK() ((void)0)
#else
void checkGlError(const char* file, int line);
#define SHREFRACT_GL_CHECK() ::shrefract::gl::checkGlError(__FILE__, __LINE__)
#endif

}  // namespace shrefract::gl
