// Kernel tests for the per-voxel loop: actualizarVoxel, intersecciones, proximoTriangulo and the
// three counting kernels (rayosEnGrilla, rayosIntersectando, rayosReflejados), each run as one
// real pass on hand-made texels.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <iterator>
#include <vector>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::grid_uniforms;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

namespace {

// Triangle lists, 4 entries per row: entry 0 is the shared empty list; {5, 7} starts at 1,
// {2, 6} at 4 (second row: the list wraps).
const std::vector<float> kLists = {kNone, 5, 7, kNone, 2, 6, kNone, 0};

}  // namespace

TEST_CASE("update voxel reads the pointer at (X*sizeY + Y, Z) and the first entry of that list") {
  // A 2 x 3 x 2 grid: the pointer texture is 6 x 2. Voxel (1, 0, 1) lives at texel (3, 1) and
  // voxel (0, 2, 1) at (2, 1); the texels an x-major layout (Y*sizeX + X) would read instead,
  // (1, 1) and (4, 1), hold decoys.
  const Texture pointers = scalars("voxel pointers", 6, 2,
                                   {0, 0, 0, 0, 0, 0,  //
                                    0, 4, 4, 1, 0, 0});
  const Texture lists = scalars("triangle lists", 4, 2, kLists);
  kernels::UpdateVoxel k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), {2, 3, 2}, 4);
  const Texture trav = texels("traversal", 5, 1,
                              {{1, 0, 1, 2.0f},
                               {0, 2, 1, 3.0f},
                               {0, 1, 0, 0.0f},    // an empty voxel: pointer 0, list {-1}
                               {kNone, 0, 0, 0},   // done ray
                               {1, 0, 1, 0.0f}});  // still testing a triangle
  const Texture vs = texels(
      "voxel state", 5, 1,
      {{0, 0, 0, kNone}, {0, 0, 0, kNone}, {0, 0, 0, kNone}, {9, 8, 7, kNone}, {2, 3, 4, 5}});
  const Texture out = ktest::run(k, {&trav, &vs, &pointers, &lists}, 5, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 0, 0, 5));
  CHECK_TEXEL(out, 1, 0, glm::vec4(4, 0, 0, 2));
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(out, 3, 0, glm::vec4(9, 8, 7, kNone));
  CHECK_TEXEL(out, 4, 0, glm::vec4(2, 3, 4, 5));
}

TEST_CASE("next triangle advances along the voxel's list and stops at the -1 that closes it") {
  const Texture lists = scalars("triangle lists", 4, 2, kLists);
  kernels::NextTriangle k;
  k.lists = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(1.0f), 4);
  const Texture vs =
      texels("voxel state", 4, 1, {{1, 0, 0, 5}, {2, 0, 0, 7}, {4, 0, 0, 2}, {3, 1, 2, kNone}});
  const Texture out = ktest::run(k, {&vs, &lists}, 4, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(2, 0, 0, 7));
  CHECK_TEXEL(out, 1, 0, glm::vec4(3, 0, 0, kNone));  // the list's end: back to traversal
  CHECK_TEXEL(out, 2, 0, glm::vec4(5, 0, 0, 6));      // entry 5 sits on the second row
  CHECK_TEXEL(out, 3, 0, glm::vec4(3, 1, 2, kNone));  // nothing to test: unchanged
}

