// vgpu-rt's listing commands (commands.cpp): `scenes`, `kernels` and `gl-devices`. Each prints to
// stdout and returns the exit status; a usage error throws cli::UsageError.
#pragma once

#include <string>
#include <vector>

namespace cli {

// `vgpu-rt scenes [FILE...]`: the bundled scenes (none named) or the glTF files named, one line
// each: triangles, path and animations (index, name, key times and duration), and what
// `render --time/--frames` plays by default (every animation together, or the first alone when
// two drive the same path of one node). A file that cannot be read is listed as unreadable.
int run_scenes(const std::vector<std::string>& files);

// `vgpu-rt kernels [NAME] [--glsl]`: every kernel's outputs, instructions, branches and fetches,
// or one kernel's (its GLSL with `glsl`).
int run_kernels(const std::string& name, bool glsl);
// `vgpu-rt gl-devices`: the EGL devices, or a runtime_error in a build without GL.
int run_gl_devices();

}  // namespace cli
