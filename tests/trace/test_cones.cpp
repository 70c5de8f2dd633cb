// The object-space decision of adaptive sampling (--aa-criterion object, kernels/cones.h) on a
// whole frame: a fold of one material that the image-space rule cannot see, the stream tracer
// against the CPU tracer.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

// Two white squares of one material, facing the camera at z = 4: the back one at z = 0
// (x in [-4, 4]), a front one at z = 2 from x = 0.1 rightwards. One light far above the camera,
// diffuse shading, no shadows or reflections: both squares have the same colour and the same
// surface key, and only the hit distances tell them apart (4 behind, 2 in front).
struct FoldCase {
  host::Scene scene;
  host::Grid grid;
  host::Camera camera;
  FoldCase() {
    scene.name = "fold";
    scene.materials = {{{1.0f, 1.0f, 1.0f}, 0.0f}};
    scene.add_flat_triangle({-4, -2, 0}, {4, -2, 0}, {4, 2, 0}, 0, 0);
    scene.add_flat_triangle({-4, -2, 0}, {4, 2, 0}, {-4, 2, 0}, 0, 1);
    scene.add_flat_triangle({0.1f, -2, 2}, {4, -2, 2}, {4, 2, 2}, 0, 2);
    scene.add_flat_triangle({0.1f, -2, 2}, {4, 2, 2}, {0.1f, 2, 2}, 0, 3);
    scene.input_triangles = 4;
    scene.lights = {{{0, 0, 1000}, {1, 1, 1}}};
    grid = host::build_grid(scene, host::GridSpec{glm::ivec3(4, 4, 2)});
    camera.position = {0, 0, 4};
    camera.forward = {0, 0, -1};
    camera.up = {0, 1, 0};
    // 9 x 3 pixels 0.1 radians apart (0.4 wide at z = 0): column 4's centre ray (x = 0) passes
    // left of the front square, column 5's meets it at x = 0.2.
    camera.yfov = 2.0f * std::atan(0.15f);
  }
};

host::RenderOptions fold_options(host::RenderOptions::AaCriterion criterion) {
  host::RenderOptions opt;
  opt.width = 9;
  opt.height = 3;
  opt.bounces = 0;
  opt.shadows = false;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.profile = "gf6600";
  opt.spp = 16;
  opt.adaptive = true;
  opt.aa_threshold = 0.05f;
  opt.aa_criterion = criterion;
  return opt;
}

}  // namespace

TEST_CASE(
    "the object criterion refines a fold of one material that the image criterion cannot see, "
    "and the CPU tracer marks the same pixels") {
  FoldCase e;
  using C = host::RenderOptions::AaCriterion;
  // The image criterion: one key, one colour, so every pixel keeps its one ray.
  const host::RenderResult image =
      host::StreamTracer(e.scene, e.grid, fold_options(C::image)).render(e.camera);
  REQUIRE(image.rays_per_pixel.size() == 27);
  for (const uint32_t n : image.rays_per_pixel) CHECK(n == 1u);
  // The object criterion: the hit distances bend by about 2 at columns 4 and 5, more than 2
  // widths of their cones (0.1 radians a pixel: 0.8 at t 4, 0.4 at t 2): both go to the last
  // level (1 + 2x2 + 4x4 = 21 rays), every other pixel keeps its one ray.
  const host::RenderOptions opt = fold_options(C::object);
  const host::RenderResult g = host::StreamTracer(e.scene, e.grid, opt).render(e.camera);
  const host::RenderResult c = host::render_cpu(e.scene, e.grid, e.camera, opt);
  REQUIRE(g.rays_per_pixel.size() == 27);
  CHECK(g.rays_per_pixel == c.rays_per_pixel);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 9; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      CHECK(g.rays_per_pixel[size_t(y * 9 + x)] == (x == 4 || x == 5 ? 21u : 1u));
    }
  for (int i = 0; i < 27 * 3; ++i) CHECK(std::fabs(g.rgb[size_t(i)] - c.rgb[size_t(i)]) < 1e-4f);
}
