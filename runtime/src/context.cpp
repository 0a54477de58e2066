// The two headless backends. EGL headers stay in this file; GL calls go through gl.h.
#define EGL_NO_X11
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "gl.h"
#include "shrefract/context.h"

// From GL/osmesa.h, which pulls in GL/gl.h (prototypes we must not see): the few tokens used.
#define OSMESA_RGBA 0x1908
#define OSMESA_FORMAT 0x22
#define OSMESA_CONTEXT_MAJOR_VERSION 0x36
#define OSMESA_CONTEXT_MINOR_VERSION 0x37
#define OSMESA_PROFILE 0x33
#define OSMESA_CORE_PROFILE 0x34
#define OSMESA_DEPTH_BITS 0x30

namespace shrefract {

namespace {

// libOSMesa, opened RTLD_LOCAL at first use so its exported gl* symbols never shadow the
// application's libGL/libOpenGL.
struct OSMesaLib {
    using Context = void*;
    Context (*createContextAttribs)(const int*, Context) = nullptr;
    unsigned char (*makeCurrent)(Context, void*, unsigned, int, int) = nullptr;
    void (*destroyContext)(Context) = nullptr;
    Context (*getCurrentContext)() = nullptr;
    void* (*getProcAddress)(const char*) = nullptr;
    void* handle = nullptr;
    std::string error;

    static OSMesaLib& get(bool load) {
        static OSMesaLib lib;
        if (lib.handle || !load) return lib;
        for (const char* name : {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}) {
            lib.handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
            if (lib.handle) break;
        }
        if (!lib.handle) {
            lib.error = "libOSMesa not found (install libosmesa6; removed from Mesa >= 25.1)";
            return lib;
        }
        lib.createContextAttribs = reinterpret_cast<decltype(lib.createContextAttribs)>(
            dlsym(lib.handle, "OSMesaCreateContextAttribs"));
        lib.makeCurrent =
            reinterpret_cast<decltype(lib.makeCurrent)>(dlsym(lib.handle, "OSMesaMakeCurrent"));
        lib.destroyContext = reinterpret_cast<decltype(lib.destroyContext)>(
            dlsym(lib.handle, "OSMesaDestroyContext"));
        lib.getCurrentContext = reinterpret_cast<decltype(lib.getCurrentContext)>(
            dlsym(lib.handle, "OSMesaGetCurrentContext"));
        lib.getProcAddress = reinterpret_cast<decltype(lib.getProcAddress)>(
            dlsym(lib.handle, "OSMesaGetProcAddress"));
        if (!lib.createContextAttribs || !lib.makeCurrent || !lib.destroyContext ||
            !lib.getCurrentContext || !lib.getProcAddress)
            lib.error = "libOSMesa lacks OSMesaCreateContextAttribs (too old)";
        return lib;
    }
};

void* osmesaLoader(const char* name) { return OSMesaLib::get(true).getProcAddress(name); }
void* eglLoader(const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }

std::string describeCurrent(gl::Loader loader) {
    gl::ensureLoaded(loader);
    auto s = [](GLenum e) {
        const GLubyte* v = gl::glGetString(e);
        return v ? std::string(reinterpret_cast<const char*>(v)) : std::string("?");
    };
    return s(GL_RENDERER) + ", " + s(GL_VERSION);
}

// EGL without a window. Display: the first hardware EGL device (EGL_EXT_platform_device: NVIDIA's
// driver, Mesa on a GPU render node), else Mesa's surfaceless platform (llvmpipe when there is no
// GPU). Context: config-less (EGL_KHR_no_config_context), else from a pbuffer-capable config;
// made current without a surface either way (EGL_KHR_surfaceless_context).
class EglContext final : public HeadlessContext {
public:
    EglContext() {
        auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
            eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (!getPlatformDisplay)
            throw ContextError("EGL: eglGetPlatformDisplayEXT unavailable (no EGL_EXT_platform_base)");
        std::string tried;
        for (EGLDisplay d : hardwareDisplays(getPlatformDisplay)) {
            if (tryDisplay(d, &tried)) return;
        }
        EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d == EGL_NO_DISPLAY)
            throw ContextError("EGL: no GPU device and no surfaceless display (needs "
                               "EGL_EXT_platform_device or Mesa's EGL_MESA_platform_surfaceless); "
                               "error 0x" + hex(eglGetError()) + tried);
        if (!tryDisplay(d, &tried)) throw ContextError("EGL: no usable display" + tried);
    }
    ~EglContext() override {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        // The display is shared process-wide by Mesa; terminating it would kill other contexts.
    }
    void makeCurrent() override {
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            throw ContextError("EGL: eglMakeCurrent failed (EGL_KHR_surfaceless_context?)");
    }
    Backend backend() const override { return Backend::Egl; }
    void* (*loader() const)(const char*) override { return &eglLoader; }
    std::string description() const override { return describeCurrent(&eglLoader); }

private:
    // Displays of the EGL devices that are not Mesa's software rasterizer, in device order.
    static std::vector<EGLDisplay> hardwareDisplays(PFNEGLGETPLATFORMDISPLAYEXTPROC getDisplay) {
        auto queryDevices =
            reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto queryString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
            eglGetProcAddress("eglQueryDeviceStringEXT"));
        std::vector<EGLDisplay> out;
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (!queryDevices || !queryString || !queryDevices(16, devices, &count)) return out;
        for (EGLint i = 0; i < count; ++i) {
            const char* ext = queryString(devices[i], EGL_EXTENSIONS);
            if (ext && std::strstr(ext, "EGL_MESA_device_software")) continue;
            EGLDisplay d = getDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
            if (d != EGL_NO_DISPLAY) out.push_back(d);
        }
        return out;
    }

