// recorridoIterativo (kernels/looping_traversal.h) on hand-made texels: a 2x1x1 grid of unit
// voxels, an empty voxel 0 and voxel 1 holding triangle 0 in the plane x = 1.5. Three rays from
// (0.5, 0.5, 0.5): +x (3 iterations: step out of the empty voxel, test the triangle, step out
// of the grid with the hit), -x (1 iteration: out of the grid) and one already done (0). Every
// channel of the three outputs is checked, and the batch's loop counters. Linked into test_gl
// too, every pass is made again as a GL pass (one GLSL loop) from the same texels, and
// its three outputs must match the vgpu's texel by texel (tests/gl/gl_compare.h): a loop budget,
// break or carried variable the GLSL gets wrong shows up there, the budget-stopped pass too.
#include <iterator>
#include <vector>

#include "kernel_pass.h"

namespace {

using kernels::kFar;
using kernels::kNone;
using kernels::LoopingTraversal;
using vgpu::Texture;

struct Scene {
  Texture origins =
      ktest::texels("origins", 3, 1, std::vector<glm::vec4>(3, {0.5f, 0.5f, 0.5f, 0}));
  Texture rays = ktest::texels("rays", 3, 1, {{1, 0, 0, 100}, {-1, 0, 0, 100}, {1, 0, 0, 100}});
  Texture trav = ktest::texels("traversal", 3, 1, {{0, 0, 0, 0}, {0, 0, 0, 0}, {kNone, 0, 0, 3}});
  Texture vs = ktest::texels("voxel state", 3, 1, std::vector<glm::vec4>(3, {0, 0, 0, kNone}));
  Texture isect = ktest::texels("intersection", 3, 1,
                                {{kFar, 0, 0, kNone}, {kFar, 0, 0, kNone}, {2, 0.5f, 0.25f, 0}});
  Texture v0 = ktest::vec3s("vertices0", 1, 1, {{1.5f, -1, -1}});
  Texture v1 = ktest::vec3s("vertices1", 1, 1, {{1.5f, 3, -1}});
  Texture v2 = ktest::vec3s("vertices2", 1, 1, {{1.5f, 0.5f, 3}});
  Texture pointers = ktest::scalars("voxel pointers", 2, 1, {0, 1});  // voxel 0 empty
  Texture lists = ktest::scalars("triangle lists", 3, 1, {kNone, 0, kNone});
};

LoopingTraversal kernel(int steps) {
  LoopingTraversal k;
  k.grid = ktest::grid_uniforms({0, 0, 0}, {1, 1, 1}, {2, 1, 1}, 3);
  k.scene.width = 1;
  k.steps = steps;
  return k;
}

struct Outputs {
  Texture trav{"traversal out", 3, 1, 4}, vs{"voxel state out", 3, 1, 4},
      isect{"intersection out", 3, 1, 4};
  vgpu::PassRecord rec;
};

Outputs pass(vgpu::Gpu& gpu, const vgpu::KernelProgram<LoopingTraversal>& p, const Texture& trav,
             const Texture& vs, const Texture& isect, const Scene& s) {
  Outputs o;
  gpu.use_program(p);
  gpu.unbind_textures();
  const Texture* units[] = {&s.origins, &s.rays, &trav, &vs,         &isect,
                            &s.v0,      &s.v1,   &s.v2, &s.pointers, &s.lists};
  for (int u = 0; u < 10; ++u) gpu.bind_texture(u, *units[u]);
  const std::vector<Texture> before =
      ktest::before_pass({&o.trav, &o.vs, &o.isect});  // the GL pass starts from the same texels
  gpu.set_targets({&o.trav, &o.vs, &o.isect});
  o.rec = gpu.draw();
  if (ktest::gl_check()) {
    // The GL device computes in fp32, as the vgpu does here: compared channel by channel.
    REQUIRE(gpu.precision() == vgpu::Format::fp32);
    REQUIRE(p.precision() == vgpu::Format::fp32);
    ktest::check_on_gl(p, {std::begin(units), std::end(units)}, before, {&o.trav, &o.vs, &o.isect},
                       nullptr);
  }
  return o;
}

}  // namespace

