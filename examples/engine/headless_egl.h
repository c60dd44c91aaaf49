// An initialised EGL display for rendering with no window system, shared by
// the engine example and the tests' GL helper (tests/gl_context.cpp). Mesa
// offers its surfaceless platform (llvmpipe on the CPU, or a GPU through
// Mesa's drivers); NVIDIA's driver offers GPUs as EGL devices
// (EGL_EXT_platform_device). The first that initialises is taken, in that
// order; EGL_NO_DISPLAY if neither does.
#ifndef SKYBAKE_EXAMPLES_ENGINE_HEADLESS_EGL_H_
#define SKYBAKE_EXAMPLES_ENGINE_HEADLESS_EGL_H_

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>

namespace skybake {

inline EGLDisplay HeadlessEglDisplay() {
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) return EGL_NO_DISPLAY;
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto offers = [&](const char* name) { return client_extensions && std::strstr(client_extensions, name); };
  auto initialised = [](EGLDisplay display) {
    EGLint major = 0, minor = 0;
    return display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor);
  };
  if (offers("EGL_MESA_platform_surfaceless")) {
    EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (initialised(display)) return display;
  }
  if (offers("EGL_EXT_platform_device")) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (query_devices && query_devices(8, devices, &count)) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (initialised(display)) return display;
      }
    }
  }
  return EGL_NO_DISPLAY;
}

}  // namespace skybake

#endif  // SKYBAKE_EXAMPLES_ENGINE_HEADLESS_EGL_H_
