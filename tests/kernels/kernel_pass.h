// Helpers shared by the kernel tests: hand-made textures, one kernel pass through a real
// vgpu::Gpu (profile gf5700), and per-channel texel checks. Expected values always come from the
// test itself, never from the kernels' own helpers. Linked into test_gl too, where gl_check() is
// set: there every pass that run() makes on the vgpu is made again on the GL device, from the
// same texels, and its outputs and query count are checked against the vgpu's
// (tests/gl/gl_compare.h).
#pragma once

#include <doctest/doctest.h>

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <string>
#include <vector>

#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace ktest {

using vgpu::Texture;

// The GL comparison, switched on at run time. The kernel tests are compiled once and linked into
// two executables: test_kernels runs them on the vgpu alone (gl_check() stays null), test_gl
// links tests/gl/kernel_gl_check.cpp, which sets it to gltest::check_same_targets before any
// test runs: the pass of program p that the vgpu made (units bound in order, targets starting
// from `before` and ending as `outs`, the query count if any) is made again on the GL device and
// compared channel by channel.
using GlCheck = void (*)(const vgpu::Program& p, const std::vector<const Texture*>& units,
                         const std::vector<const Texture*>& before,
                         const std::vector<const Texture*>& outs, const uint64_t* query);
inline GlCheck& gl_check() {
  static GlCheck check = nullptr;
  return check;
}

// Copies of a pass's targets as they were before it, kept only where the GL device will redo the
// pass from them.
inline std::vector<Texture> before_pass(std::initializer_list<const Texture*> targets) {
  std::vector<Texture> copies;
  if (gl_check())
    for (const Texture* t : targets) copies.push_back(*t);
  return copies;
}

// The GL device's check of a pass of p on the vgpu (see gl_check), where it is switched on.
inline void check_on_gl(const vgpu::Program& p, const std::vector<const Texture*>& units,
                        const std::vector<Texture>& before, const std::vector<const Texture*>& outs,
                        const uint64_t* query) {
  if (!gl_check()) return;
  std::vector<const Texture*> from;
  for (const Texture& t : before) from.push_back(&t);
  gl_check()(p, units, from, outs, query);
}

inline const vgpu::Profile& gf5700() {
  return vgpu::profile("gf5700");
}

// A w x h texture of 4-channel texels, row-major (texel (x, y) = values[y * w + x]); texels past
// the list are zero.
inline Texture texels(std::string name, int w, int h, const std::vector<glm::vec4>& values) {
  Texture t(std::move(name), w, h, 4);
  for (size_t i = 0; i < values.size(); ++i)
    for (int c = 0; c < 4; ++c) t.set(int(i % size_t(w)), int(i / size_t(w)), c, values[i][c]);
  return t;
}

// The same with 1-channel texels (triangle lists, voxel pointers).
inline Texture scalars(std::string name, int w, int h, const std::vector<float>& values) {
  Texture t(std::move(name), w, h, 1);
  for (size_t i = 0; i < values.size(); ++i)
    t.set(int(i % size_t(w)), int(i / size_t(w)), 0, values[i]);
  return t;
}

// A texture holding one 3-vector per entry in xyz (vertex and normal textures), w texels wide.
inline Texture vec3s(std::string name, int w, int h, const std::vector<glm::vec3>& values) {
  Texture t(std::move(name), w, h, 3);
  for (size_t i = 0; i < values.size(); ++i)
    for (int c = 0; c < 3; ++c) t.set(int(i % size_t(w)), int(i / size_t(w)), c, values[i][c]);
  return t;
}

inline glm::vec4 at(const Texture& t, int x, int y) {
  glm::vec4 v(0.0f, 0.0f, 0.0f, 1.0f);
  for (int c = 0; c < t.channels(); ++c) v[c] = t.get(x, y, c);
  return v;
}

// One pass of program p: units[i] bound to texture unit i, rendering into target (whatever the
// target held is kept where fragments are discarded). With `query`, the pass runs inside an
// occlusion query and its count is stored there.
inline vgpu::PassRecord draw(vgpu::Device& gpu, const vgpu::Program& p,
                             const std::vector<const Texture*>& units, Texture& target,
                             uint64_t* query = nullptr) {
  gpu.use_program(p);
  gpu.unbind_textures();
  for (size_t i = 0; i < units.size(); ++i) gpu.bind_texture(int(i), *units[i]);
  gpu.set_targets({&target});
  if (query) gpu.begin_query();
  vgpu::PassRecord rec = gpu.draw();
  if (query) *query = gpu.end_query();
  return rec;
}

// One pass of kernel k over a fresh w x h target of 4 channels, cleared to `fill`.
template <class K>
Texture run(vgpu::Device& gpu, const K& k, const std::vector<const Texture*>& units, int w, int h,
            glm::vec4 fill = glm::vec4(0.0f), uint64_t* query = nullptr,
            vgpu::PassRecord* record = nullptr) {
  vgpu::KernelProgram<K> program(k);
  // Built in place, not by operator+ (GCC 12 warns, wrongly, of a bounds overflow there).
  std::string name(K::name);
  name.append(" out");
  Texture out = gpu.make_texture(name, w, h, 4);
  const float f[4] = {fill.x, fill.y, fill.z, fill.w};
  out.fill(f);
  const std::vector<Texture> before = before_pass({&out});  // the GL pass starts from these
  const vgpu::PassRecord rec = draw(gpu, program, units, out, query);
  gpu.download(out);
  if (record) *record = rec;
  // The GL device computes in fp32 (GLSL floats): compared where the vgpu does too.
  auto* vgpu_gpu = dynamic_cast<vgpu::Gpu*>(&gpu);
  bool fp32 = vgpu_gpu && vgpu_gpu->precision() == vgpu::Format::fp32 &&
              program.precision() == vgpu::Format::fp32 && out.format() == vgpu::Format::fp32;
  for (const Texture* t : units) fp32 = fp32 && t->format() == vgpu::Format::fp32;
  if (fp32) check_on_gl(program, units, before, {&out}, query);
  return out;
}

