// The run-time registry of every kernel, made from the one list in kernels/kernel_list.h.
// `vgpu-rt kernels` lists and prints them (host/cli/commands.cpp), the report embeds their
// GLSL (host/report/report.cpp) and the GL device's tests compile each one (tests/gl). What each
// kernel is, and its paper name: kernels/README.md.
#pragma once

#include <memory>
#include <vector>

#include "kernels/kernels.h"
#include "vgpu/program.h"

namespace kernels {

// Which kernels a list holds.
enum class Programs {
  multipass,     // VGPU_MULTIPASS_KERNELS
  with_looping,  // VGPU_MULTIPASS_KERNELS, then VGPU_LOOPING_KERNELS
};

// Every kernel of the list as a program with its default uniforms, in the list's order.
inline std::vector<std::unique_ptr<vgpu::Program>> all_programs(
    Programs which = Programs::multipass) {
  std::vector<std::unique_ptr<vgpu::Program>> v;
#define VGPU_APPEND_PROGRAM(K, file) v.push_back(std::make_unique<vgpu::KernelProgram<K>>());
  VGPU_MULTIPASS_KERNELS(VGPU_APPEND_PROGRAM)
  if (which == Programs::with_looping) {
    VGPU_LOOPING_KERNELS(VGPU_APPEND_PROGRAM)
  }
#undef VGPU_APPEND_PROGRAM
  return v;
}

// Every kernel's C++ type name (the functor in namespace kernels), in all_programs's order with
// the looping ones: what the glossary's test checks kernels/README.md against.
inline std::vector<const char*> all_type_names() {
#define VGPU_TYPE_NAME(K, file) #K,
  return {VGPU_ALL_KERNELS(VGPU_TYPE_NAME)};
#undef VGPU_TYPE_NAME
}

}  // namespace kernels
