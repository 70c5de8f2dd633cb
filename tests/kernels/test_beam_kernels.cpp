// Kernel tests for beams over tiles (kernels/beams.h): rayosHaz (one step of each tile's beam),
// rayosHazPerdidos (the count of tiles that miss) and inicioHaz (each pixel's ray started where its
// tile's beam stopped, at exactly the state the 3D-DDA reaches), each a real pass on hand-made
// texels, every output channel checked.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "kernel_pass.h"
#include "tests/support/reference.h"

using kernels::kFar;
using kernels::kNone;
using ktest::grid_uniforms;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;

namespace {

// A 4x4x4 grid of unit voxels from the origin, an 8x2 image of 2x2 tiles (4 tiles in a row),
// looking down +z from (2.5, 2.5, -5) with a narrow field.
kernels::BeamUniforms beam_uniforms() {
  kernels::BeamUniforms u;
  u.camera.forward = {0, 0, 1};
  u.camera.right = {1, 0, 0};
  u.camera.up = {0, 1, 0};
  u.camera.tan_half_fov = 0.05f;
  u.camera.aspect = 4.0f;
  u.camera.width = 8;
  u.camera.height = 2;
  u.eye = {2.5f, 2.5f, -5.0f};
  u.tile = 2;
  u.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), {4, 4, 4});
  u.min_cell = 1;
  u.margin = 1e-3f;
  u.min_step = 0.5f;
  u.far = 10.0f;
  return u;
}

// The test's own camera, in double: the unit direction through image point (px, py).
glm::dvec3 ray_dir(double px, double py) {
  const double sx = (2.0 * px / 8.0 - 1.0) * 0.05 * 4.0, sy = (1.0 - 2.0 * py / 2.0) * 0.05;
  return glm::normalize(glm::dvec3(sx, sy, 1.0));
}

// Tile tx's corner rays (pixel centres 2tx + 0.5, 2tx + 1.5; rows 0.5, 1.5), the widest
// cosine to their mean, and where the first of them leaves the box [lo, hi] after t (each must
// be inside at t).
struct Tile {
  std::vector<glm::dvec3> corners;
  double cosw;
};
Tile tile(int tx) {
  Tile t;
  for (double py : {0.5, 1.5})
    for (double px : {2.0 * tx + 0.5, 2.0 * tx + 1.5}) t.corners.push_back(ray_dir(px, py));
  glm::dvec3 axis(0.0);
  for (const auto& d : t.corners) axis += d;
  axis = glm::normalize(axis);
  t.cosw = 1.0;
  for (const auto& d : t.corners) t.cosw = std::min(t.cosw, glm::dot(axis, d));
  return t;
}
double first_exit(const Tile& t, double at, glm::dvec3 lo, glm::dvec3 hi) {
  const glm::dvec3 e(2.5, 2.5, -5.0);
  double out = 1e300;
  for (const auto& d : t.corners) {
    const std::pair<double, double> in_out = host::box_interval(e, d, lo, hi);
    const double tn = in_out.first, tf = in_out.second;
    REQUIRE(tn <= at);
    REQUIRE(tf >= at);
    out = std::min(out, tf);
  }
  return out;
}

}  // namespace

