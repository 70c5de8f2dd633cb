// vgpu-rt's listing commands: `scenes` (the bundled scenes or named files, with their
// animations), `kernels` (each fragment program's outputs, instructions, branches and fetches
// per unit, or its generated GLSL) and `gl-devices` (the EGL devices --gl-device can name).
#include "host/cli/commands.h"

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/cli/options.h"
#include "host/scene/animation.h"
#include "host/scene/gltf_loader.h"
#include "kernels/registry.h"
#include "vgpu/glsl.h"
#include "vgpu/vgpu.h"
#ifdef VGPU_HAVE_GL
#include "gl/context.h"
#endif

namespace cli {

int run_scenes(const std::vector<std::string>& files) {
  std::vector<std::pair<std::string, std::string>> listed;  // (name, path)
  if (files.empty()) listed = host::list_scenes();
  for (const std::string& f : files) listed.emplace_back(f, f);
  for (const auto& [name, path] : listed) {
    const int width = files.empty() ? 14 : 0;  // bundled names in a column
    try {
      // The listing counts triangles: images are not decoded (loading the image module would
      // take the listing from 0.1 s to 1 s), each stands as one white texel.
      host::LoadOptions listing;
      listing.read_image = [](const std::vector<unsigned char>&) {
        return host::ImagePixels{1, 1, 3, {1.0f, 1.0f, 1.0f}};
      };
      const host::AnimatedScene s(path, listing);
      std::string animations;
      const std::vector<host::Animation>& list = s.animations();
      for (size_t i = 0; i < list.size(); ++i) {
        char range[96];
        std::snprintf(range, sizeof range, " %g-%g s (%g s)", list[i].start, list[i].end,
                      list[i].end - list[i].start);
        animations +=
            (i ? ", " : "  animations: ") + std::to_string(i) + " '" + list[i].name + "'" + range;
      }
      if (list.size() > 1) {
        const std::string clash = s.clash(s.all());
        animations += clash.empty() ? "; all play together by default"
                                    : "; " + clash + ": the first plays alone by default";
      }
      if (files.empty())
        std::printf("%-*s %7zu triangles  %s%s\n", width, name.c_str(), s.rest().triangle_count(),
                    path.c_str(), animations.c_str());
      else
        std::printf("%s: %zu triangles%s\n", path.c_str(), s.rest().triangle_count(),
                    animations.c_str());
    } catch (const std::exception& e) {
      std::printf("%-*s (unreadable: %s)\n", width, name.c_str(), e.what());
    }
  }
  return 0;
}

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
