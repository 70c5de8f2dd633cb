// Kernel tests for the fused two-output programs of --mrt on (kernels/fused.h), each run as one
// real pass writing two render targets on hand-made texels (a gf6600 vgpu, and on the GL device
// in test_gl). Every channel of both targets is checked against values worked out here, and
// against the two single kernels run one after the other as the multipass pipeline runs them.
#include <doctest/doctest.h>

#include <vector>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::check_same;
using ktest::grid_uniforms;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

namespace {

// Triangle lists, 4 entries per row: entry 0 is the shared empty list; {1, 0} starts at 1,
// {0} at 4.
const std::vector<float> kLists = {kNone, 1, 0, kNone, 0, kNone, 0, 0};

}  // namespace

TEST_CASE("intersections + next triangle tests the current triangle and moves to the next entry") {
  // Triangle 0 lies in the plane x = 2.5 spanning y, z in [0, 4]; triangle 1 is it at x = 3.5.
  // Unit voxels, t_slack 0.001; the ray o = (0.5, 1, 0.5), d = +x meets triangle 0 at t = 2
  // (voxel 2 spans t in [1.5, 2.5]) with u = y / 4 = 0.25, v = z / 4 = 0.125, and triangle 1 at
  // t = 3, beyond voxel 2.
  const Texture v0 = vec3s("vertices0", 2, 1, {{2.5f, 0, 0}, {3.5f, 0, 0}});
  const Texture v1 = vec3s("vertices1", 2, 1, {{2.5f, 4, 0}, {3.5f, 4, 0}});
  const Texture v2 = vec3s("vertices2", 2, 1, {{2.5f, 0, 4}, {3.5f, 0, 4}});
  const Texture lists = scalars("triangle lists", 4, 2, kLists);
  const glm::vec4 o(0.5f, 1, 0.5f, 0), px(1, 0, 0, kFar), none(kFar, 0, 0, kNone);
  // Fragments: 0 tests triangle 1 (list entry 1; next is entry 2, triangle 0) in voxel 2: t = 3
  // lies beyond the voxel; 1 tests triangle 0 (entry 2; next is the -1 at 3) and hits it;
  // 2 tests triangle 0 (entry 4, next the -1 at 5) but holds a nearer hit; 3 has nothing to test.
  const Texture to = texels("origins", 4, 1, {o, o, o, o});
  const Texture tr = texels("rays", 4, 1, {px, px, px, px});
  const Texture tt = texels("traversal", 4, 1,
                            {{2, 1, 0, 1.5f}, {2, 1, 0, 1.5f}, {2, 1, 0, 1.5f}, {2, 1, 0, 1.5f}});
  const Texture tv =
      texels("voxel state", 4, 1, {{1, 0, 0, 1}, {2, 0, 0, 0}, {4, 0, 0, 0}, {3, 9, 8, kNone}});
  const Texture tb =
      texels("intersection", 4, 1, {none, none, {1.75f, 0.5f, 0.5f, 1}, {5, 0.1f, 0.2f, 1}});
  kernels::IntersectNext k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(4.0f), 4, 1e-3f);
  k.scene.width = 2;
  const auto out = ktest::run_targets(k, {&to, &tr, &tt, &tv, &tb, &v0, &v1, &v2, &lists}, 4, 1);
  const Texture &hit = out[0], &vs = out[1];
  CHECK_TEXEL(hit, 0, 0, none);
  CHECK_TEXEL(hit, 1, 0, glm::vec4(2, 0.25f, 0.125f, 0));
  CHECK_TEXEL(hit, 2, 0, glm::vec4(1.75f, 0.5f, 0.5f, 1));
  CHECK_TEXEL(hit, 3, 0, glm::vec4(5, 0.1f, 0.2f, 1));
  CHECK_TEXEL(vs, 0, 0, glm::vec4(2, 0, 0, 0));
  CHECK_TEXEL(vs, 1, 0, glm::vec4(3, 0, 0, kNone));
  CHECK_TEXEL(vs, 2, 0, glm::vec4(5, 0, 0, kNone));
  CHECK_TEXEL(vs, 3, 0, glm::vec4(3, 9, 8, kNone));

  // The multipass pipeline's two passes give the same texels.
  kernels::Intersections ki;
  ki.grid = k.grid;
  ki.scene = k.scene;
  kernels::NextTriangle kn;
  kn.lists = k.grid;
  check_same(hit, ktest::run(ki, {&to, &tr, &tt, &tv, &tb, &v0, &v1, &v2}, 4, 1));
  check_same(vs, ktest::run(kn, {&tv, &lists}, 4, 1));
}