TEST_CASE("intersections keeps the nearest hit inside the current voxel, before tmax") {
  // Four triangles, two per texel row. Triangle 3 lies in the plane x = 2.5 spanning y, z in
  // [0, 4]; triangle 2 is the same with corners 1 and 2 swapped (opposite winding, u and v
  // swapped); triangles 0 and 1 are triangle 3 moved to x = 2.0015 and x = 2.0005.
  // Unit voxels, t_slack = 0.001. The ray o = (0.5, 1, 0.5), d = +x meets x = 2.5 at t = 2
  // (voxel 2 spans t in [1.5, 2.5]); by hand (Moller-Trumbore): u = y / 4 = 0.25 (weight of
  // corner 1), v = z / 4 = 0.125 (corner 2).
  auto corners = [](float x, bool swap) {
    const glm::vec3 p0(x, 0, 0), p1(x, 4, 0), p2(x, 0, 4);
    return swap ? std::array<glm::vec3, 3>{p0, p2, p1} : std::array<glm::vec3, 3>{p0, p1, p2};
  };
  const std::array<glm::vec3, 3> tri[4] = {corners(2.0015f, false), corners(2.0005f, false),
                                           corners(2.5f, true), corners(2.5f, false)};
  std::vector<glm::vec3> c[3];
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) c[k].push_back(tri[i][k]);
  const Texture v0 = vec3s("vertices0", 2, 2, c[0]), v1 = vec3s("vertices1", 2, 2, c[1]),
                v2 = vec3s("vertices2", 2, 2, c[2]);

  struct Case {
    glm::vec4 origin, ray, trav, vs, best;
  };
  const glm::vec4 o(0.5f, 1, 0.5f, 0), px(1, 0, 0, kFar), none(kFar, 0, 0, kNone);
  const Case cases[] = {
      {o, px, {2, 1, 0, 1.5f}, {0, 0, 0, 3}, none},                      // 0 hit
      {o, px, {2, 1, 0, 1.5f}, {0, 0, 0, 2}, none},                      // 1 other winding
      {{0.5f, 3.5f, 3.5f, 0}, px, {2, 3, 3, 1.5f}, {0, 0, 0, 3}, none},  // 2 misses: u + v = 1.75
      {o, px, {1, 1, 0, 0.5f}, {0, 0, 0, 0}, none},  // 3 t = 1.5015 > exit 1.5 + slack
      {o, px, {1, 1, 0, 0.5f}, {0, 0, 0, 1}, none},  // 4 t = 1.5005 <= exit 1.5 + slack
      {o, px, {3, 1, 0, 2.5f}, {0, 0, 0, 3}, none},  // 5 t = 2 before the voxel's entry 2.5
      {o, px, {2, 1, 0, 1.5f}, {0, 0, 0, 3}, {1.75f, 0.5f, 0.5f, 0}},  // 6 a nearer hit stays
      {o, px, {2, 1, 0, 1.5f}, {0, 0, 0, 3}, {2.25f, 0.5f, 0.5f, 0}},  // 7 a farther one goes
      {o, {1, 0, 0, 1.9f}, {2, 1, 0, 1.5f}, {0, 0, 0, 3}, none},       // 8 beyond tmax
      {o, {1, 0, 0, 2.1f}, {2, 1, 0, 1.5f}, {0, 0, 0, 3}, none},       // 9 before tmax
      {o, px, {2, 1, 0, 1.5f}, {0, 0, 0, kNone}, {5, 0.1f, 0.2f, 1}},  // 10 nothing to test
      {o, {0, 1, 0, kFar}, {0, 1, 0, 0}, {0, 0, 0, 3}, none},          // 11 parallel: det = 0
      {{3.5f, 1, 0.5f, 0}, {-1, 0, 0, kFar}, {2, 1, 0, 0.5f}, {0, 0, 0, 3}, none},  // 12 back side
      {{3.5f, 1, 0.5f, 0}, px, {3, 1, 0, 0}, {0, 0, 0, 3}, none},  // 13 behind the origin
  };
  const int n = int(std::size(cases));
  std::vector<glm::vec4> origins, rays, trav, vs, best;
  for (const Case& k : cases) {
    origins.push_back(k.origin);
    rays.push_back(k.ray);
    trav.push_back(k.trav);
    vs.push_back(k.vs);
    best.push_back(k.best);
  }
  const Texture to = texels("origins", n, 1, origins), tr = texels("rays", n, 1, rays),
                tt = texels("traversal", n, 1, trav), tv = texels("voxel state", n, 1, vs),
                tb = texels("intersection", n, 1, best);
  kernels::Intersections k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(4.0f), 1, 1e-3f);
  k.scene.width = 2;
  const Texture out = ktest::run(k, {&to, &tr, &tt, &tv, &tb, &v0, &v1, &v2}, n, 1);

  CHECK_TEXEL(out, 0, 0, glm::vec4(2, 0.25f, 0.125f, 3));
  CHECK_TEXEL(out, 1, 0, glm::vec4(2, 0.125f, 0.25f, 2));
  CHECK_TEXEL(out, 2, 0, none);
  CHECK_TEXEL(out, 3, 0, none);
  // t = -(o.x - p0.x), every step exact in float.
  CHECK_TEXEL(out, 4, 0, glm::vec4(2.0005f - 0.5f, 0.25f, 0.125f, 1));
  CHECK_TEXEL(out, 5, 0, none);
  CHECK_TEXEL(out, 6, 0, glm::vec4(1.75f, 0.5f, 0.5f, 0));
  CHECK_TEXEL(out, 7, 0, glm::vec4(2, 0.25f, 0.125f, 3));
  CHECK_TEXEL(out, 8, 0, none);
  CHECK_TEXEL(out, 9, 0, glm::vec4(2, 0.25f, 0.125f, 3));
  CHECK_TEXEL(out, 10, 0, glm::vec4(5, 0.1f, 0.2f, 1));
  CHECK_TEXEL(out, 11, 0, none);
  CHECK_TEXEL(out, 12, 0, glm::vec4(1, 0.25f, 0.125f, 3));  // two-sided: det > 0 from +x
  CHECK_TEXEL(out, 13, 0, none);
}