TEST_CASE("beam march moves each beam to where its first corner ray leaves an empty box") {
  // Beam distances: every voxel holds a triangle (0) but (2, 2, 1), whose neighbours one step
  // away are empty (2). Voxel (X, Y, Z) at texel (X * 4 + Y, Z).
  std::vector<float> k(16 * 4, 0.0f);
  k[1 * 16 + 2 * 4 + 2] = 2.0f;
  const Texture distances = scalars("beam distances", 16, 4, k);
  // Tile 0 starts at the eye, off the grid; tile 1 stands in voxel (2, 2, 0), which holds a
  // triangle; tile 2 in the empty voxel (2, 2, 1); tile 3 past the grid's far face.
  const Texture beams =
      texels("beams", 4, 1, {{0, 0, 0, 0}, {0, 5.5f, 0, 4}, {0, 6.5f, 0, 2}, {0, 20, 0, 7}});
  kernels::BeamMarch march;
  march.beams = beam_uniforms();
  const Texture out = ktest::run(march, {&beams, &distances}, 4, 1);
  const double m = 1e-3, far = 1e30;
  // Tile 0: the half-space in front of the grid (z < 0) holds all four corners until z = -m.
  const Tile t0 = tile(0);
  const double exit0 =
      first_exit(t0, 0.0, glm::dvec3(-far), glm::dvec3(far, far, -m)) * t0.cosw * 0.9999;
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-5, glm::vec4(0, float(exit0), 0, 1));
  // Tile 1: no empty box holds it: it stops where it is.
  CHECK_TEXEL(out, 1, 0, glm::vec4(-1, 5.5f, 0, 4));
  // Tile 2: the cube of voxels one step around (2, 2, 1) is empty: [1, 4) x [1, 4) x [0, 3).
  const Tile t2 = tile(2);
  const double exit2 =
      first_exit(t2, 6.5, glm::dvec3(1 + m, 1 + m, m), glm::dvec3(4 - m, 4 - m, 3 - m)) * t2.cosw *
      0.9999;
  CHECK(exit2 > 7.5);
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-5, glm::vec4(0, float(exit2), 0, 3));
  // Tile 3: beyond the far face and moving away: the half-space holds it for ever, the beam
  // passes the farthest corner of the grid (far = 10): the whole tile misses.
  const glm::vec4 t3 = ktest::at(out, 3, 0);
  CHECK(t3.x == -1);
  CHECK(t3.y >= 10.0f);
  CHECK(t3.z == 1);
  CHECK(t3.w == 8);
  // A second step: the stopped beams keep their texels.
  const Texture again = ktest::run(march, {&out, &distances}, 4, 1);
  CHECK_TEXEL(again, 1, 0, ktest::at(out, 1, 0));
  CHECK_TEXEL(again, 3, 0, ktest::at(out, 3, 0));
  // The count of tiles that miss: tile 3 alone.
  uint64_t missed = 0;
  ktest::run(kernels::BeamsMissed{}, {&out}, 4, 1, glm::vec4(0.0f), &missed);
  CHECK(missed == 1);
}

TEST_CASE(
    "beam march leaves the empty cube around the beam's voxel through whichever of its six faces "
    "the beam points at") {
  // Beam distances: every voxel of the 4x4x4 grid holds a triangle (0) but (2, 2, 2), whose
  // neighbours one step away are empty (2): the cube [1, 4) on every axis. A 2x2 image of one
  // 2x2 tile from the eye (2.3, 2.6, 2.45), inside that voxel, looking along each axis both
  // ways: the beam must move on to where its first corner ray leaves the cube (less the margin)
  // through the face it looks at, 1.3 to 1.7 cells away (the cube's faces at 1 and 4), scaled
  // by cos(theta) and 0.9999; every output channel is checked.
  std::vector<float> k(16 * 4, 0.0f);
  k[2 * 16 + 2 * 4 + 2] = 2.0f;
  const Texture distances = scalars("beam distances", 16, 4, k);
  const Texture start = texels("beams", 1, 1, {{0, 0, 0, 0}});
  const glm::dvec3 e(2.3, 2.6, 2.45);
  const double m = 1e-3;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {-1.0, 1.0}) {
      CAPTURE(axis);
      CAPTURE(sign);
      glm::dvec3 f(0.0), right(0.0), up(0.0);
      f[axis] = sign;
      right[(axis + 1) % 3] = 1.0;
      up[(axis + 2) % 3] = 1.0;
      kernels::BeamUniforms u = beam_uniforms();
      u.camera.forward = glm::vec3(f);
      u.camera.right = glm::vec3(right);
      u.camera.up = glm::vec3(up);
      u.camera.aspect = 1.0f;
      u.camera.width = 2;
      u.camera.height = 2;
      u.eye = glm::vec3(e);
      kernels::BeamMarch march;
      march.beams = u;
      const Texture out = ktest::run(march, {&start, &distances}, 1, 1);
      // The test's own corner rays (pixel centres 0.5 and 1.5 of the 2x2 image), in double.
      std::vector<glm::dvec3> corners;
      for (double py : {0.5, 1.5})
        for (double px : {0.5, 1.5})
          corners.push_back(
              glm::normalize(f + right * ((px - 1.0) * 0.05) + up * ((1.0 - py) * 0.05)));
      glm::dvec3 mean(0.0);
      for (const auto& d : corners) mean += d;
      mean = glm::normalize(mean);
      double cosw = 1.0, exit = 1e300;
      for (const auto& d : corners) {
        cosw = std::min(cosw, glm::dot(mean, d));
        double tf = 1e300;
        for (int a = 0; a < 3; ++a) {
          if (d[a] == 0.0) continue;
          tf = std::min(tf, std::max((1 + m - e[a]) / d[a], (4 - m - e[a]) / d[a]));
        }
        exit = std::min(exit, tf);
      }
      // Along the axis the face it looks at comes first: x 1.3 or 1.7 away, y 1.6 or 1.4, z 1.45
      // or 1.55.
      const double face = sign < 0 ? e[axis] - 1 - m : 4 - m - e[axis];
      CHECK(exit == doctest::Approx(face / cosw).epsilon(1e-3));
      CHECK_TEXEL_NEAR(out, 0, 0, 1e-5, glm::vec4(0, float(exit * cosw * 0.9999), 0, 1));
    }
}

