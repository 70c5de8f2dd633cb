// The GL device checked against the vgpu on the same hand-made texels: every kernel pass that a
// kernel test runs (tests/kernels/kernel_pass.h) is run again as a GL pass, and each output
// channel must match the vgpu's within the kernel's stated ulps, the query count exactly.
#pragma once

#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "gl/gl_device.h"
#include "vgpu/vgpu.h"

namespace gltest {

// One GL context for the whole test run (a context costs ~0.1 s on llvmpipe).
inline gl::GlDevice& device() {
  static gl::GlDevice d(vgpu::profile("gf5700"));
  return d;
}

// A second context whose profile has multiple render targets, for the fused programs.
inline gl::GlDevice& mrt_device() {
  static gl::GlDevice d(vgpu::profile("gf6600"));
  return d;
}

// Ulps each kernel's outputs may differ by, and why. Kernels made of +, -, *, compares, selects,
// floor and fetches must be bit-exact: IEEE fp32 gives one answer and the shader forbids fusing
// a*b+c (precise). Kernels that divide or take square roots get a few ulps: GLSL (4.60, sec.
// 4.7.1) allows 2.5 ulps for a / b and inherits sqrt's precision from inversesqrt (2 ulps), and
// the error propagates through the expressions after them (a normalised vector, a hit
// parameter t). llvmpipe computes both correctly rounded: measured 0 ulps on every kernel
// (VGPU_GL_ULPS=1 build/tests/test_gl prints the worst per kernel); these bounds are for
// drivers that use the approximations GLSL allows.
inline int ulps_allowed(const std::string& kernel) {
  static const std::map<std::string, int> allowed = {
      {"generate rays", 4},       // normalize: rsqrt, then three products
      {"init traversal", 4},      // slab entry t = (plane - o) / d
      {"reset traversal", 4},     // the same slab test
      {"traversal", 4},           // exit parameters (plane - o) / d
      {"intersections", 16},      // Moller-Trumbore: a reciprocal feeds u, v and t
      {"reflection origin", 16},  // barycentric interpolation through 1 / det
      {"reflection direction", 16},
      {"shader", 64},  // normalised normals, light vectors, a 32nd power of the specular term
      {"shadow rays", 4},
      {"intersections + next triangle", 16},  // as intersections
      {"traversal + update voxel", 4},        // as traversal
  };
  const auto it = allowed.find(kernel);
  return it == allowed.end() ? 0 : it->second;
}

// Distance in ulps between two floats (equal NaNs and +-0 count as 0).
inline uint64_t ulp_distance(float a, float b) {
  if (a == b || (std::isnan(a) && std::isnan(b))) return 0;
  if (std::isnan(a) || std::isnan(b)) return UINT64_MAX;
  auto ordered = [](float f) {
    const int64_t i = std::bit_cast<int32_t>(f);
    return i < 0 ? int64_t(INT32_MIN) - i : i;
  };
  const int64_t d = ordered(a) - ordered(b);
  return uint64_t(d < 0 ? -d : d);
}

// The most ulps seen per kernel in this run (reported by test_gl_device.cpp's last case).
inline std::map<std::string, uint64_t>& worst_ulps() {
  static std::map<std::string, uint64_t> w;
  return w;
}

// The pass of program p that the vgpu made (units bound in order, targets starting from
// `before`, ending as `vgpu_outs`), made again on the GL device and compared channel by channel.
inline void check_same_targets(const vgpu::Program& p,
                               const std::vector<const vgpu::Texture*>& units,
                               const std::vector<const vgpu::Texture*>& before,
                               const std::vector<const vgpu::Texture*>& vgpu_outs,
                               const uint64_t* vgpu_query) {
  gl::GlDevice& d = p.outputs() > 1 ? mrt_device() : device();
  std::vector<vgpu::Texture> outs;  // copies: new textures, created on the device from these texels
  outs.reserve(before.size());
  for (const vgpu::Texture* t : before) outs.push_back(*t);
  d.use_program(p);
  d.unbind_textures();
  for (size_t i = 0; i < units.size(); ++i) d.bind_texture(int(i), *units[i]);
  if (outs.size() == 1)
    d.set_targets({&outs[0]});
  else
    d.set_targets({&outs[0], &outs[1]});
  if (vgpu_query) d.begin_query();
  d.draw();
  const uint64_t n = vgpu_query ? d.end_query() : 0;
  const std::string name = p.name();
  const uint64_t allowed = uint64_t(ulps_allowed(name));
  uint64_t& worst = worst_ulps()[name];
  for (size_t o = 0; o < outs.size(); ++o) {
    vgpu::Texture& out = outs[o];
    d.download(out);
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < out.channels(); ++c) {
          const float g = out.get(x, y, c), v = vgpu_outs[o]->get(x, y, c);
          const uint64_t u = ulp_distance(g, v);
          worst = std::max(worst, u);
          if (u > allowed) {
            INFO("GL device against vgpu: program '"
                 << name << "' target " << o << " texel (" << x << ", " << y << ") channel " << c
                 << ": GL " << g << ", vgpu " << v << ", " << u << " ulps (allowed " << allowed
                 << ")");
            CHECK(u <= allowed);
          }
        }
  }
  if (vgpu_query) {
    INFO("GL device against vgpu: program '" << name << "' occlusion query");
    CHECK(n == *vgpu_query);
  }
}

inline void check_same_pass(const vgpu::Program& p, const std::vector<const vgpu::Texture*>& units,
                            const vgpu::Texture& before, const vgpu::Texture& vgpu_out,
                            const uint64_t* vgpu_query) {
  check_same_targets(p, units, {&before}, {&vgpu_out}, vgpu_query);
}

}  // namespace gltest
