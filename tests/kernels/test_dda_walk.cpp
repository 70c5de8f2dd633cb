// The 3D-DDA as the GPU runs it: initTraversal (or reinicializarTraversal) then the traversal
// kernel pass after pass on one pixel with no hits, collecting the voxels visited, compared with
// host::voxel_walk_reference (sorted plane crossings in double, no DDA).
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "kernel_pass.h"
#include "tests/support/reference.h"

using kernels::kFar;
using kernels::kNone;
using ktest::texels;
using ktest::Texture;

namespace {

// Box [-1, 2] x [-2, 2] x [0.5, 2.5] in 6 x 4 x 8 voxels of 0.5 x 1 x 0.25: every voxel plane is
// a dyadic float, so the kernel's float boundaries equal the reference's double ones.
host::Grid walk_grid() {
  return host::build_grid_in_box(host::Scene{}, {-1, -2, 0.5f}, {2, 2, 2.5f}, {6, 4, 8});
}

struct Walk {
  std::vector<glm::ivec3> voxels;
  std::vector<float> t;  // entry parameter of each voxel
};

// Drives the kernels on a 1x1 target until the ray is done. inside = false: the ray is a camera
// ray from `origin` (initTraversal, eye uniform); true: reinicializarTraversal from the origins
// texture.
Walk gpu_walk(const host::Grid& grid, glm::vec3 origin, glm::vec3 dir, bool reset) {
  kernels::GridUniforms g = ktest::grid_uniforms(grid.lo, grid.cell, glm::vec3(grid.res));
  vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
  const Texture origins = texels("origins", 1, 1, {glm::vec4(origin, 0)});
  const Texture rays = texels("rays", 1, 1, {glm::vec4(dir, kFar)});
  const Texture isect = texels("intersection", 1, 1, {{kFar, 0, 0, kNone}});
  Texture trav[2] = {Texture("traversal A", 1, 1, 4), Texture("traversal B", 1, 1, 4)};
  kernels::InitTraversal init;
  init.eye = origin;
  init.grid = g;
  kernels::ResetTraversal re;
  re.grid = g;
  kernels::Traversal step;
  step.grid = g;
  vgpu::KernelProgram<kernels::InitTraversal> p_init(init);
  vgpu::KernelProgram<kernels::ResetTraversal> p_reset(re);
  vgpu::KernelProgram<kernels::Traversal> p_step(step);
  if (reset)
    ktest::draw(gpu, p_reset, {&origins, &rays}, trav[0]);
  else
    ktest::draw(gpu, p_init, {&rays}, trav[0]);
  Walk w;
  int cur = 0;
  for (int pass = 0; pass < 200; ++pass) {
    const glm::vec4 t = ktest::at(trav[cur], 0, 0);
    if (t.x < 0) return w;
    w.voxels.push_back(glm::ivec3(t));
    w.t.push_back(t.w);
    ktest::draw(gpu, p_step, {&origins, &rays, &trav[cur], &isect}, trav[cur ^ 1]);
    cur ^= 1;
  }
  FAIL("the walk did not end within 200 passes");
  return w;
}

std::string to_string(const std::vector<glm::ivec3>& walk) {
  std::ostringstream s;
  for (const glm::ivec3& v : walk) s << "(" << v.x << "," << v.y << "," << v.z << ") ";
  return s.str();
}

void check_walk(glm::vec3 origin, glm::vec3 dir, bool reset, bool expect_empty = false) {
  const host::Grid grid = walk_grid();
  const Walk w = gpu_walk(grid, origin, dir, reset);
  const std::vector<glm::ivec3> ref =
      host::voxel_walk_reference(grid, glm::dvec3(origin), glm::dvec3(dir));
  INFO("gpu:       " << to_string(w.voxels));
  INFO("reference: " << to_string(ref));
  CHECK(w.voxels == ref);
  CHECK(ref.empty() == expect_empty);
  for (size_t i = 1; i < w.t.size(); ++i) CHECK(w.t[i] >= w.t[i - 1]);
}

glm::vec3 unit(glm::vec3 v) {
  return v / std::sqrt(glm::dot(v, v));
}

}  // namespace

