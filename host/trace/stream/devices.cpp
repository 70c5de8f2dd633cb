// Device construction by name.
#include "host/trace/stream/devices.h"

#include "host/model/formats.h"
#include "host/trace/render_options.h"
#include "vgpu/gpu.h"
#ifdef VGPU_HAVE_GL
#include "gl/gl_device.h"
#endif

namespace host {

bool have_gl_device() {
#ifdef VGPU_HAVE_GL
  return true;
#else
  return false;
#endif
}

std::unique_ptr<vgpu::Device> make_device(const RenderOptions& opt) {
  const vgpu::Profile& profile = vgpu::profile(opt.profile);
  if (opt.device == "vgpu") {
    auto gpu = std::make_unique<vgpu::Gpu>(profile, opt.threads, opt.lanes);
    gpu->set_precision(opt.formats.finest());
    gpu->set_recorded(opt.recorded_programs);
    gpu->set_stop_when(opt.stop_when);
    return gpu;
  }
  if (opt.device == "gl") {
#ifdef VGPU_HAVE_GL
    bool fp32 = true;
    for (const host::Group g : host::kGroups)
      fp32 = fp32 && opt.formats.arithmetic(g) == vgpu::Format::fp32;
    if (!fp32)
      throw vgpu::Error(
          "the GL device computes in fp32 only (GLSL floats); use --engine stream for --precision "
          "fp24/fp16");
    using Wait = gl::GlDevice::ReadbackWait;
    const Wait wait = opt.gl_readback == "auto"    ? Wait::automatic
                      : opt.gl_readback == "block" ? Wait::block
                      : opt.gl_readback == "poll"
                          ? Wait::poll
                          : throw vgpu::Error("unknown GL read-back wait '" + opt.gl_readback +
                                              "' (known: auto, block, poll)");
    return std::make_unique<gl::GlDevice>(profile, opt.gl_device, wait);
#else
    throw vgpu::Error(
        "this build has no GL device: EGL and OpenGL (libegl-dev, libopengl-dev, libgl-dev) were "
        "not found when it was built");
#endif
  }
  throw vgpu::Error("unknown device '" + opt.device + "' (known: vgpu, gl)");
}

}  // namespace host
