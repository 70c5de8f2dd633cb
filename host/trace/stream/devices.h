// The devices the stream tracer can drive, by name: the virtual GPU ("vgpu") and, where the
// build found EGL, the GL device ("gl": the same passes on a real OpenGL driver).
#pragma once

#include <memory>
#include <string>

#include "vgpu/device.h"

namespace host {

struct RenderOptions;

// Whether this build has the GL device (EGL and OpenGL were found when it was built).
bool have_gl_device();

// The device opt.device names, for opt.profile. Throws vgpu::Error (or gl::Unavailable, a
// std::runtime_error) naming what is missing.
std::unique_ptr<vgpu::Device> make_device(const RenderOptions& opt);

}  // namespace host
