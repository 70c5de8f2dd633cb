// vgpu-rt's listing commands: `kernels` (each fragment program's outputs, instructions, branches
// and fetches per unit, or its generated GLSL) and `gl-devices` (the EGL devices --gl-device
// can name).
#include "host/cli/commands.h"

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "host/cli/options.h"
#include "kernels/registry.h"
#include "vgpu/glsl.h"
#include "vgpu/vgpu.h"
#ifdef VGPU_HAVE_GL
#include "gl/context.h"
#endif

namespace cli {

// `vgpu-rt kernels [NAME] [--glsl]`: what a fragment program is, per kernel.
int run_kernels(const std::string& name, bool glsl) {
  // Every kernel of the one list (kernels/registry.h), the looping variant's last.
  const auto programs = kernels::all_programs(kernels::Programs::with_looping);
  auto spelled = [](std::string n) {
    for (char& c : n)
      if (c == ' ') c = '-';
    return n;
  };
  if (name.empty()) {
    if (glsl) throw UsageError("kernels --glsl: name a kernel (vgpu-rt kernels lists them)");
    std::printf("%-22s %-22s %7s %7s %8s  %s\n", "kernel", "paper name", "outputs", "instr.",
                "branches", "textures (unit: contents, fetches per fragment)");
    for (const auto& p : programs) {
      const vgpu::Program::Analysis a = p->analyze();
      std::string units;
      for (int u = 0; u < vgpu::kMaxTextureUnits; ++u)
        if (a.fetches.per_unit[u])
          units += (units.empty() ? "" : ", ") + std::to_string(u) + ": " + p->unit_name(u) +
                   (a.fetches.per_unit[u] > 1 ? " x" + std::to_string(a.fetches.per_unit[u]) : "");
      std::printf("%-22s %-22s %7d %7d %8d  %s\n", spelled(p->name()).c_str(), p->paper_name(),
                  p->outputs(), a.instructions, a.branches, units.empty() ? "-" : units.c_str());
    }
    std::printf(
        "instructions: one per arithmetic, compare, select and fetch, every branch taken (the "
        "counting run); default uniforms\n");
    return 0;
  }
  for (const auto& p : programs) {
    if (name != p->name() && name != spelled(p->name()) && name != p->paper_name()) continue;
    if (glsl) {
      std::fputs(vgpu::to_glsl(*p, true).source.c_str(), stdout);
    } else {
      const vgpu::Program::Analysis a = p->analyze();
      std::printf("%s (paper: %s): %d output(s), %d instructions, %d branch block(s)\n", p->name(),
                  p->paper_name(), p->outputs(), a.instructions, a.branches);
      for (int u = 0; u < vgpu::kMaxTextureUnits; ++u)
        if (a.fetches.per_unit[u])
          std::printf("  unit %2d  %-16s %d fetch(es) per fragment\n", u, p->unit_name(u).c_str(),
                      a.fetches.per_unit[u]);
    }
    return 0;
  }
  throw UsageError("kernels: no kernel named '" + name + "' (vgpu-rt kernels lists them)");
}

int run_gl_devices() {
#ifdef VGPU_HAVE_GL
  const auto devices = gl::Context::list_devices();
  if (devices.empty()) std::printf("EGL lists no devices (auto uses the surfaceless platform)\n");
  for (const auto& d : devices)
    std::printf("%d  %s%s\n", d.index, d.name.c_str(), d.software ? " (software)" : "");
  return 0;
#else
  throw std::runtime_error("gl-devices: this build has no GL device (EGL was not found)");
#endif
}

}  // namespace cli