    // Initializes `d` and makes a 4.5 (else 3.3) core context current on it; on failure appends
    // the reason to `why` and leaves nothing behind.
    bool tryDisplay(EGLDisplay d, std::string* why) {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(d, &major, &minor)) {
            *why += "; eglInitialize: error 0x" + hex(eglGetError());
            return false;
        }
        if (!eglBindAPI(EGL_OPENGL_API)) {
            *why += "; desktop OpenGL API not available";
            return false;
        }
        EGLConfig config = EGL_NO_CONFIG_KHR;
        for (int attempt = 0; attempt < 2 && context_ == EGL_NO_CONTEXT; ++attempt) {
            if (attempt == 1) {  // no EGL_KHR_no_config_context: any desktop-GL config
                const EGLint want[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                       EGL_OPENGL_BIT, EGL_NONE};
                EGLint n = 0;
                if (!eglChooseConfig(d, want, &config, 1, &n) || n < 1) break;
            }
            for (int version : {45, 33}) {
                EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, version / 10,
                                    EGL_CONTEXT_MINOR_VERSION, version % 10,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
                context_ = eglCreateContext(d, config, EGL_NO_CONTEXT, attribs);
                if (context_ != EGL_NO_CONTEXT) break;
            }
        }
        if (context_ == EGL_NO_CONTEXT) {
            *why += "; cannot create a 3.3 core context: error 0x" + hex(eglGetError());
            return false;
        }
        display_ = d;
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
            *why += "; eglMakeCurrent without surface failed (EGL_KHR_surfaceless_context?)";
            eglDestroyContext(display_, context_);
            context_ = EGL_NO_CONTEXT;
            display_ = EGL_NO_DISPLAY;
            return false;
        }
        return true;
    }

    static std::string hex(EGLint v) {
        char b[16];
        std::snprintf(b, sizeof b, "%04x", static_cast<unsigned>(v));
        return b;
    }
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
};

class OSMesaContext final : public HeadlessContext {
public:
    OSMesaContext(int width, int height)
        : width_(std::max(1, width)), height_(std::max(1, height)),
          buffer_(static_cast<size_t>(width_) * height_) {
        OSMesaLib& lib = OSMesaLib::get(true);
        if (!lib.error.empty()) throw ContextError("OSMesa: " + lib.error);
        for (int version : {45, 33}) {
            int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24,
                             OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                             OSMESA_CONTEXT_MAJOR_VERSION, version / 10,
                             OSMESA_CONTEXT_MINOR_VERSION, version % 10, 0};
            context_ = lib.createContextAttribs(attribs, nullptr);
            if (context_) break;
        }
        if (!context_) throw ContextError("OSMesa: cannot create a 3.3 core profile context");
        makeCurrent();
    }
    ~OSMesaContext() override {
        OSMesaLib& lib = OSMesaLib::get(false);
        // Release first, so that OSMesaGetCurrentContext() no longer names a dead context.
        if (lib.getCurrentContext() == context_) lib.makeCurrent(nullptr, nullptr, 0, 0, 0);
        lib.destroyContext(context_);
    }
    void makeCurrent() override {
        if (!OSMesaLib::get(false).makeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE,
                                               width_, height_))
            throw ContextError("OSMesa: OSMesaMakeCurrent failed");
    }
    Backend backend() const override { return Backend::OSMesa; }
    void* (*loader() const)(const char*) override { return &osmesaLoader; }
    std::string description() const override { return describeCurrent(&osmesaLoader); }

private:
    int width_, height_;
    std::vector<uint32_t> buffer_;
    void* context_ = nullptr;
};

}  // namespace

std::unique_ptr<HeadlessContext> createHeadlessContext(Backend backend, int width, int height) {
    if (backend == Backend::OSMesa) return std::make_unique<OSMesaContext>(width, height);
    return std::make_unique<EglContext>();
}

namespace gl {
Loader currentContextLoader() {
    OSMesaLib& lib = OSMesaLib::get(false);
    if (lib.handle && lib.getCurrentContext && lib.getCurrentContext()) return &osmesaLoader;
    return &eglLoader;
}
}  // namespace gl

}  // namespace shrefract
