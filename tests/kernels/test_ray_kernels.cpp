// Kernel tests for the ray set-up and grid-walk kernels: generadorRayos, initTraversal,
// reinicializarTraversal and one traversal step (ending at the grid's face or past the ray's
// tmax), each run as one real pass on hand-made texels.
#include <doctest/doctest.h>

#include <cmath>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::grid_uniforms;
using ktest::texels;
using ktest::Texture;

namespace {

// The unit grid over [0, 4]^3 most cases use: voxel planes at the integers.
const kernels::GridUniforms kUnitGrid =
    grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(4.0f));

glm::vec3 unit(glm::dvec3 v) {
  return glm::vec3(v / std::sqrt(glm::dot(v, v)));
}

}  // namespace

TEST_CASE("generate rays gives each pixel the normalised camera ray through its centre") {
  // 4x2 pixels, aspect 2, tan(fov/2) = 0.5, camera looking down +x with right = +z, up = +y:
  // pixel (x, y) has screen offsets sx = ((x + 0.5) / 2 - 1) * 0.5 * 2, sy = (1 - (y + 0.5)) * 0.5.
  kernels::GenerateRays k;
  k.forward = {1, 0, 0};
  k.right = {0, 0, 1};
  k.up = {0, 1, 0};
  k.tan_half_fov = 0.5f;
  k.aspect = 2.0f;
  k.width = 4;
  k.height = 2;
  const Texture rays = ktest::run(k, {}, 4, 2);
  const double sx[4] = {-0.75, -0.25, 0.25, 0.75}, sy[2] = {0.25, -0.25};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const glm::vec3 d = unit({1.0, sy[y], sx[x]});  // forward + sx right + sy up
      CHECK_TEXEL_NEAR(rays, x, y, 1e-6, glm::vec4(d, kFar));
    }
}

TEST_CASE("init traversal finds the entry voxel and entry t of each camera ray, or marks it done") {
  kernels::InitTraversal k;
  k.eye = {-1.0f, 1.5f, 2.5f};  // left of the box [0, 4]^3, in voxel row y = 1, z = 2
  k.grid = kUnitGrid;
  const Texture rays = texels("rays", 4, 2,
                              {
                                  {1, 0, 0, kFar},        // enters the x = 0 face at t = 1
                                  {-1, 0, 0, kFar},       // points away from the box
                                  {0.6f, 0.8f, 0, kFar},  // enters x = 0 at t = 1/0.6, y = 2.83
                                  {1, 0, 0, -1.0f},       // no ray (tmax < 0)
                                  {1, 0, 0, 0.5f},        // ends before the box (tmax 0.5 < 1)
                                  {0, 0, 1, kFar},        // parallel to the x slab, outside it
                                  {1, 0, 0, 3.0f},        // short ray that still reaches the box
                                  {0.8f, 0, 0.6f, kFar},  // enters at t = 1.25, z = 3.25
                              });
  const Texture trav = ktest::run(k, {&rays}, 4, 2);
  const glm::vec4 done(kNone, 0, 0, 0);
  CHECK_TEXEL(trav, 0, 0, glm::vec4(0, 1, 2, 1));
  CHECK_TEXEL(trav, 1, 0, done);
  CHECK_TEXEL_NEAR(trav, 2, 0, 1e-6, glm::vec4(0, 2, 2, 1.0 / 0.6));
  CHECK_TEXEL(trav, 3, 0, done);
  CHECK_TEXEL(trav, 0, 1, done);
  CHECK_TEXEL(trav, 1, 1, done);
  CHECK_TEXEL(trav, 2, 1, glm::vec4(0, 1, 2, 1));
  CHECK_TEXEL_NEAR(trav, 3, 1, 1e-6, glm::vec4(0, 1, 3, 1.25));
}