TEST_CASE(
    "the looping beam march ends in one pass where the march's passes end, and stops at its step "
    "budget") {
  // The distances of the test above, with a deeper empty pocket: the voxels of z 1 to 3 whose x
  // and y are 1 to 3 are empty, those on the axis (2, 2, z) two steps from any triangle, so tile
  // 2 marches through three cubes and out of the far face (it misses).
  std::vector<float> k(16 * 4, 0.0f);
  for (int z = 1; z < 4; ++z) {
    for (int x = 1; x < 4; ++x)
      for (int y = 1; y < 4; ++y) k[size_t(z * 16 + x * 4 + y)] = 1.0f;
    k[size_t(z * 16 + 2 * 4 + 2)] = 2.0f;
  }
  const Texture distances = scalars("beam distances", 16, 4, k);
  const Texture start =
      texels("beams", 4, 1, {{0, 0, 0, 0}, {0, 5.5f, 0, 4}, {0, 6.5f, 0, 2}, {0, 20, 0, 7}});
  kernels::BeamMarch march;
  march.beams = beam_uniforms();
  // The passes: step until no beam marches (x -1 everywhere), counting each tile's steps.
  std::vector<Texture> passes{start};
  int runs = 0;
  auto marching = [](const Texture& t) {
    for (int i = 0; i < 4; ++i)
      if (ktest::at(t, i, 0).x >= 0) return true;
    return false;
  };
  while (marching(passes.back())) {
    REQUIRE(++runs < 20);
    passes.push_back(ktest::run(march, {&passes.back(), &distances}, 4, 1));
  }
  REQUIRE(runs >= 3);  // some beam takes two steps or more before it stops
  kernels::BeamMarchLooping loop;
  loop.beams = beam_uniforms();
  loop.steps = 20;
  vgpu::Gpu gpu(ktest::gf6600(), 1, 1);  // a profile with loops
  vgpu::PassRecord rec;
  const Texture out =
      ktest::run(gpu, loop, {&start, &distances}, 4, 1, glm::vec4(7, 8, 9, 10), nullptr, &rec);
  uint64_t iterations = 0;
  for (int i = 0; i < 4; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out, i, 0, ktest::at(passes.back(), i, 0));
    // A tile iterates once per pass it ran while marching (the last one stops it).
    for (size_t p = 0; p + 1 < passes.size(); ++p) iterations += ktest::at(passes[p], i, 0).x >= 0;
  }
  CHECK(rec.counters.loop_iterations == iterations);
  // With a budget of one step the loop leaves every tile where the first pass leaves it.
  loop.steps = 1;
  const Texture cut = ktest::run(gpu, loop, {&start, &distances}, 4, 1, glm::vec4(7));
  for (int i = 0; i < 4; ++i) CHECK_TEXEL(cut, i, 0, ktest::at(passes[1], i, 0));
}