template <class K>
Texture run(const K& k, const std::vector<const Texture*>& units, int w, int h,
            glm::vec4 fill = glm::vec4(0.0f), uint64_t* query = nullptr) {
  vgpu::Gpu gpu(gf5700(), 1, 1);
  return run(gpu, k, units, w, h, fill, query);
}

// A profile with multiple render targets, for the fused programs (kernels/fused.h).
inline const vgpu::Profile& gf6600() {
  return vgpu::profile("gf6600");
}

// One pass of a kernel k of several outputs (K::outputs targets: 2 or 3) through a gf6600 vgpu,
// over fresh w x h targets of 4 channels, target i cleared to fills[i]. Compared on the GL device
// like run().
template <class K>
std::array<Texture, K::outputs> run_targets(const K& k, const std::vector<const Texture*>& units,
                                            int w, int h,
                                            const std::array<glm::vec4, K::outputs>& fills = {}) {
  vgpu::Gpu gpu(gf6600(), 1, 1);
  vgpu::KernelProgram<K> program(k);
  std::array<Texture, K::outputs> outs;
  for (int i = 0; i < K::outputs; ++i) {
    // Built in place: g++ 12 at -O1 warns (-Warray-bounds, a false positive) on the temporaries
    // of name + " out" + number.
    std::string name(K::name);
    name.append(" out").append(std::to_string(i));
    outs[size_t(i)] = gpu.make_texture(name, w, h, 4);
    const glm::vec4& v = fills[size_t(i)];
    const float f[4] = {v.x, v.y, v.z, v.w};
    outs[size_t(i)].fill(f);
  }
  static_assert(K::outputs == 2 || K::outputs == 3, "run_targets binds two or three targets");
  auto targets = [&](auto&& use) {
    if constexpr (K::outputs == 2)
      return use({&outs[0], &outs[1]});
    else
      return use({&outs[0], &outs[1], &outs[2]});
  };
  const std::vector<Texture> before =
      targets([](std::initializer_list<const Texture*> t) { return before_pass(t); });
  gpu.use_program(program);
  gpu.unbind_textures();
  for (size_t i = 0; i < units.size(); ++i) gpu.bind_texture(int(i), *units[i]);
  targets([&](std::initializer_list<Texture*> t) { gpu.set_targets(t); });
  gpu.draw();
  targets([&](std::initializer_list<const Texture*> t) {
    check_on_gl(program, units, before, t, nullptr);
  });
  return outs;
}

// A grid uniform block: box corner lo, voxel size cell, res voxels per axis.
inline kernels::GridUniforms grid_uniforms(glm::vec3 lo, glm::vec3 cell, glm::vec3 res,
                                           float list_width = 1, float t_slack = 0) {
  kernels::GridUniforms g;
  g.lo = lo;
  g.cell = cell;
  g.res = res;
  g.list_width = list_width;
  g.t_slack = t_slack;
  return g;
}

}  // namespace ktest

// Every channel of texel (x, y) equals the expected vec4 exactly.
#define CHECK_TEXEL(tex, tx, ty, ...)                                \
  do {                                                               \
    const glm::vec4 expected_ = (__VA_ARGS__);                       \
    const glm::vec4 got_ = ktest::at((tex), (tx), (ty));             \
    INFO((tex).name() << " texel (" << (tx) << ", " << (ty) << ")"); \
    CHECK(got_.x == expected_.x);                                    \
    CHECK(got_.y == expected_.y);                                    \
    CHECK(got_.z == expected_.z);                                    \
    CHECK(got_.w == expected_.w);                                    \
  } while (0)

// Every channel of texel (x, y) within eps * (1 + |expected|) of the expected vec4
// (doctest::Approx).
#define CHECK_TEXEL_NEAR(tex, tx, ty, eps, ...)                       \
  do {                                                                \
    const glm::vec4 expected_ = (__VA_ARGS__);                        \
    const glm::vec4 got_ = ktest::at((tex), (tx), (ty));              \
    INFO((tex).name() << " texel (" << (tx) << ", " << (ty) << ")");  \
    for (int c_ = 0; c_ < 4; ++c_) {                                  \
      CAPTURE(c_);                                                    \
      CHECK(got_[c_] == doctest::Approx(expected_[c_]).epsilon(eps)); \
    }                                                                 \
  } while (0)

namespace ktest {

// Two textures of one shape, every channel of every texel equal.
inline void check_same(const Texture& a, const Texture& b) {
  REQUIRE(a.width() == b.width());
  REQUIRE(a.height() == b.height());
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) CHECK_TEXEL(a, x, y, ktest::at(b, x, y));
}

// The first n texels of row 0 (one per ray) equal in every channel.
inline void check_same(const Texture& a, const Texture& b, int n) {
  for (int i = 0; i < n; ++i) CHECK_TEXEL(a, i, 0, ktest::at(b, i, 0));
}

// Whether any of the first n texels of row 0 has x (or w) at least v: a walk's loop conditions
// ("some ray still walks", "some ray still has triangles to test").
inline bool any_x_at_least(const Texture& t, int n, float v) {
  for (int i = 0; i < n; ++i)
    if (at(t, i, 0).x >= v) return true;
  return false;
}
inline bool any_w_at_least(const Texture& t, int n, float v) {
  for (int i = 0; i < n; ++i)
    if (at(t, i, 0).w >= v) return true;
  return false;
}

}  // namespace ktest