namespace {

// Runs a counting kernel inside an occlusion query over a target cleared to 7: surviving
// fragments write their (1, 0, 0, 0), discarded ones leave the 7s.
template <class K>
void check_counting(const K& k, const Texture& in, const std::vector<bool>& survives) {
  vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
  uint64_t count = 0;
  vgpu::PassRecord rec;
  const Texture out =
      ktest::run(gpu, k, {&in}, in.width(), in.height(), glm::vec4(7.0f), &count, &rec);
  uint64_t expected = 0;
  for (int x = 0; x < in.width(); ++x) {
    CAPTURE(x);
    expected += survives[size_t(x)];
    CHECK_TEXEL(out, x, 0, survives[size_t(x)] ? glm::vec4(1, 0, 0, 0) : glm::vec4(7.0f));
  }
  CHECK(count == expected);
  CHECK(rec.counters.fragments_discarded == uint64_t(in.width()) - expected);
  CHECK(rec.counters.fragments_shaded == uint64_t(in.width()));
}

}  // namespace

TEST_CASE("rays in grid discards exactly the rays whose traversal is done") {
  const float x[8] = {0, kNone, 3, -1e30f, -0.0f, -0.5f, 2, kNone};
  std::vector<glm::vec4> t;
  for (float v : x) t.push_back({v, 1, 2, 3});
  check_counting(kernels::RaysInGrid{}, texels("traversal", 8, 1, t),
                 {true, false, true, false, true, false, true, false});
}

TEST_CASE("rays intersecting discards exactly the rays with no triangle left in their voxel") {
  const float w[8] = {0, kNone, 3, kNone, 7, -0.5f, -0.0f, 1};
  std::vector<glm::vec4> t;
  for (float v : w) t.push_back({4, 5, 6, v});
  check_counting(kernels::RaysIntersecting{}, texels("voxel state", 8, 1, t),
                 {true, false, true, false, true, false, true, true});
}

TEST_CASE("reflected rays discards exactly the rays whose weight is under the cut") {
  // Cut 1/512: 1/512 itself is kept, the float just below it is not.
  const float w[8] = {0,     1.0f / 1024, 1.0f / 512, 0.5f, 1, -1, std::nextafter(1.0f / 512, 0.0f),
                      0.002f};
  std::vector<glm::vec4> t;
  for (float v : w) t.push_back({0.1f, 0.2f, 0.3f, v});
  check_counting(kernels::ReflectedRays{}, texels("result", 8, 1, t),
                 {false, false, true, true, true, false, false, true});
}