TEST_CASE("traversal + update voxel steps each ray and loads the first triangle of its new voxel") {
  // A 4 x 1 x 2 grid of unit voxels: the pointer texture is 4 x 2 (voxel (X, 0, Z) at (X, Z)).
  // Voxel (1, 0, 0) points at list entry 1 (triangle 1), voxel (2, 0, 0) at the empty list 0,
  // voxel (1, 0, 1) at entry 4 (triangle 0).
  const Texture pointers = scalars("voxel pointers", 4, 2, {0, 1, 0, 0, 0, 4, 0, 0});
  const Texture lists = scalars("triangle lists", 4, 2, kLists);
  const glm::vec4 px(1, 0, 0, kFar), pz(0, 0, 1, kFar), none(kFar, 0, 0, kNone);
  const glm::vec4 empty(0, 0, 0, kNone);
  // Fragments, origin (0.5, 0.5, 0.5) unless noted:
  //   0 along +x in voxel (0, 0, 0): exits at t = 0.5 into (1, 0, 0), loads entry 1, triangle 1
  //   1 along +x in voxel (1, 0, 0): into (2, 0, 0), the empty list: entry 0, triangle -1
  //   2 along +x in voxel (3, 0, 0): leaves the grid, done (x = -1); voxel state kept
  //   3 along +z in voxel (1, 0, 0) (origin (1.5, 0.5, 0.5)): into (1, 0, 1), entry 4
  //   4 along +x in voxel (0, 0, 0) with a hit there: done; voxel state kept
  //   5 a done ray: both states kept
  const glm::vec4 o(0.5f, 0.5f, 0.5f, 0), o3(1.5f, 0.5f, 0.5f, 0);
  const Texture to = texels("origins", 6, 1, {o, o, o, o3, o, o});
  const Texture tr = texels("rays", 6, 1, {px, px, px, pz, px, px});
  const Texture tt = texels("traversal", 6, 1,
                            {{0, 0, 0, 0},
                             {1, 0, 0, 0.5f},
                             {3, 0, 0, 2.5f},
                             {1, 0, 0, 0},
                             {0, 0, 0, 0},
                             {kNone, 0, 0, 7}});
  const Texture ti =
      texels("intersection", 6, 1, {none, none, none, none, {0.25f, 0.1f, 0.2f, 1}, {4, 0, 0, 0}});
  const Texture tv =
      texels("voxel state", 6, 1, {empty, empty, empty, empty, {6, 5, 4, kNone}, {3, 2, 1, kNone}});
  kernels::TraverseUpdate k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), {4, 1, 2}, 4);
  const auto out = ktest::run_targets(k, {&to, &tr, &tt, &ti, &tv, &pointers, &lists}, 6, 1);
  const Texture &trav = out[0], &vs = out[1];
  CHECK_TEXEL(trav, 0, 0, glm::vec4(1, 0, 0, 0.5f));
  CHECK_TEXEL(trav, 1, 0, glm::vec4(2, 0, 0, 1.5f));
  CHECK_TEXEL(trav, 2, 0, glm::vec4(kNone, 0, 0, 2.5f));
  CHECK_TEXEL(trav, 3, 0, glm::vec4(1, 0, 1, 0.5f));
  CHECK_TEXEL(trav, 4, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(trav, 5, 0, glm::vec4(kNone, 0, 0, 7));
  CHECK_TEXEL(vs, 0, 0, glm::vec4(1, 0, 0, 1));
  CHECK_TEXEL(vs, 1, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(vs, 2, 0, empty);
  CHECK_TEXEL(vs, 3, 0, glm::vec4(4, 0, 0, 0));
  CHECK_TEXEL(vs, 4, 0, glm::vec4(6, 5, 4, kNone));
  CHECK_TEXEL(vs, 5, 0, glm::vec4(3, 2, 1, kNone));

  // The multipass pipeline: traversal, then actualizarVoxel on the traversal it wrote.
  kernels::Traversal kt;
  kt.grid = k.grid;
  kernels::UpdateVoxel ku;
  ku.grid = k.grid;
  const Texture stepped = ktest::run(kt, {&to, &tr, &tt, &ti}, 6, 1);
  check_same(trav, stepped);
  check_same(vs, ktest::run(ku, {&stepped, &tv, &pointers, &lists}, 6, 1));
}

TEST_CASE("traversal + update voxel ends a ray whose next voxel begins past its tmax") {
  // The grid of the case above, no slack. Both rays go +x from (0.5, 0.5, 0.5) in voxel
  // (0, 0, 0), leaving it at t = 0.5: with tmax 0.5 the next voxel holds nothing that can count
  // (done, voxel state kept); with tmax 0.6 the ray steps and loads triangle 1 of voxel (1, 0, 0).
  const Texture pointers = scalars("voxel pointers", 4, 2, {0, 1, 0, 0, 0, 4, 0, 0});
  const Texture lists = scalars("triangle lists", 4, 2, kLists);
  const glm::vec4 o(0.5f, 0.5f, 0.5f, 0), none(kFar, 0, 0, kNone), empty(0, 0, 0, kNone);
  const Texture to = texels("origins", 2, 1, {o, o});
  const Texture tr = texels("rays", 2, 1, {{1, 0, 0, 0.5f}, {1, 0, 0, 0.6f}});
  const Texture tt = texels("traversal", 2, 1, {{0, 0, 0, 0}, {0, 0, 0, 0}});
  const Texture ti = texels("intersection", 2, 1, {none, none});
  const Texture tv = texels("voxel state", 2, 1, {empty, empty});
  kernels::TraverseUpdate k;
  k.grid = grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), {4, 1, 2}, 4);
  const auto out = ktest::run_targets(k, {&to, &tr, &tt, &ti, &tv, &pointers, &lists}, 2, 1);
  CHECK_TEXEL(out[0], 0, 0, glm::vec4(kNone, 0, 0, 0));
  CHECK_TEXEL(out[0], 1, 0, glm::vec4(1, 0, 0, 0.5f));
  CHECK_TEXEL(out[1], 0, 0, empty);
  CHECK_TEXEL(out[1], 1, 0, glm::vec4(1, 0, 0, 1));
}

TEST_CASE("a fused program is refused on a profile with one output, naming it and the limit") {
  vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
  vgpu::KernelProgram<kernels::TraverseUpdate> p;
  Texture a = gpu.make_texture("traversal B", 2, 1, 4), b = gpu.make_texture("voxel B", 2, 1, 4);
  const Texture in = texels("in", 2, 1, {});
  gpu.use_program(p);
  for (int u = 0; u < 7; ++u) gpu.bind_texture(u, in);
  gpu.set_targets({&a, &b});
  CHECK_THROWS_WITH_AS(gpu.draw(),
                       "program 'traversal + update voxel' writes 2 outputs; profile gf5700 "
                       "allows 1 (no multiple render targets)",
                       vgpu::Error);
}
