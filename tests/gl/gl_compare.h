// The GL device checked against the vgpu on the same hand-made texels: every kernel pass that a
// kernel test runs (tests/kernels/kernel_pass.h, tests/kernels/test_looping_traversal.cpp) is
// run again as a GL pass, and each output channel must match the vgpu's within the kernel's
// stated ulps, the query count exactly. And whole frames: check_same_frame.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>
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

// A second context whose profile has multiple render targets and loops, for the fused and the
// looping programs.
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
      {"looping traversal", 16},              // intersections and traversal in one loop
      {"bvh intersections", 16},              // as intersections
      {"bvh intersections + next triangle", 16},
      {"bvh looping traversal", 16},  // intersections and the box test in one loop
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
  gl::GlDevice& d = p.outputs() > 1 || p.analyze().loop.loops > 0 ? mrt_device() : device();
  std::vector<vgpu::Texture> outs;  // copies: new textures, created on the device from these texels
  outs.reserve(before.size());
  for (const vgpu::Texture* t : before) outs.push_back(*t);
  d.use_program(p);
  d.unbind_textures();
  for (size_t i = 0; i < units.size(); ++i) d.bind_texture(int(i), *units[i]);
  switch (outs.size()) {
    case 1:
      d.set_targets({&outs[0]});
      break;
    case 2:
      d.set_targets({&outs[0], &outs[1]});
      break;
    case 3:  // the looping program: traversal, voxel state and intersection
      d.set_targets({&outs[0], &outs[1], &outs[2]});
      break;
    default:
      FAIL("check_same_targets binds 1 to 3 targets, not " << outs.size());
  }
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

// A whole frame of one scene from the vgpu and from the GL device (`device`, its description):
// the primary hits' triangle ids and depths (RenderResult::hit_id, ::depth) and the image.
// llvmpipe computes every kernel correctly rounded, as the vgpu does (0 ulps measured on every
// kernel, see ulps_allowed), so there all three must be equal bit for bit: one differing texel
// in any pass of the frame shows up as a differing hit id, depth or colour. Another driver may
// use the approximations GLSL allows within each kernel's stated ulps, and those bounds forbid
// requiring equality there: `depth_kernel` (intersections: 16 ulps) may move a hit parameter t,
// which changes the depth and, for a ray through a shared edge or two hits a few ulps apart,
// the triangle hit; the shader (64 ulps) changes colours. There hit ids may differ on 0.1% of
// the pixels, depths where the hit ids agree by depth_kernel's ulps, and colours to a PSNR of
// 60 dB.
inline void check_same_frame(const std::string& device, const std::string& depth_kernel,
                             const std::vector<float>& vgpu_hit, const std::vector<float>& gl_hit,
                             const std::vector<float>& vgpu_depth,
                             const std::vector<float>& gl_depth, const std::vector<float>& vgpu_rgb,
                             const std::vector<float>& gl_rgb) {
  const size_t n = vgpu_hit.size();
  REQUIRE(n > 0);
  REQUIRE(gl_hit.size() == n);
  REQUIRE(vgpu_depth.size() == n);
  REQUIRE(gl_depth.size() == n);
  REQUIRE(vgpu_rgb.size() == 3 * n);
  REQUIRE(gl_rgb.size() == 3 * n);
  const bool exact = device.find("llvmpipe") != std::string::npos;
  size_t hits = 0, depths = 0, colours = 0, first = n;
  uint64_t depth_ulps = 0, colour_ulps = 0;
  double sq = 0;
  for (size_t i = 0; i < n; ++i) {
    if (vgpu_hit[i] != gl_hit[i]) {
      ++hits;
      first = std::min(first, i);
      continue;
    }
    const uint64_t u = ulp_distance(vgpu_depth[i], gl_depth[i]);
    depth_ulps = std::max(depth_ulps, u);
    depths += u > 0;
    if (u > 0) first = std::min(first, i);
  }
  for (size_t i = 0; i < 3 * n; ++i) {
    const uint64_t u = ulp_distance(vgpu_rgb[i], gl_rgb[i]);
    colour_ulps = std::max(colour_ulps, u);
    colours += u > 0;
    if (u > 0) first = std::min(first, i / 3);
    const double d = double(vgpu_rgb[i]) - double(gl_rgb[i]);
    sq += d * d;
  }
  const double mse = sq / double(3 * n);
  const double psnr = mse == 0 ? INFINITY : 10 * std::log10(1.0 / mse);
  MESSAGE("GL device (" << device << ") against vgpu, " << n << " pixels: " << hits << " hit ids, "
                        << depths << " depths (worst " << depth_ulps << " ulps) and " << colours
                        << " colour channels (worst " << colour_ulps << " ulps, PSNR " << psnr
                        << " dB) differ");
  std::ostringstream where;
  if (first < n)
    where << "first differing pixel " << first << ": hit id vgpu " << vgpu_hit[first] << ", GL "
          << gl_hit[first] << "; depth vgpu " << vgpu_depth[first] << ", GL " << gl_depth[first]
          << "; red vgpu " << vgpu_rgb[3 * first] << ", GL " << gl_rgb[3 * first];
  const std::string where_text = where.str();
  INFO(where_text);
  if (exact) {
    CHECK(hits == 0);
    CHECK(depths == 0);
    CHECK(colours == 0);
  } else {
    CHECK(hits * 1000 <= n);
    CHECK(depth_ulps <= uint64_t(ulps_allowed(depth_kernel)));
    CHECK(psnr >= 60.0);
  }
}

inline void check_same_pass(const vgpu::Program& p, const std::vector<const vgpu::Texture*>& units,
                            const vgpu::Texture& before, const vgpu::Texture& vgpu_out,
                            const uint64_t* vgpu_query) {
  check_same_targets(p, units, {&before}, {&vgpu_out}, vgpu_query);
}

}  // namespace gltest
