// vgpu-rt's listing commands (commands.cpp): `kernels` and `gl-devices`. Each prints to stdout
// and returns the exit status; a usage error throws cli::UsageError.
#pragma once

#include <string>

namespace cli {

// `vgpu-rt kernels [NAME] [--glsl]`: every kernel's outputs, instructions, branches and fetches,
// or one kernel's (its GLSL with `glsl`).
int run_kernels(const std::string& name, bool glsl);
// `vgpu-rt gl-devices`: the EGL devices, or a runtime_error in a build without GL.
int run_gl_devices();

}  // namespace cli
