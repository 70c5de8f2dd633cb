// A headless OpenGL 3.3 core context through EGL: no window, no X server. On NVIDIA the EGL
// device platform (one display per GPU), on Mesa the device platform's software device or the
// surfaceless platform (llvmpipe). Throws gl::Unavailable naming what is missing.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace gl {

struct Unavailable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct EglDeviceInfo {
  int index = 0;
  std::string name;  // EGL_DRM_DEVICE_FILE_EXT or the device's extension summary
  bool software = false;
};

class Context {
 public:
  // device: "auto" (the first hardware EGL device, else software/surfaceless) or an index
  // into list_devices().
  explicit Context(const std::string& device = "auto");
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& version() const { return version_; }    // GL_VERSION
  const std::string& platform() const { return platform_; }  // how the display was opened
  // A software renderer (Mesa's software device or the surfaceless platform: llvmpipe).
  bool software() const { return software_; }
  // Makes this context current on the calling thread if it is not (several devices in one
  // process each have their own context).
  void make_current() const;

  static std::vector<EglDeviceInfo> list_devices();

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;
  std::string renderer_, version_, platform_;
  bool software_ = false;
};

}  // namespace gl
