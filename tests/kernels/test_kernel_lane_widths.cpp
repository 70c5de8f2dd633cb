// Every kernel gives bit-identical outputs, query counts and pass counters at lane widths 1, 4,
// 8 and 16, in fp32 and in the rounded fp24 and fp16 lane families, on a 13x3 target (partial
// batches at every width above 1) of random-ish texels that reach every branch: hits and misses,
// done and walking rays, empty and full voxels, plus a few NaN, infinite and signed-zero channels.
#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "kernel_pass.h"
#include "tests/support/lane_widths.h"

using kernels::kFar;
using kernels::kNone;
using ktest::Texture;

namespace {

constexpr int kW = 13, kH = 3;

// splitmix64: the same texels on every run and machine.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * float(next() >> 40) / float(1 << 24);
  }
  int pick(int n) { return int(next() % uint64_t(n)); }
  // About one value in 24 becomes a special.
  float maybe_special(float v) {
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(), 0.0f, -0.0f};
    return pick(24) == 0 ? specials[pick(5)] : v;
  }
};

using Gen = std::function<glm::vec4(Rng&)>;

Texture make(const char* name, int w, int h, int channels, uint64_t seed, const Gen& gen) {
  Rng r{seed};
  Texture t(name, w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4 v = gen(r);
      for (int c = 0; c < channels; ++c) t.set(x, y, c, r.maybe_special(v[c]));
    }
  return t;
}

// Per-pixel state textures, with values picked to take every path of the kernels.
struct Inputs {
  Texture origins, rays, trav, vs, isect, surface, result, shadow;
  Texture v[3], n[3], colors, lists, pointers;
  Inputs() {
    origins = make("origins", kW, kH, 4, 1, [](Rng& r) {
      return glm::vec4(r.uniform(-1, 5), r.uniform(-1, 5), float(r.pick(5)) + 0.5f, 0);
    });
    rays = make("rays", kW, kH, 4, 2, [](Rng& r) {
      glm::vec3 d(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1));
      for (int a = 0; a < 3; ++a)
        if (r.pick(4) == 0) d[a] = 0;
      const float len = glm::length(d);
      if (len > 0) d /= len;
      const float tmax = r.pick(8) == 0 ? -1.0f : r.pick(2) ? kFar : r.uniform(0, 6);
      return glm::vec4(d, tmax);
    });
    trav = make("traversal", kW, kH, 4, 3, [](Rng& r) {
      return glm::vec4(float(r.pick(5) - 1), float(r.pick(4)), float(r.pick(4)), r.uniform(0, 4));
    });
    vs = make("voxel state", kW, kH, 4, 4,
              [](Rng& r) { return glm::vec4(float(r.pick(7)), 0, 0, float(r.pick(5) - 1)); });
    isect = make("intersection", kW, kH, 4, 5, [](Rng& r) {
      return glm::vec4(r.pick(2) ? kFar : r.uniform(0, 6), r.uniform(0, 1), r.uniform(0, 1),
                       float(r.pick(5) - 1));
    });
    surface = make("surface", kW, kH, 4, 6, [](Rng& r) {
      return glm::vec4(r.uniform(0, 4), r.uniform(0, 4), r.uniform(0, 4), float(r.pick(5) - 1));
    });
    result = make("result", kW, kH, 4, 7, [](Rng& r) {
      const float w[5] = {0, 1.0f / 1024, 1.0f / 512, 0.3f, 1};
      return glm::vec4(r.uniform(0, 1), r.uniform(0, 1), r.uniform(0, 1), w[r.pick(5)]);
    });
    shadow = make("shadow", kW, kH, 4, 8,
                  [](Rng& r) { return glm::vec4(r.uniform(0, 6), 0, 0, float(r.pick(3) - 1)); });
    // Four triangles in [0, 4]^3, two per row.
    for (int k = 0; k < 3; ++k) {
      v[k] = make(("vertices" + std::to_string(k)).c_str(), 2, 2, 3, 10 + uint64_t(k), [](Rng& r) {
        return glm::vec4(r.uniform(0, 4), r.uniform(0, 4), r.uniform(0, 4), 0);
      });
      n[k] = make(("normals" + std::to_string(k)).c_str(), 2, 2, 3, 20 + uint64_t(k), [](Rng& r) {
        return glm::vec4(glm::normalize(glm::vec3(r.uniform(-1, 1), r.uniform(-1, 1), 1)), 0);
      });
    }
    colors = make("colors", 2, 2, 4, 30, [](Rng& r) {
      return glm::vec4(r.uniform(0, 1), r.uniform(0, 1), r.uniform(0, 1), r.uniform(0, 1));
    });
    // Lists of width 4: {-1, 0, 1, -1, 2, 3, 1, -1}; pointers of a 4x4x4 grid at 0, 1 or 4.
    lists = ktest::scalars("triangle lists", 4, 2, {kNone, 0, 1, kNone, 2, 3, 1, kNone});
    pointers = make("voxel pointers", 16, 4, 1, 31, [](Rng& r) {
      const float start[3] = {0, 1, 4};
      return glm::vec4(start[r.pick(3)], 0, 0, 0);
    });
  }
};

