// Headless OpenGL contexts for tools and tests: one small interface, two backends.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "shrefract/enum_names.h"

namespace shrefract {

enum class Backend { Egl, OSMesa };
template <> struct EnumNames<Backend> {
    static constexpr const char* what = "GL backend";
    static constexpr NamedValue<Backend> table[] = {{Backend::Egl, "egl"}, {Backend::OSMesa, "osmesa"}};
};

// No context could be made (library missing, driver refused): the message says which and why.
struct ContextError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// An OpenGL 3.3+ core context with no window. Render into framebuffer objects; the size given at
// creation only sizes OSMesa's default buffer.
class HeadlessContext {
public:
    virtual ~HeadlessContext() = default;
    // Makes this context current on the calling thread.
    virtual void makeCurrent() = 0;
    // Which backend made it.
    virtual Backend backend() const = 0;
    // Resolves a GL function by name for this context (pass to RefractorOptions::loader).
    virtual void* (*loader() const)(const char*) = 0;
    // GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile)".
    virtual std::string description() const = 0;
};

// Creates a core-profile context (4.5, else 3.3) and makes it current. EGL: Mesa's surfaceless
// platform, no surface. OSMesa: libOSMesa loaded at run time. Throws ContextError.
std::unique_ptr<HeadlessContext> createHeadlessContext(Backend backend, int width = 16,
                                                       int height = 16);

}  // namespace shrefract
