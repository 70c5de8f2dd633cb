// EGL display, config, context and a 1x1 pbuffer; everything else renders into textures.
#include "gl/context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <map>
#include <sstream>

#include "gl/gl.h"

namespace gl {

namespace {

std::string egl_error() {
  char b[32];
  std::snprintf(b, sizeof b, "EGL error 0x%04x", unsigned(eglGetError()));
  return b;
}

bool has_word(const char* list, const char* word) {
  if (!list) return false;
  std::istringstream in(list);
  std::string w;
  while (in >> w)
    if (w == word) return true;
  return false;
}

struct DeviceEnum {
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_string = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC platform_display = nullptr;
  std::vector<EGLDeviceEXT> devices;

  DeviceEnum() {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!has_word(client, "EGL_EXT_device_enumeration") && !has_word(client, "EGL_EXT_device_base"))
      return;
    query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    query_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
        eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (!query_devices) return;
    EGLint n = 0;
    if (!query_devices(0, nullptr, &n) || n <= 0) return;
    devices.resize(size_t(n));
    query_devices(n, devices.data(), &n);
    devices.resize(size_t(n));
  }
  EglDeviceInfo info(int i) const {
    EglDeviceInfo d;
    d.index = i;
    const char* ext = query_string ? query_string(devices[size_t(i)], EGL_EXTENSIONS) : nullptr;
    d.software = has_word(ext, "EGL_MESA_device_software");
    const char* file = has_word(ext, "EGL_EXT_device_drm") && query_string
                           ? query_string(devices[size_t(i)], EGL_DRM_DEVICE_FILE_EXT)
                           : nullptr;
    d.name = file ? file : d.software ? "software (Mesa)" : "EGL device";
    return d;
  }
};

// EGL hands out one display per device and process: every Context on it shares it, so it is
// terminated only when the last one lets it go.
std::map<EGLDisplay, int>& display_users() {
  static std::map<EGLDisplay, int> users;
  return users;
}
void release_display(EGLDisplay d) {
  auto it = display_users().find(d);
  if (it != display_users().end() && --it->second > 0) return;
  if (it != display_users().end()) display_users().erase(it);
  eglTerminate(d);
}

}  // namespace

std::vector<EglDeviceInfo> Context::list_devices() {
  DeviceEnum e;
  std::vector<EglDeviceInfo> out;
  for (int i = 0; i < int(e.devices.size()); ++i) out.push_back(e.info(i));
  return out;
}

Context::Context(const std::string& device) {
  DeviceEnum e;
  // Candidate displays in order of preference.
  struct Candidate {
    EGLDisplay display;
    std::string how;
    bool software = false;
  };
  std::vector<Candidate> candidates;
  std::string tried;
  if (device != "auto") {
    char* end = nullptr;
    const long idx = std::strtol(device.c_str(), &end, 10);
    if (device.empty() || *end != '\0' || idx < 0)
      throw Unavailable("--gl-device: expected auto or a device index, got '" + device + "'");
    if (e.devices.empty() || !e.platform_display)
      throw Unavailable("--gl-device " + device +
                        ": EGL cannot enumerate devices here (no EGL_EXT_device_enumeration)");
    if (idx >= long(e.devices.size()))
      throw Unavailable("--gl-device " + device + ": EGL lists " +
                        std::to_string(e.devices.size()) + " device(s) (0.." +
                        std::to_string(e.devices.size() - 1) + ")");
    candidates.push_back(
        {e.platform_display(EGL_PLATFORM_DEVICE_EXT, e.devices[size_t(idx)], nullptr),
         "EGL device " + device + " (" + e.info(int(idx)).name + ")", e.info(int(idx)).software});
  } else {
    if (e.platform_display) {
      // Hardware devices first, then software ones.
      for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < int(e.devices.size()); ++i) {
          const EglDeviceInfo d = e.info(i);
          if (d.software != (pass == 1)) continue;
          candidates.push_back(
              {e.platform_display(EGL_PLATFORM_DEVICE_EXT, e.devices[size_t(i)], nullptr),
               "EGL device " + std::to_string(i) + " (" + d.name + ")", d.software});
        }
      const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
      if (has_word(client, "EGL_MESA_platform_surfaceless"))
        candidates.push_back(
            {e.platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
             "EGL surfaceless platform", true});
    }
  }
  if (candidates.empty())
    throw Unavailable(
        "no EGL display: EGL offers neither device enumeration nor the surfaceless platform");

  for (const Candidate& c : candidates) {
    auto note = [&](const std::string& why) {
      tried += (tried.empty() ? "" : "; ") + c.how + ": " + why;
    };
    if (c.display == EGL_NO_DISPLAY) {
      note("no display (" + egl_error() + ")");
      continue;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(c.display, &major, &minor)) {
      note("eglInitialize failed (" + egl_error() + ")");
      continue;
    }
    ++display_users()[c.display];
    if (!eglBindAPI(EGL_OPENGL_API)) {
      note("no desktop OpenGL API");
      release_display(c.display);
      continue;
    }
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE,
                                     EGL_PBUFFER_BIT,
                                     EGL_RENDERABLE_TYPE,
                                     EGL_OPENGL_BIT,
                                     EGL_RED_SIZE,
                                     8,
                                     EGL_GREEN_SIZE,
                                     8,
                                     EGL_BLUE_SIZE,
                                     8,
                                     EGL_NONE};
    EGLConfig config = nullptr;
    EGLint nconfig = 0;
    if (!eglChooseConfig(c.display, config_attribs, &config, 1, &nconfig) || nconfig < 1) {
      note("no EGL config with a pbuffer and OpenGL");
      release_display(c.display);
      continue;
    }
    const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                  3,
                                  EGL_CONTEXT_MINOR_VERSION,
                                  3,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                  EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                  EGL_NONE};
    EGLContext ctx = eglCreateContext(c.display, config, EGL_NO_CONTEXT, ctx_attribs);
    if (ctx == EGL_NO_CONTEXT) {
      note("no OpenGL 3.3 core context (" + egl_error() + ")");
      release_display(c.display);
      continue;
    }
    const EGLint pb_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    EGLSurface surf = eglCreatePbufferSurface(c.display, config, pb_attribs);
    // A candidate that fails after its context exists gives everything back.
    auto drop = [&](const std::string& why) {
      note(why);
      eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (surf != EGL_NO_SURFACE) eglDestroySurface(c.display, surf);
      eglDestroyContext(c.display, ctx);
      release_display(c.display);
    };
    if (!eglMakeCurrent(c.display, surf, surf, ctx)) {
      drop("eglMakeCurrent failed (" + egl_error() + ")");
      continue;
    }
    GLint gl_major = 0, gl_minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &gl_major);
    glGetIntegerv(GL_MINOR_VERSION, &gl_minor);
    if (gl_major * 10 + gl_minor < 33) {
      drop("OpenGL " + std::to_string(gl_major) + "." + std::to_string(gl_minor) + " (3.3 needed)");
      continue;
    }
    display_ = c.display;
    context_ = ctx;
    surface_ = surf;
    platform_ = c.how;
    software_ = c.software;
    renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    version_ = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return;
  }
  throw Unavailable("no usable OpenGL 3.3 device: " + tried);
}

Context::~Context() {
  if (!display_) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
  eglDestroyContext(display_, context_);
  release_display(display_);
}

void Context::make_current() const {
  if (eglGetCurrentContext() == context_) return;
  if (!eglMakeCurrent(display_, surface_, surface_, context_))
    throw Unavailable("cannot make the GL context current (" + egl_error() + ")");
}

}  // namespace gl