kernels::GridUniforms grid() {
  return ktest::grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(4.0f), 4, 1e-4f);
}

struct Output {
  Texture tex;
  vgpu::PassRecord rec;
  uint64_t query = 0;
};

template <class K>
Output run_at(int lanes, const K& k, const std::vector<const Texture*>& units, bool query,
              vgpu::Format precision = vgpu::Format::fp32) {
  vgpu::Gpu gpu(ktest::gf5700(), 1, lanes);
  gpu.set_precision(precision);
  Output o;
  o.tex = ktest::run(gpu, k, units, kW, kH, glm::vec4(7.0f), query ? &o.query : nullptr, &o.rec);
  return o;
}

template <class K>
void check_widths(const K& k, const std::vector<const Texture*>& units, bool query = false) {
  CAPTURE(std::string(K::name));
  // The rounded lane family runs at width 1 or 8 (Gpu::draw): every other width is 8.
  for (vgpu::Format f : {vgpu::Format::fp32, vgpu::Format::fp24, vgpu::Format::fp16}) {
    CAPTURE(vgpu::format_name(f));
    const Output ref = run_at(1, k, units, query, f);
    for (int lanes : {4, 8, 16}) {
      if (!test_support::kernel_width_built(lanes)) continue;
      CAPTURE(lanes);
      const Output o = run_at(lanes, k, units, query, f);
      CHECK(std::memcmp(o.tex.data().data(), ref.tex.data().data(), ref.tex.data().size_bytes()) ==
            0);
      CHECK(o.query == ref.query);
      CHECK(o.rec.counters.same_counts(ref.rec.counters));
    }
  }
}

}  // namespace

TEST_CASE(
    "every kernel gives bit-identical outputs and counters at lane widths 1, 4, 8 and 16, at fp32, "
    "fp24 and fp16") {
  const Inputs in;
  {
    kernels::GenerateRays k;
    k.forward = glm::normalize(glm::vec3(0.2f, -0.3f, -1));
    k.right = glm::normalize(glm::cross(k.forward, glm::vec3(0, 1, 0)));
    k.up = glm::cross(k.right, k.forward);
    k.aspect = float(kW) / kH;
    k.width = kW;
    k.height = kH;
    check_widths(k, {});
  }
  {
    kernels::InitTraversal k;
    k.eye = {-1.3f, 2.2f, 1.7f};
    k.grid = grid();
    check_widths(k, {&in.rays});
  }
  {
    kernels::ResetTraversal k;
    k.grid = grid();
    check_widths(k, {&in.origins, &in.rays});
  }
  {
    kernels::Traversal k;
    k.grid = grid();
    check_widths(k, {&in.origins, &in.rays, &in.trav, &in.isect});
  }
  check_widths(kernels::RaysInGrid{}, {&in.trav}, true);
  {
    kernels::UpdateVoxel k;
    k.grid = grid();
    check_widths(k, {&in.trav, &in.vs, &in.pointers, &in.lists});
  }
  {
    kernels::Intersections k;
    k.grid = grid();
    k.scene.width = 2;
    check_widths(
        k, {&in.origins, &in.rays, &in.trav, &in.vs, &in.isect, &in.v[0], &in.v[1], &in.v[2]});
  }
  {
    kernels::NextTriangle k;
    k.lists = grid();
    check_widths(k, {&in.vs, &in.lists});
  }
  check_widths(kernels::RaysIntersecting{}, {&in.vs}, true);
  for (kernels::ShadingModel model : {kernels::ShadingModel::diffuse, kernels::ShadingModel::phong,
                                      kernels::ShadingModel::phong_atten}) {
    for (bool shadows : {false, true}) {
      CAPTURE(int(model));
      CAPTURE(shadows);
      kernels::Shader k;
      k.scene.width = 2;
      k.model = model;
      k.shadows = shadows;
      k.light = {2, 7, 3};
      k.first_light = shadows;
      k.last_light = !shadows;
      check_widths(k, {&in.surface, &in.rays, &in.result, &in.shadow, &in.colors, &in.v[0],
                       &in.v[1], &in.v[2], &in.n[0], &in.n[1], &in.n[2]});
    }
  }
  check_widths(kernels::ReflectedRays{}, {&in.result}, true);
  {
    kernels::ReflectionOrigin k;
    k.scene.width = 2;
    k.offset = 1e-3f;
    check_widths(k, {&in.origins, &in.rays, &in.isect, &in.v[0], &in.v[1], &in.v[2]});
  }
  {
    kernels::ReflectionDirection k;
    k.scene.width = 2;
    check_widths(k, {&in.rays, &in.surface, &in.result, &in.v[0], &in.v[1], &in.v[2], &in.n[0],
                     &in.n[1], &in.n[2]});
  }
  {
    kernels::ShadowRays k;
    k.light = {2, 7, 3};
    check_widths(k, {&in.surface, &in.result});
  }
}