TEST_CASE(
    "init traversal scales by the voxel size and puts a point on the far face in the last voxel") {
  // Box [-2, 2] x [0, 4] x [1, 4] cut into 8 x 2 x 3 voxels of 0.5 x 2 x 1.
  kernels::InitTraversal k;
  k.eye = {0.3f, 5.0f, 2.7f};
  k.grid = grid_uniforms({-2, 0, 1}, {0.5f, 2, 1}, {8, 2, 3});
  const Texture rays = texels("rays", 1, 1, {{0, -1, 0, kFar}});
  const Texture trav = ktest::run(k, {&rays}, 1, 1);
  // Enters the top face y = 4 at t = 1, point (0.3, 4, 2.7): x = floor(2.3 / 0.5) = 4,
  // y = floor(4 / 2) = 2 clamped to 1, z = floor(1.7) = 1.
  CHECK_TEXEL(trav, 0, 0, glm::vec4(4, 1, 1, 1));
}

TEST_CASE("reset traversal starts a ray inside the grid in the voxel of its origin at t = 0") {
  kernels::ResetTraversal k;
  k.grid = kUnitGrid;
  const Texture origins = texels("origins", 5, 1,
                                 {{2.5f, 1.25f, 0.5f, 0},
                                  {2.5f, 1.25f, 0.5f, 0},
                                  {5, 1.5f, 1.5f, 0},
                                  {2.5f, 1.25f, 0.5f, 0},
                                  {5, 1.5f, 1.5f, 0}});
  const Texture rays = texels("rays", 5, 1,
                              {{0, 0, 1, kFar},
                               {0, 0, -1, kFar},
                               {-1, 0, 0, kFar},   // from outside: enters the x = 4 face at t = 1
                               {0, 0, 1, -1.0f},   // no ray
                               {1, 0, 0, kFar}});  // from outside, pointing away
  const Texture trav = ktest::run(k, {&origins, &rays}, 5, 1);
  CHECK_TEXEL(trav, 0, 0, glm::vec4(2, 1, 0, 0));
  CHECK_TEXEL(trav, 1, 0, glm::vec4(2, 1, 0, 0));
  CHECK_TEXEL(trav, 2, 0, glm::vec4(3, 1, 1, 1));  // x = floor(4) = 4 clamped to the last voxel
  CHECK_TEXEL(trav, 3, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(trav, 4, 0, glm::vec4(kNone, 0, 0, 0));
}

TEST_CASE("one traversal pass steps each walking ray into the next voxel along its direction") {
  kernels::Traversal k;
  k.grid = kUnitGrid;
  const float s = 1.0f / std::sqrt(2.0f);
  const Texture origins = texels("origins", 8, 1,
                                 {{0.5f, 1.5f, 1.25f, 0},
                                  {3.5f, 1.5f, 1.5f, 0},
                                  {0.5f, 1.5f, 1.25f, 0},
                                  {0.5f, 1.5f, 1.25f, 0},
                                  {0.5f, 1.5f, 1.25f, 0},
                                  {0.5f, 0.5f, 0.5f, 0},
                                  {1.5f, 3.25f, 0.5f, 0},
                                  {0.5f, 0.5f, 0.5f, 0}});
  const Texture rays = texels("rays", 8, 1,
                              {{1, 0, 0, kFar},
                               {-1, 0, 0, kFar},
                               {1, 0, 0, kFar},
                               {1, 0, 0, kFar},
                               {1, 0, 0, kFar},
                               {s, s, 0, kFar},
                               {0, -1, 0, kFar},
                               {0.6f, 0, 0.8f, kFar}});
  const Texture trav_in = texels("traversal", 8, 1,
                                 {{1, 1, 1, 0.5f},   // leaves x = 2 at t = 1.5
                                  {1, 1, 1, 1.5f},   // going -x: leaves x = 1 at t = 2.5
                                  {3, 1, 1, 2.5f},   // steps out of the grid at t = 3.5
                                  {1, 1, 1, 0.5f},   // has a hit in this voxel
                                  {kNone, 7, 8, 9},  // already done
                                  {0, 0, 0, 0},      // leaves through the edge x = y = 1
                                  {1, 3, 0, 0},      // going -y: leaves y = 3 at t = 0.25
                                  {0, 0, 0, 0}});    // z = 1 at t = 0.625 before x = 1 at 0.83
  std::vector<glm::vec4> none(8, glm::vec4(kFar, 0, 0, kNone));
  none[3] = {1.7f, 0.2f, 0.3f, 2};
  const Texture isect = texels("intersection", 8, 1, none);
  const Texture trav = ktest::run(k, {&origins, &rays, &trav_in, &isect}, 8, 1);
  CHECK_TEXEL(trav, 0, 0, glm::vec4(2, 1, 1, 1.5f));
  CHECK_TEXEL(trav, 1, 0, glm::vec4(0, 1, 1, 2.5f));
  CHECK_TEXEL(trav, 2, 0, glm::vec4(kNone, 0, 0, 2.5f));
  CHECK_TEXEL(trav, 3, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(trav, 4, 0, glm::vec4(kNone, 7, 8, 9));
  CHECK_TEXEL_NEAR(trav, 5, 0, 1e-6, glm::vec4(1, 1, 0, 0.5 * std::sqrt(2.0)));  // both axes step
  CHECK_TEXEL(trav, 6, 0, glm::vec4(1, 2, 0, 0.25f));
  CHECK_TEXEL_NEAR(trav, 7, 0, 1e-6, glm::vec4(0, 0, 1, 0.625));
}

TEST_CASE("a traversal pass ends a ray whose next voxel begins past its tmax, less the slack") {
  // The walk's rule for shadow rays (tmax = the light's distance): a hit in a later voxel has
  // t >= its entry - t_slack, so once the next voxel's entry t_exit has t_exit - t_slack >= tmax
  // nothing there can pass t < tmax and the ray is done. Every ray goes +x from (0.5, 1.5, 1.25)
  // in voxel (1, 1, 1), entered at t = 0.5, leaving at x = 2: t_exit = 1.5, less the slack 0.25
  // = 1.25.
  kernels::Traversal k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(4.0f), 1, 0.25f);
  const glm::vec4 o(0.5f, 1.5f, 1.25f, 0);
  const Texture origins = texels("origins", 6, 1, std::vector<glm::vec4>(6, o));
  const Texture rays = texels("rays", 6, 1,
                              {{1, 0, 0, 1.25f},    // exactly at the bound: done
                               {1, 0, 0, 1.0f},     // the light inside this voxel: done
                               {1, 0, 0, 1.3f},     // a hit in the next voxel could still count
                               {1, 0, 0, kFar},     // a primary ray
                               {1, 0, 0, 1.3f},     // in the last voxel: leaves the grid
                               {1, 0, 0, 1.25f}});  // already done: kept
  const Texture trav_in = texels("traversal", 6, 1,
                                 {{1, 1, 1, 0.5f},
                                  {1, 1, 1, 0.5f},
                                  {1, 1, 1, 0.5f},
                                  {1, 1, 1, 0.5f},
                                  {3, 1, 1, 2.5f},
                                  {kNone, 4, 5, 6}});
  const Texture isect =
      texels("intersection", 6, 1, std::vector<glm::vec4>(6, glm::vec4(kFar, 0, 0, kNone)));
  const Texture trav = ktest::run(k, {&origins, &rays, &trav_in, &isect}, 6, 1);
  CHECK_TEXEL(trav, 0, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(trav, 1, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(trav, 2, 0, glm::vec4(2, 1, 1, 1.5f));
  CHECK_TEXEL(trav, 3, 0, glm::vec4(2, 1, 1, 1.5f));
  CHECK_TEXEL(trav, 4, 0, glm::vec4(kNone, 0, 0, 2.5f));
  CHECK_TEXEL(trav, 5, 0, glm::vec4(kNone, 4, 5, 6));
}