TEST_CASE("looping traversal walks, tests and finishes each ray in one pass") {
  const Scene s;
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);  // 1024-pixel batches: the three rays are one
  const vgpu::KernelProgram<LoopingTraversal> p(kernel(32));
  const Outputs o = pass(gpu, p, s.trav, s.vs, s.isect, s);
  // +x: hit at t = 1, u = 15/64, v = 3/8; then out of the grid through x = 2 with the hit.
  CHECK_TEXEL(o.trav, 0, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(o.vs, 0, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 0, 0, glm::vec4(1, 0.234375f, 0.375f, 0));
  // -x: out of the grid through x = 0, no hit; the entry parameter is kept.
  CHECK_TEXEL(o.trav, 1, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(o.vs, 1, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 1, 0, glm::vec4(kFar, 0, 0, kNone));
  // Already done: every output is its input.
  CHECK_TEXEL(o.trav, 2, 0, glm::vec4(kNone, 0, 0, 3));
  CHECK_TEXEL(o.vs, 2, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 2, 0, glm::vec4(2, 0.5f, 0.25f, 0));
  const vgpu::Counters& c = o.rec.counters;
  CHECK(c.loop_iterations == 3 + 1 + 0);
  CHECK(c.loop_lane_slots == 3 * 3);
  CHECK(c.loop_lanes_idle == 5);
  CHECK(c.loop_batch_iterations == 3);
  CHECK(o.rec.loop_active ==
        std::vector<uint64_t>({2, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                               0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  CHECK(o.rec.loop_idle[0] == 1);
  CHECK(o.rec.loop_idle[1] == 2);
  CHECK(o.rec.loop_idle[2] == 2);
  CHECK(o.rec.loop_idle[3] == 0);
}

TEST_CASE("looping traversal ends a ray at the first voxel that begins past its tmax") {
  // The scene above with a third, empty voxel (x in [2, 3]): triangle 0 at x = 1.5 sits in
  // voxel 1. Every ray from (0.5, 0.5, 0.5), no slack:
  //   0 +x, tmax 0.75 (a light before the triangle): voxel 0, then voxel 1 where the hit at
  //     t = 1 does not pass t < tmax; voxel 2 begins at 1.5 >= tmax: done there, 3 iterations,
  //     entry t 0.5 kept (a walk on to the grid's face would end in voxel 2, at 1.5, after 4)
  //   1 -x, no bound: out of the grid through x = 0 (1 iteration)
  //   2 +x, tmax 1.5: the hit counts (1 < 1.5) and ends the walk (3 iterations)
  Scene s;
  s.rays = ktest::texels("rays", 3, 1, {{1, 0, 0, 0.75f}, {-1, 0, 0, kFar}, {1, 0, 0, 1.5f}});
  s.trav = ktest::texels("traversal", 3, 1, std::vector<glm::vec4>(3, {0, 0, 0, 0}));
  s.isect = ktest::texels("intersection", 3, 1, std::vector<glm::vec4>(3, {kFar, 0, 0, kNone}));
  s.pointers = ktest::scalars("voxel pointers", 3, 1, {0, 1, 2});
  LoopingTraversal k = kernel(32);
  k.grid = ktest::grid_uniforms({0, 0, 0}, {1, 1, 1}, {3, 1, 1}, 3);
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);
  const vgpu::KernelProgram<LoopingTraversal> p(k);
  const Outputs o = pass(gpu, p, s.trav, s.vs, s.isect, s);
  CHECK_TEXEL(o.trav, 0, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(o.vs, 0, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 0, 0, glm::vec4(kFar, 0, 0, kNone));
  CHECK_TEXEL(o.trav, 1, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(o.vs, 1, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 1, 0, glm::vec4(kFar, 0, 0, kNone));
  CHECK_TEXEL(o.trav, 2, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(o.vs, 2, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(o.isect, 2, 0, glm::vec4(1, 0.234375f, 0.375f, 0));
  CHECK(o.rec.counters.loop_iterations == 3 + 1 + 3);
}

TEST_CASE("looping traversal stopped by its budget resumes where it stopped") {
  const Scene s;
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);
  const vgpu::KernelProgram<LoopingTraversal> p(kernel(2));
  const Outputs a = pass(gpu, p, s.trav, s.vs, s.isect, s);
  // After 2 iterations the +x ray is in voxel 1 with its hit, its list read to the end.
  CHECK_TEXEL(a.trav, 0, 0, glm::vec4(1, 0, 0, 0.5f));
  CHECK_TEXEL(a.vs, 0, 0, glm::vec4(2, 0, 1, kNone));
  CHECK_TEXEL(a.isect, 0, 0, glm::vec4(1, 0.234375f, 0.375f, 0));
  CHECK_TEXEL(a.trav, 1, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK(a.rec.counters.loop_iterations == 2 + 1);
  const Outputs b = pass(gpu, p, a.trav, a.vs, a.isect, s);
  CHECK_TEXEL(b.trav, 0, 0, glm::vec4(kNone, 0, 0, 0.5f));
  CHECK_TEXEL(b.vs, 0, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(b.isect, 0, 0, glm::vec4(1, 0.234375f, 0.375f, 0));
  CHECK_TEXEL(b.trav, 1, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(b.isect, 1, 0, glm::vec4(kFar, 0, 0, kNone));
  CHECK(b.rec.counters.loop_iterations == 1);
  CHECK(b.rec.counters.loop_lane_slots == 3);
}

TEST_CASE("looping traversal's static count holds its body once") {
  const vgpu::KernelProgram<LoopingTraversal> p(kernel(32));
  const vgpu::Program::Analysis a = p.analyze();
  CHECK(a.loop.loops == 1);
  CHECK(a.loop.max_iterations == 32);
  // Outside the body: the five own-texel fetches; inside: pointer, two list entries, three
  // vertices per iteration.
  CHECK(a.fetches.total() == 11);
  CHECK(a.loop.body_fetches.total() == 6);
  CHECK(a.instructions - a.loop.body_instructions == 5 + 1);  // fetches + the entry compare
}