TEST_CASE("the traversal kernel walks a diagonal ray through the voxels the reference finds") {
  // Generic directions: no two planes are crossed at the same t in exact arithmetic (a float
  // near-tie would be decided differently by the float kernel and the double reference).
  SUBCASE("entering from outside, every component positive") {
    check_walk({-2, -2.7f, 0.1f}, unit({1, 0.71f, 0.43f}), false);
  }
  SUBCASE("entering from outside, every component negative") {
    check_walk({3, 2.5f, 3.0f}, unit({-0.8f, -0.5f, -0.3f}), false);
  }
  SUBCASE("starting inside the grid (reset traversal)") {
    check_walk({0.31f, 0.13f, 1.27f}, unit({-0.3f, 0.87f, 0.52f}), true);
  }
  SUBCASE("starting inside the grid, mixed signs") {
    check_walk({1.7f, -1.2f, 2.2f}, unit({-0.9f, 0.35f, -0.25f}), true);
  }
}

TEST_CASE("the traversal kernel walks rays parallel to an axis, both directions") {
  SUBCASE("+x") {
    check_walk({-3, 0.3f, 1.1f}, {1, 0, 0}, false);
  }
  SUBCASE("-x") {
    check_walk({5, 0.3f, 1.1f}, {-1, 0, 0}, false);
  }
  SUBCASE("+y") {
    check_walk({0.2f, -5, 1.3f}, {0, 1, 0}, false);
  }
  SUBCASE("-y") {
    check_walk({0.2f, 5, 1.3f}, {0, -1, 0}, false);
  }
  SUBCASE("+z") {
    check_walk({0.7f, -1.5f, -1}, {0, 0, 1}, false);
  }
  SUBCASE("-z") {
    check_walk({0.7f, -1.5f, 4}, {0, 0, -1}, false);
  }
  SUBCASE("-x from inside") {
    check_walk({1.3f, 0.6f, 1.9f}, {-1, 0, 0}, true);
  }
  SUBCASE("+z lying in the voxel planes y = 0 and x = 0.5 (the + side is walked)") {
    check_walk({0.5f, 0.0f, -1}, {0, 0, 1}, false);
  }
}

TEST_CASE("the traversal kernel walks rays parallel to a coordinate plane, both directions") {
  SUBCASE("xy plane, +x +y") {
    check_walk({-2, -3.3f, 1.05f}, {0.6f, 0.8f, 0}, false);
  }
  SUBCASE("xy plane, -x -y") {
    check_walk({3, 3.3f, 1.05f}, {-0.6f, -0.8f, 0}, false);
  }
  SUBCASE("yz plane, +y -z") {
    check_walk({0.3f, -3, 3.1f}, {0, 0.6f, -0.8f}, false);
  }
  SUBCASE("yz plane, -y +z") {
    check_walk({0.3f, 3, 0.1f}, {0, -0.6f, 0.8f}, false);
  }
  SUBCASE("xz plane, +x -z") {
    check_walk({-1.5f, 0.4f, 2.9f}, {0.8f, 0, -0.6f}, false);
  }
  SUBCASE("xz plane, -x +z, from inside") {
    check_walk({1.9f, 0.4f, 0.6f}, {-0.8f, 0, 0.6f}, true);
  }
}

TEST_CASE(
    "the traversal kernel crosses voxel edges and corners diagonally, as the reference does") {
  // d = (0.5, 1, 0.25) s: the x and y components differ by exactly a factor 2, the voxel sizes
  // too, so x and y planes are crossed at bit-identical t wherever the line meets a voxel edge.
  const float s = 1.0f / std::sqrt(1.3125f);
  const glm::vec3 d(0.5f * s, s, 0.25f * s);
  SUBCASE("through x-y edges, entering through the z = 0.5 face") {
    // The line passes through (-1 + 0.5 i, -2 + i) in x, y, never at a z plane there.
    check_walk({-0.875f, -1.75f, 0.2f}, d, false);
  }
  SUBCASE("through voxel corners, from inside") {
    // The line passes through (-1 + 0.5 i, -2 + i, 0.5 + 0.25 i): x, y and z tie.
    check_walk({-0.875f, -1.75f, 0.5625f}, d, true);
  }
  SUBCASE("through voxel corners, entering at the grid's corner") {
    check_walk({-1.125f, -2.25f, 0.4375f}, d, false);
  }
}

TEST_CASE("a ray that misses the grid visits no voxel") {
  SUBCASE("pointing away") {
    check_walk({-3, -3, 0}, unit({-1, 0.2f, 0.1f}), false, true);
  }
  SUBCASE("passing beside the box") {
    check_walk({-3, 5, 1}, {1, 0, 0}, false, true);
  }
  SUBCASE("parallel to a face, outside it") {
    check_walk({0.5f, 0.5f, 3}, {1, 0, 0}, false, true);
  }
}
