// A program as a GLSL 3.30 fragment shader, printed from its recording (vgpu/record.h): one
// statement per fragment-program instruction, texRECT fetches as texelFetch, every constant a
// uniform so a uniform change needs no recompilation. The GL device compiles this text; `vgpu-rt
// kernels NAME --glsl` shows it to a learner.
#pragma once

#include <string>
#include <vector>

#include "vgpu/program.h"

namespace vgpu {

struct GlslProgram {
  std::string source;            // the fragment shader
  std::vector<float> constants;  // the values of the uniform array k[]
  // Texture units the shader samples, and the sampler uniform bound to each.
  std::vector<int> units;
  std::vector<std::string> samplers;
  int statements = 0;  // instructions the shader kept (the dead ones are dropped)
};

// Prints a recording of program p. annotate: append each constant's value as a comment (for
// people; the device compiles the plain text, which does not change with the uniforms).
GlslProgram to_glsl(const Program& p, const Recording& rec, bool annotate = false);
inline GlslProgram to_glsl(const Program& p, bool annotate = false) {
  return to_glsl(p, p.record(), annotate);
}

// The vertex shader every pass uses: one triangle that covers the viewport.
const char* fullscreen_vertex_shader();

}  // namespace vgpu