TEST_CASE("beam entry starts a ray at the traversal state the 3D-DDA reaches, or where it enters") {
  const kernels::BeamUniforms u = beam_uniforms();
  const glm::vec3 e = u.eye;
  auto unit = [](glm::vec3 v) { return v / std::sqrt(glm::dot(v, v)); };
  const glm::vec3 d0 = unit({0.1f, 0.05f, 1.0f}), d1 = unit({-0.1f, 0.15f, 1.0f});
  // A ray whose point at t = 8.1 lies 0.0005 past the face z = 3: too near to trust.
  const float dz = 8.0005f / 8.1f;
  const glm::vec3 d2{std::sqrt(1.0f - dz * dz), 0.0f, dz};
  const glm::vec3 d3 = unit({0.05f, -0.05f, 1.0f});
  // Pixels (x, y) of the 8x2 image; tile 0 (x 0-1) stopped at t = 8.1, tile 1 (x 2-3) missed,
  // tile 2 (x 4-5) stopped before the grid (t = 2), tile 3 (x 6-7) at t = 8.1 too.
  const Texture rays = texels("rays", 8, 2,
                              {{d0, kFar},
                               {d1, kFar},
                               {d0, kFar},
                               {d1, kFar},  //
                               {d0, kFar},
                               {d1, kFar},
                               {d3, kFar},
                               {d0, kFar},  //
                               {d2, kFar},
                               {d3, kNone},
                               {d0, kFar},
                               {d1, kFar},  //
                               {d0, kFar},
                               {d1, kFar},
                               {d0, kNone},
                               {d1, kFar}});
  const Texture beams = texels(
      "beams", 4, 1, {{-1, 8.1f, 0, 5}, {-1, 1e30f, 1, 3}, {-1, 2.0f, 0, 1}, {-1, 8.1f, 0, 4}});
  kernels::BeamEntry entry;
  entry.beams = u;
  const Texture out = ktest::run(entry, {&rays, &beams}, 8, 2);
  // The references: initTraversal, then traversal steps until the voxel the test expects.
  kernels::InitTraversal init;
  init.eye = e;
  init.grid = u.grid;
  const Texture entered = ktest::run(init, {&rays}, 8, 2);
  const Texture no_hit =
      texels("intersection", 8, 2, std::vector<glm::vec4>(16, {kFar, 0, 0, kNone}));
  const Texture origins = texels("origins", 8, 2, std::vector<glm::vec4>(16, glm::vec4(e, 0)));
  kernels::Traversal step;
  step.grid = u.grid;
  std::vector<Texture> walk{entered};
  for (int i = 0; i < 12; ++i)
    walk.push_back(ktest::run(step, {&origins, &rays, &walk.back(), &no_hit}, 8, 2));
  // Where the DDA of pixel (x, y) stands in voxel v (the test's own floor of the point at t).
  auto dda_at = [&](int x, int y, glm::vec3 d, double t) {
    const glm::dvec3 p = glm::dvec3(e) + glm::dvec3(d) * t;
    const glm::vec4 v(std::floor(p.x), std::floor(p.y), std::floor(p.z), 0);
    for (const Texture& s : walk) {
      const glm::vec4 st = ktest::at(s, x, y);
      if (st.x == v.x && st.y == v.y && st.z == v.z) return st;
    }
    INFO("pixel " << x << "," << y << " voxel " << v.x << "," << v.y << "," << v.z);
    FAIL("the walk never reached the voxel");
    return glm::vec4(0);
  };
  // Tile 0: moved on, to the DDA's own state, bit for bit, and past where the ray entered.
  CHECK_TEXEL(out, 0, 0, dda_at(0, 0, d0, 8.1));
  CHECK_TEXEL(out, 1, 0, dda_at(1, 0, d1, 8.1));
  CHECK(ktest::at(out, 0, 0).w > ktest::at(entered, 0, 0).w);
  CHECK(ktest::at(out, 0, 0).z == 3);
  // Pixel (0, 1): its point lies too near a face: it enters as initTraversal has it. Pixel
  // (1, 1) has no ray: done.
  const glm::vec4 done(kNone, 0, 0, 0);
  CHECK_TEXEL(out, 0, 1, ktest::at(entered, 0, 1));
  CHECK(ktest::at(entered, 0, 1).x >= 0);
  CHECK_TEXEL(out, 1, 1, done);
  // Tile 1 missed: its rays are done, even those that would enter the grid.
  for (int y = 0; y < 2; ++y)
    for (int x = 2; x < 4; ++x) CHECK_TEXEL(out, x, y, done);
  // Tile 2 stopped before the grid: its rays enter as initTraversal has it; no ray: done.
  CHECK_TEXEL(out, 4, 0, ktest::at(entered, 4, 0));
  CHECK_TEXEL(out, 5, 0, ktest::at(entered, 5, 0));
  CHECK_TEXEL(out, 4, 1, ktest::at(entered, 4, 1));
  CHECK_TEXEL(out, 5, 1, ktest::at(entered, 5, 1));
  // Tile 3: moved on; its pixel without a ray is done.
  CHECK_TEXEL(out, 6, 0, dda_at(6, 0, d3, 8.1));
  CHECK_TEXEL(out, 7, 0, dda_at(7, 0, d0, 8.1));
  CHECK_TEXEL(out, 6, 1, done);
  CHECK_TEXEL(out, 7, 1, dda_at(7, 1, d1, 8.1));
}
